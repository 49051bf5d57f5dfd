#include "bench/run.hpp"

#include "bench/core/content_hash.hpp"
#include "bench/core/ground_truth.hpp"
#include "bench/core/policies.hpp"
#include "bench/core/registry.hpp"
#include "bench/core/tree_cache.hpp"
#include "bench/plan.hpp"
#include "bvh/mesh_io.hpp"
#include "traversal/strategies.hpp"

#ifdef BVHLAB_HAVE_FCL
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#endif

#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

#ifndef BVHLAB_BUILD_TYPE
#define BVHLAB_BUILD_TYPE "unknown"
#endif

namespace bvhlab {
namespace {

using Clock = std::chrono::steady_clock;
using LogFn = std::function<void(const std::string&)>;
constexpr double kNotApplicable = std::numeric_limits<double>::quiet_NaN();
/// Poses per block of the interleaved timing loop (see run_scene).
constexpr std::size_t kPoseBlock = 50;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// ---------------------------------------------------------------------------------------------------------
// Progress bar on stderr: redrawn in place on a terminal, a line per tenth otherwise.

class Progress {
 public:
  Progress(bool enabled, std::size_t total)
      : enabled_(enabled && total > 0), total_(total), tty_(isatty(2)) {}
  void advance(std::size_t done, const std::string& label) {
    if (!enabled_) return;
    done_ += done;
    const double fraction = std::min(1.0, double(done_) / double(total_));
    if (tty_) {
      const auto now = Clock::now();
      if (done_ < total_ && now - last_ < std::chrono::milliseconds(100)) return;
      last_ = now;
      const int width = 30, filled = static_cast<int>(fraction * width);
      std::fprintf(stderr, "\r[%s%s] %3d%%  %-48.48s", std::string(filled, '#').c_str(),
                   std::string(width - filled, '.').c_str(), static_cast<int>(fraction * 100), label.c_str());
      if (done_ >= total_) std::fputc('\n', stderr);
    } else {
      const int tenth = static_cast<int>(fraction * 10);
      if (tenth > printed_tenth_) {
        printed_tenth_ = tenth;
        std::fprintf(stderr, "  %3d%% of the queries done (%s)\n", tenth * 10, label.c_str());
      }
    }
    std::fflush(stderr);
  }

 private:
  bool enabled_;
  std::size_t total_, done_ = 0;
  bool tty_;
  int printed_tenth_ = 0;
  Clock::time_point last_{};
};

// ---------------------------------------------------------------------------------------------------------
// Objects, hierarchies and the strategies' timed series.

struct ObjectData {
  const SceneObject* spec = nullptr;
  Mesh mesh;
  std::string key;  ///< mesh checksum and every transform applied to it
};

struct QueryRecord {
  bool collides = false, exact = true, budget_exhausted = false;
  double probability = 0, micros = 0;
  Counters counters;
};

template <class Query>
void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                  Query&& query) {
  out.clear();
  out.reserve(poses.size());
  bool sink = false;
  for (std::size_t k = 0; k < poses.size() && k < static_cast<std::size_t>(std::max(warmup, 0)); ++k)
    sink ^= query(poses[k]).collides;
  for (const RigidTransform& pose : poses) {
    const auto start = Clock::now();
    const Result r = query(pose);
    const auto stop = Clock::now();
    out.push_back({r.collides, r.exact, r.budget_exhausted, r.probability,
                   std::chrono::duration<double, std::micro>(stop - start).count(), r.counters});
  }
  if (sink && out.empty()) std::fputc(' ', stderr);  // keeps the warm-up from being optimised away
}

/// What an empty timed region costs: the median of back-to-back clock reads. Subtracted from every query time
/// (clamped at 0), so that sub-microsecond ADB answers are not inflated by the clock itself.
double clock_overhead_us() {
  std::vector<double> samples(20001);
  for (double& sample : samples) {
    const auto start = Clock::now();
    const auto stop = Clock::now();
    sample = std::chrono::duration<double, std::micro>(stop - start).count();
  }
  std::nth_element(samples.begin(), samples.begin() + samples.size() / 2, samples.end());
  return samples[samples.size() / 2];
}

class PreparedHierarchy {
 public:
  virtual ~PreparedHierarchy() = default;
  /// Times `variant` on every pose (one dispatch to the strategy's type per series, none per query).
  virtual void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
                   std::vector<QueryRecord>& out) const = 0;
  /// Exact first-contact answer (the ground truth's source).
  [[nodiscard]] virtual bool exact_collides(const RigidTransform& pose) const = 0;
  [[nodiscard]] virtual bool has_counters() const { return true; }
  /// One untimed query with the full result (witness, contacts).
  [[nodiscard]] virtual Result query(const StrategyVariant& variant, const RigidTransform& pose) const = 0;
  ModelInfo model;  ///< A's tree
};

template <class BV, class D>
class BvhlabHierarchy final : public PreparedHierarchy {
 public:
  BvhlabHierarchy(std::shared_ptr<const Tree<BV, D>> a, std::shared_ptr<const Tree<BV, D>> b)
      : a_(std::move(a)), b_(std::move(b)) {}

  void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
           std::vector<QueryRecord>& out) const override {
    with_configured(variant, [&]<class S>(std::type_identity<S>, const typename S::Options& options) {
      timed_series(poses, warmup, out,
                   [&](const RigidTransform& p) { return S::query(*a_, *b_, p, options); });
    });
  }
  [[nodiscard]] Result query(const StrategyVariant& variant, const RigidTransform& pose) const override {
    Result result;
    with_configured(variant, [&]<class S>(std::type_identity<S>, const typename S::Options& options) {
      result = S::query(*a_, *b_, pose, options);
    });
    return result;
  }
  [[nodiscard]] bool exact_collides(const RigidTransform& pose) const override {
    return query_exact(a_->bvh, b_->bvh, pose).collides;
  }

 private:
  /// Calls f(type_identity<S>, options) for the variant's strategy S, configured; throws when S cannot run
  /// on these trees.
  template <class F>
  static void with_configured(const StrategyVariant& variant, F&& f) {
    with_strategy(variant.strategy, [&]<class S>(std::type_identity<S> strategy) {
      if constexpr (S::template accepts<D>)
        f(strategy, strategy_options<S>(variant.values, variant.budget));
      else
        throw std::invalid_argument("strategy " + variant.label() + " does not run on trees with density '" +
                                    std::string(D::name()) + "'");
    });
  }
  std::shared_ptr<const Tree<BV, D>> a_, b_;
};

#ifdef BVHLAB_HAVE_FCL
template <class FclBV>
class FclHierarchy final : public PreparedHierarchy {
 public:
  using Model = fcl::BVHModel<FclBV>;
  FclHierarchy(std::shared_ptr<const Model> a, std::shared_ptr<const Model> b)
      : a_(std::move(a)), b_(std::move(b)) {}

  void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
           std::vector<QueryRecord>& out) const override {
    if (variant.strategy != ExactStrategy::name())
      throw std::logic_error("runner: FCL hierarchies run the exact strategy only");
    timed_series(poses, warmup, out, [&](const RigidTransform& p) { return query(p); });
  }
  [[nodiscard]] bool exact_collides(const RigidTransform& pose) const override {
    return query(pose).collides;
  }
  [[nodiscard]] bool has_counters() const override { return false; }
  [[nodiscard]] Result query(const StrategyVariant& variant, const RigidTransform& pose) const override {
    if (variant.strategy != ExactStrategy::name())
      throw std::invalid_argument("FCL hierarchies answer exact first-contact queries only");
    return query(pose);
  }

 private:
  Result query(const RigidTransform& pose) const {
    const fcl::CollisionRequestd request(1, false);
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = pose.rotation;
    tf.translation() = pose.translation;
    fcl::CollisionResultd result;
    fcl::collide(a_.get(), fcl::Transform3d::Identity(), b_.get(), tf, request, result);
    Result r;
    r.collides = result.isCollision();
    r.probability = r.collides ? 1 : 0;
    return r;
  }
  std::shared_ptr<const Model> a_, b_;
};
#endif

// Progress of a long build or annotation as log lines, every 10%, for meshes large enough to wait on.
std::function<void(std::size_t, std::size_t)> percent_logger(const LogFn& log, std::string what,
                                                             std::size_t triangles) {
  constexpr std::size_t kLargeMesh = 100'000;
  if (triangles < kLargeMesh) return {};
  return [log, what = std::move(what), next = std::size_t{10}](std::size_t done, std::size_t total) mutable {
    const std::size_t percent = total ? 100 * done / total : 100;
    if (percent < next) return;
    log("  " + what + " " + std::to_string(percent) + "%");
    next = percent / 10 * 10 + 10;
  };
}

// ---------------------------------------------------------------------------------------------------------
// Trees: from the run's memory, else the disk cache, else built (and then cached).

class TreeStore {
 public:
  TreeStore(const std::filesystem::path& cache_dir, RunStats& stats, LogFn log, unsigned threads)
      : cache_(cache_dir.empty() ? cache_dir : cache_dir / "trees", log),
        stats_(stats),
        log_(std::move(log)),
        threads_(threads) {}

  /// The tree of `object` for hierarchy `h` with density D (parameters `density`): from this run's memory,
  /// else the disk cache, else built (a density starts from the plain tree, itself remembered).
  template <class BV, class D>
  std::shared_ptr<const Tree<BV, D>> tree(const ObjectData& object, const HierarchySpec& h,
                                          const DensitySpec& density, ModelInfo* info = nullptr) {
    const std::string annotation = density.label();
    const std::string key = plain_key<BV>(object, h) + (annotation == "none" ? "" : "|" + annotation);
    using T = Tree<BV, D>;
    if (auto hit = memo_.find(key); hit != memo_.end()) {
      if (info) *info = infos_.at(key);
      return std::static_pointer_cast<const T>(hit->second);
    }
    CachedTreeTimes times;
    auto start = Clock::now();
    std::optional<T> tree = cache_.load<BV, D>(key, object.mesh, &times, annotation);
    stats_.preprocess_seconds += seconds_since(start);
    const bool from_cache = tree.has_value();
    if (!tree) {
      tree.emplace(make_tree<BV, D>(object, h, density, times));
      cache_.store(key, *tree, times);
    }
    auto shared = std::make_shared<const T>(std::move(*tree));
    remember(key, shared, describe(*shared, object, h, annotation, times, from_cache), info);
    return shared;
  }

#ifdef BVHLAB_HAVE_FCL
  template <class FclBV>
  std::shared_ptr<const fcl::BVHModel<FclBV>> fcl_model(const ObjectData& object, const HierarchySpec& h,
                                                        ModelInfo* info) {
    const std::string key = "fcl|" + h.bv + "|" + object.key;
    using Model = fcl::BVHModel<FclBV>;
    if (auto hit = memo_.find(key); hit != memo_.end()) {
      *info = infos_.at(key);
      return std::static_pointer_cast<const Model>(hit->second);
    }
    log_("building " + h.bv + " model of " + object.spec->name);
    const auto start = Clock::now();
    auto model = std::make_shared<Model>();
    std::vector<fcl::Vector3d> points(object.mesh.vertices.begin(), object.mesh.vertices.end());
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(object.mesh.triangles.size());
    for (const auto& t : object.mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
    model->beginModel();
    model->addSubModel(points, triangles);
    model->endModel();
    ++stats_.fcl_models_built;
    ModelInfo m;
    m.object = object.spec->name;
    m.hierarchy = h.name;
    m.bv = h.bv;
    m.annotation = "none";
    m.triangles = object.mesh.triangle_count();
    m.nodes = static_cast<std::size_t>(model->getNumBVs());
    m.model_bytes = double(m.nodes) * double(sizeof(fcl::BVNode<FclBV>));
    m.bytes_per_triangle = m.triangles ? m.model_bytes / double(m.triangles) : 0;
    m.build_seconds = seconds_since(start);
    stats_.preprocess_seconds += m.build_seconds;
    remember(key, std::shared_ptr<const Model>(model), m, info);
    return model;
  }
#endif

  [[nodiscard]] std::vector<ModelInfo> models() const {
    std::vector<ModelInfo> out;
    for (const auto& key : order_) out.push_back(infos_.at(key));
    return out;
  }
  [[nodiscard]] const TreeCache& cache() const {
    return cache_;
  }

 private:
  template <class BV, class D>
  Tree<BV, D> make_tree(const ObjectData& object, const HierarchySpec& h, const DensitySpec& density,
                        CachedTreeTimes& times) {
    if constexpr (std::is_same_v<D, NoDensity>) {
      log_("building " + std::string(BV::name()) + " tree of " + object.spec->name + " (" +
           std::to_string(object.mesh.triangle_count()) + " triangles)");
      BuildOptions options = h.build;
      options.threads = threads_;
      options.progress = percent_logger(log_, "building: triangles placed", object.mesh.triangle_count());
      Tree<BV, NoDensity> built{Bvh<BV>::build(object.mesh, options), {}};
      ++stats_.trees_built;
      times.build_seconds = built.bvh.stats().build_seconds;
      return built;
    } else {
      ModelInfo plain_info;
      Bvh<BV> bvh = tree<BV, NoDensity>(object, h, DensitySpec{}, &plain_info)->bvh;  // a copy to annotate
      const auto start = Clock::now();
      log_("annotating " + std::string(BV::name()) + " tree of " + object.spec->name + " (" +
           density.label() + ")");
      AnnotationContext context;
      context.threads = threads_;
      context.progress = percent_logger(log_, "annotating", object.mesh.triangle_count());
      AnnotateStats annotate_stats;
      Tree<BV, D> annotated =
          annotate_tree<D>(std::move(bvh), density_params<D>(density.values), context, &annotate_stats);
      ++stats_.trees_annotated;
      stats_.annotation_clip_calls += annotate_stats.clip_calls;
      times.build_seconds = plain_info.build_seconds;
      times.annotate_seconds = annotate_stats.seconds;
      stats_.preprocess_seconds += seconds_since(start);
      return annotated;
    }
  }

  template <class BV>
  static std::string plain_key(const ObjectData& object, const HierarchySpec& h) {
    return "bvhlab-tree v1|" + object.key + "|bv=" + std::string(BV::name()) +
           "|split=" + std::string(to_string(h.build.split)) +
           "|leaf=" + std::to_string(h.build.max_leaf_triangles);
  }

  template <class T>
  static ModelInfo describe(const T& tree, const ObjectData& object, const HierarchySpec& h,
                            const std::string& annotation, const CachedTreeTimes& times, bool from_cache) {
    const BvhStats s = tree.bvh.stats();
    ModelInfo m;
    m.object = object.spec->name;
    m.hierarchy = h.name;
    m.bv = h.bv;
    m.annotation = annotation;
    m.triangles = s.triangles;
    m.nodes = s.nodes;
    m.depth = s.depth;
    // Nodes and volumes, plus what the density adds; polygons are not counted (an ADB query does not need
    // them).
    m.model_bytes = double(s.nodes * s.bytes_per_node) + double(T::DensityType::memory_bytes(tree.density));
    m.bytes_per_triangle = s.triangles ? m.model_bytes / double(s.triangles) : 0;
    m.build_seconds = times.build_seconds;
    m.annotate_seconds = times.annotate_seconds;
    m.from_cache = from_cache;
    return m;
  }

  void remember(const std::string& key, std::shared_ptr<const void> value, const ModelInfo& info,
                ModelInfo* out) {
    memo_[key] = std::move(value);
    infos_[key] = info;
    order_.push_back(key);
    if (out) *out = info;
  }

  TreeCache cache_;
  RunStats& stats_;
  LogFn log_;
  unsigned threads_;
  std::map<std::string, std::shared_ptr<const void>> memo_;
  std::map<std::string, ModelInfo> infos_;
  std::vector<std::string> order_;
};

/// The planned hierarchy's trees (or FCL models) for objects a and b, ready to time.
std::unique_ptr<PreparedHierarchy> prepare(const PlannedHierarchy& planned, const ObjectData& a,
                                           const ObjectData& b, TreeStore& store) {
  const HierarchySpec& h = *planned.hierarchy;
  std::unique_ptr<PreparedHierarchy> out;
  ModelInfo info;
  if (h.is_fcl()) {
#ifdef BVHLAB_HAVE_FCL
    if (h.bv == "fcl_obb") {
      auto ma = store.fcl_model<fcl::OBBd>(a, h, &info);
      ModelInfo ignored;
      auto mb = store.fcl_model<fcl::OBBd>(b, h, &ignored);
      out = std::make_unique<FclHierarchy<fcl::OBBd>>(ma, mb);
    } else {
      auto ma = store.fcl_model<fcl::OBBRSSd>(a, h, &info);
      ModelInfo ignored;
      auto mb = store.fcl_model<fcl::OBBRSSd>(b, h, &ignored);
      out = std::make_unique<FclHierarchy<fcl::OBBRSSd>>(ma, mb);
    }
#else
    throw std::invalid_argument("hierarchy " + h.name + " needs FCL, which this build lacks");
#endif
  } else {
    const DensitySpec& density = planned.density;  // the plan decided whether the trees are annotated
    with_volume(h.bv, [&]<class BV>(std::type_identity<BV>) {
      with_density(density.name, [&]<class D>(std::type_identity<D>) {
        if constexpr (DensityFor<D, BV>) {
          auto ta = store.tree<BV, D>(a, h, density, &info);
          auto tb = &a == &b ? ta : store.tree<BV, D>(b, h, density);
          out = std::make_unique<BvhlabHierarchy<BV, D>>(ta, tb);
        } else {
          throw std::invalid_argument("density " + std::string(D::name()) + " cannot annotate " +
                                      std::string(BV::name()) + " trees");
        }
      });
    });
  }
  out->model = info;
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// Ground truth: exact answers per pose group, cached on disk, cross-checked against CGAL on a sample.

using Truth = std::vector<std::vector<std::uint8_t>>;  // [group][pose] -> 0/1

class TruthCache {
 public:
  explicit TruthCache(std::filesystem::path dir) : dir_(std::move(dir)) {}

  std::optional<Truth> load(const std::string& key, const WorkloadSpec& workload, std::string* why) const {
    if (dir_.empty()) return std::nullopt;
    const auto file = file_of(key);
    if (!std::filesystem::exists(file)) return std::nullopt;
    try {
      const std::vector<std::byte> bytes = tree_cache_detail::read_file_bytes(file);
      Reader in{bytes};
      if (in.take(8) != std::string_view("BVHLGT01")) throw std::runtime_error("not a ground-truth file");
      if (in.u64() != ContentHash().update(key).digest())
        throw std::runtime_error("stale: made for another key");
      const std::uint64_t groups = in.u64();
      if (groups != workload.groups.size()) throw std::runtime_error("stale: wrong number of pose groups");
      Truth truth(groups);
      for (std::size_t g = 0; g < groups; ++g) {
        const std::uint64_t n = in.u64();
        if (n != workload.groups[g].poses.size()) throw std::runtime_error("stale: wrong number of poses");
        const std::string_view bits = in.take((n + 7) / 8);
        truth[g].resize(n);
        for (std::size_t i = 0; i < n; ++i)
          truth[g][i] = (static_cast<unsigned char>(bits[i / 8]) >> (i % 8)) & 1;
      }
      const std::size_t body = in.position;
      if (in.u64() != hash_bytes(std::span(bytes).first(body))) throw std::runtime_error("checksum mismatch");
      if (in.position != bytes.size()) throw std::runtime_error("trailing bytes");
      return truth;
    } catch (const std::exception& e) {
      *why = file.filename().string() + ": " + e.what();
      return std::nullopt;
    }
  }

  void store(const std::string& key, const Truth& truth, const LogFn& log) const {
    if (dir_.empty()) return;
    std::string out = "BVHLGT01";
    auto put = [&](std::uint64_t v) {
      for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
    };
    put(ContentHash().update(key).digest());
    put(truth.size());
    for (const auto& group : truth) {
      put(group.size());
      std::string bits((group.size() + 7) / 8, '\0');
      for (std::size_t i = 0; i < group.size(); ++i)
        if (group[i]) bits[i / 8] = static_cast<char>(bits[i / 8] | (1 << (i % 8)));
      out += bits;
    }
    put(hash_bytes(std::as_bytes(std::span(out.data(), out.size()))));
    try {
      tree_cache_detail::write_file_bytes(file_of(key), std::as_bytes(std::span(out.data(), out.size())));
    } catch (const std::exception& e) {
      log(std::string("truth cache: could not store (") + e.what() + ")");
    }
  }

  [[nodiscard]] std::filesystem::path file_of(const std::string& key) const {
    return dir_ / (ContentHash().update(key).hex() + ".truth");
  }

 private:
  struct Reader {
    std::span<const std::byte> bytes;
    std::size_t position = 0;
    std::string_view take(std::size_t n) {
      if (bytes.size() - position < n) throw std::runtime_error("truncated");
      std::string_view out(reinterpret_cast<const char*>(bytes.data()) + position, n);
      position += n;
      return out;
    }
    std::uint64_t u64() {
      const std::string_view raw = take(8);
      std::uint64_t v = 0;
      for (int i = 7; i >= 0; --i)
        v = (v << 8) | static_cast<unsigned char>(raw[static_cast<std::size_t>(i)]);
      return v;
    }
  };
  std::filesystem::path dir_;
};

Truth compute_truth(const WorkloadSpec& workload, const PreparedHierarchy& exact, unsigned threads) {
  Truth truth(workload.groups.size());
  for (std::size_t g = 0; g < workload.groups.size(); ++g) {
    const auto& poses = workload.groups[g].poses;
    truth[g].assign(poses.size(), 0);
    const unsigned workers =
        std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(poses.size() / 64 + 1)));
    std::vector<std::thread> pool;
    for (unsigned w = 0; w < workers; ++w)
      pool.emplace_back([&, w] {
        for (std::size_t i = w; i < poses.size(); i += workers) truth[g][i] = exact.exact_collides(poses[i]);
      });
    for (auto& t : pool) t.join();
  }
  return truth;
}

// ---------------------------------------------------------------------------------------------------------
// Objects.

ObjectData load_object(const SceneObject& spec) {
  ObjectData out;
  out.spec = &spec;
  out.mesh = load_scene_object(spec);
  const RigidTransform& p = spec.placement;
  std::string key = "mesh=" + ContentHash::to_hex(hash_file(spec.path)) +
                    "|normalize=" + (spec.normalize ? "1" : "0") + "|scale=" + g17(spec.scale) +
                    "|placement=";
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) key += g17(p.rotation(i, j)) + ",";
  for (int i = 0; i < 3; ++i) key += g17(p.translation(i)) + ",";
  out.key = key;
  return out;
}

struct CalibrationAccumulator {
  std::array<std::size_t, 10> count{};
  std::array<double, 10> probability_sum{};
  std::array<std::size_t, 10> colliding{};
};

std::string run_command(const std::string& command) {
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, pipe)) out += buf;
    pclose(pipe);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------

Mesh load_scene_object(const SceneObject& object) {
  if (object.path.empty()) throw MeshError(object.mesh + ": mesh not found");
  Mesh mesh = load_mesh(object.path).mesh;
  if (object.normalize) normalize_to_unit_cube(mesh);
  for (Vec3& v : mesh.vertices) v = object.placement.apply(v * object.scale);
  return mesh;
}

QueryOutcome run_query(const SceneObject& a, const SceneObject& b, const QueryRequest& request,
                       const RigidTransform& pose, const RunOptions& options) {
  QueryOutcome outcome;
  const LogFn log = options.log ? options.log : LogFn([](const std::string& m) { std::cerr << m << '\n'; });
  Scene scene;  // a one-hierarchy, one-strategy scene, so the plan decides the density as for a run
  scene.hierarchies = {request.hierarchy};
  scene.density = request.density;
  StrategySpec strategy;
  strategy.name = request.strategy.strategy;
  scene.strategies = {strategy};
  const StrategyInfo& info = strategy_info(strategy.name);
  if (info.needs_density && !info.accepts(request.density.name))
    throw std::invalid_argument("strategy " + strategy.name + " does not run on trees with density '" +
                                request.density.name + "'");
  if (request.hierarchy.is_fcl() && strategy.name != ExactStrategy::name())
    throw std::invalid_argument("FCL hierarchies answer exact first-contact queries only");
  const unsigned threads =
      options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  TreeStore store(options.cache_dir, outcome.stats, log, threads);
  const ObjectData object_a = load_object(a);
  const ObjectData object_b = &a == &b ? ObjectData{} : load_object(b);
  const ObjectData& ob = &a == &b ? object_a : object_b;
  const PlannedHierarchy planned{
      &scene.hierarchies.front(),
      scene.needs_density(scene.hierarchies.front()) ? scene.density : DensitySpec{},
      {request.strategy}};
  auto hierarchy = prepare(planned, object_a, ob, store);
  const auto start = Clock::now();
  outcome.result = hierarchy->query(request.strategy, pose);
  outcome.micros = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
  const auto models = store.models();
  outcome.model_a = hierarchy->model;
  outcome.model_b = models.back();
  return outcome;
}

BuildOutcome build_tree_file(const SceneObject& object, const HierarchySpec& hierarchy,
                             const DensitySpec& density, const std::filesystem::path& output,
                             unsigned threads, std::function<void(const std::string&)> log) {
  if (hierarchy.is_fcl()) throw std::invalid_argument("FCL models cannot be saved as bvhlab trees");
  BuildOutcome outcome;
  RunStats stats;
  TreeStore store({}, stats, std::move(log),
                  threads ? threads : std::max(1u, std::thread::hardware_concurrency()));
  const ObjectData data = load_object(object);
  std::vector<std::byte> bytes;
  with_volume(hierarchy.bv, [&]<class BV>(std::type_identity<BV>) {
    with_density(density.name, [&]<class D>(std::type_identity<D>) {
      if constexpr (DensityFor<D, BV>)
        bytes = save_tree_to_buffer(*store.tree<BV, D>(data, hierarchy, density, &outcome.model));
      else
        throw std::invalid_argument("density " + density.name + " cannot annotate " + hierarchy.bv +
                                    " trees");
    });
  });
  saved_tree_detail::write_file_atomically(output, bytes);
  outcome.file_bytes = std::filesystem::file_size(output);
  return outcome;
}

bool is_saved_tree(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, 8) && std::string_view(magic, 8) == "BVHLTREE";
}

namespace {

/// Calls f(tree) with the saved tree in `file`, typed by the BV and density its header names.
template <class F>
void with_saved_tree(const std::filesystem::path& file, F&& f) {
  const std::vector<std::byte> bytes = saved_tree_detail::read_file(file);
  const saved_tree_detail::Header header = saved_tree_detail::read_header(bytes, file.string());
  auto named = [&](auto&& dispatch) {
    try {
      dispatch();
    } catch (const SavedTreeError&) {
      throw;
    } catch (const std::invalid_argument& e) {  // an unknown BV or density name
      throw SavedTreeError("saved tree '" + file.string() + "': " + e.what());
    }
  };
  named([&] {
    with_volume(header.bv_name, [&]<class BV>(std::type_identity<BV>) {
      with_density(header.density_name, [&]<class D>(std::type_identity<D>) {
        f(load_tree_from_buffer<BV, D>(bytes, file.string()));
      });
    });
  });
}

}  // namespace

SavedTreeInfo peek_saved_tree(const std::filesystem::path& file) {
  SavedTreeInfo info;
  with_saved_tree(file, [&]<class BV, class D>(const Tree<BV, D>& tree) {
    info.bv = BV::name();
    info.density = D::name();
    info.annotation = D::describe(tree.density);
    info.nodes = tree.bvh.nodes().size();
    const BvhStats stats = tree.bvh.stats();
    info.triangles = stats.triangles;
  });
  return info;
}

QueryOutcome run_query_on_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                const StrategyVariant& strategy, const RigidTransform& pose) {
  const StrategyInfo& info = strategy_info(strategy.strategy);
  if (info.needs_polygons)
    throw std::invalid_argument("saved trees carry no polygons, and strategy " + strategy.strategy +
                                " tests triangles; give the meshes instead");
  QueryOutcome outcome;
  with_saved_tree(a, [&]<class BV, class D>(const Tree<BV, D>& tree_a) {
    with_saved_tree(b, [&]<class BV2, class D2>(const Tree<BV2, D2>& tree_b) {
      if constexpr (!std::is_same_v<BV, BV2> || !std::is_same_v<D, D2>) {
        throw std::invalid_argument("the two trees differ in BV or density (" + std::string(BV::name()) +
                                    ", " + D::describe(tree_a.density) + " vs " + std::string(BV2::name()) +
                                    ", " + D2::describe(tree_b.density) + ")");
      } else {
        with_strategy(strategy.strategy, [&]<class S>(std::type_identity<S>) {
          if constexpr (S::template accepts<D>) {
            const auto options = strategy_options<S>(strategy.values, strategy.budget);
            const auto start = Clock::now();
            outcome.result = S::query(tree_a, tree_b, pose, options);
            outcome.micros = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
          } else {
            throw std::invalid_argument("strategy " + strategy.strategy +
                                        " does not run on trees with density '" + std::string(D::name()) +
                                        "'");
          }
        });
        for (auto [model, tree, file] :
             {std::tuple{&outcome.model_a, &tree_a, &a}, std::tuple{&outcome.model_b, &tree_b, &b}}) {
          const BvhStats st = tree->bvh.stats();
          model->object = file->filename().string();
          model->hierarchy = model->bv = BV::name();
          model->annotation = D::describe(tree->density);
          model->triangles = st.triangles;
          model->nodes = st.nodes;
          model->depth = st.depth;
          model->model_bytes = double(st.nodes * st.bytes_per_node + D::memory_bytes(tree->density));
          model->bytes_per_triangle = st.triangles ? model->model_bytes / double(st.triangles) : 0;
          model->from_cache = true;
        }
      }
    });
  });
  return outcome;
}

Environment detect_environment() {
  Environment env;
  std::string cpu;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  utsname host{};
  std::string os =
      uname(&host) == 0 ? std::string(host.sysname) + " " + host.release + " " + host.machine : "";
  env.machine = (cpu.empty() ? std::string("unknown CPU") : cpu) + ", " +
                std::to_string(std::thread::hardware_concurrency()) + " threads, " + os;
#if defined(__clang__)
  env.compiler = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  env.compiler = std::string("gcc ") + __VERSION__;
#else
  env.compiler = "unknown";
#endif
  env.build_type = BVHLAB_BUILD_TYPE;
#ifdef BVHLAB_SOURCE_DIR
  env.git_commit = run_command("git -C '" + std::string(BVHLAB_SOURCE_DIR) +
                               "' describe --always --dirty --abbrev=12 2>/dev/null");
#endif
  if (env.git_commit.empty()) env.git_commit = "unknown";
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  env.timestamp = stamp;
  return env;
}

RunOutput run_scene(const Scene& scene, const RunOptions& options) {
  const auto wall_start = Clock::now();
  RunOutput output;
  output.scene_name = scene.name;
  output.scene_file = scene.file;
  output.scene = scene;
  output.environment = detect_environment();
  RunStats& stats = output.stats;
  const LogFn log = options.log ? options.log : LogFn([](const std::string& m) { std::cerr << m << '\n'; });
  const unsigned threads =
      options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());

  TreeStore store(options.cache_dir, stats, log, threads);
  const TruthCache truth_cache(options.cache_dir.empty() ? options.cache_dir : options.cache_dir / "truth");
  stats.clock_overhead_us = clock_overhead_us();

  for (const std::string& note : scene.notes) {
    stats.skipped.push_back(note);
    log(note);
  }
  // What runs where, and on which trees: decided by the plan.
  const RunPlan plan = plan_run(scene);
  for (const std::string& why : plan.skipped) {
    stats.skipped.push_back(why);
    log(why);
  }
  // Objects: loaded on first use.
  std::map<std::string, ObjectData> objects;
  auto object = [&](const std::string& name) -> const ObjectData& {
    auto it = objects.find(name);
    if (it == objects.end()) {
      const auto start = Clock::now();
      it = objects.emplace(name, load_object(*scene.object(name))).first;
      ++stats.meshes_loaded;
      stats.preprocess_seconds += seconds_since(start);
    }
    return it->second;
  };

  Progress progress(options.progress, plan.total_queries);
  std::map<std::string, CalibrationAccumulator> calibration;
  std::map<std::string, CalibrationBin> calibration_keys;
  std::vector<std::string> calibration_order;
  std::vector<QueryRecord> block_records;

  for (const ScenePair* pair : plan.pairs) {
    const ObjectData& a = object(pair->a);
    const ObjectData& b = object(pair->b);
    const std::string label = pair->label();

    std::vector<std::unique_ptr<PreparedHierarchy>> prepared;
    for (const PlannedHierarchy& h : plan.hierarchies) prepared.push_back(prepare(h, a, b, store));

    // Ground truth from the disk cache, else from the exact traversal on the first bvhlab hierarchy.
    const auto truth_start = Clock::now();
    const std::string truth_key = "truth v1|A=" + a.key + "|B=" + b.key + "|" + scene.workload.identity;
    std::string why;
    std::optional<Truth> truth = truth_cache.load(truth_key, scene.workload, &why);
    if (truth) {
      ++stats.truth_cache_hits;
    } else {
      if (!why.empty()) {
        ++stats.truth_cache_rejected;
        log("truth cache: rejected " + why + "; recomputing");
      }
      const PreparedHierarchy* exact = nullptr;
      for (std::size_t i = 0; i < plan.hierarchies.size() && !exact; ++i)
        if (!plan.hierarchies[i].hierarchy->is_fcl()) exact = prepared[i].get();
      std::unique_ptr<PreparedHierarchy> fallback;
      if (!exact) {  // an FCL-only scene: the truth still comes from bvhlab's exact traversal
        HierarchySpec aabb;
        aabb.bv = aabb.name = "aabb";
        fallback = std::make_unique<BvhlabHierarchy<Aabb, NoDensity>>(
            store.tree<Aabb, NoDensity>(a, aabb, {}), store.tree<Aabb, NoDensity>(b, aabb, {}));
        exact = fallback.get();
      }
      log("computing the ground truth of " + label + " (exact traversal)");
      truth = compute_truth(scene.workload, *exact, threads);
      ++stats.truth_computed;
      truth_cache.store(truth_key, *truth, log);
    }
    // Cross-check against CGAL on poses spread evenly over the whole workload.
    std::size_t total_poses = 0;
    for (const auto& group : scene.workload.groups) total_poses += group.poses.size();
    const std::size_t sample =
        std::min<std::size_t>(static_cast<std::size_t>(scene.report.cgal_sample), total_poses);
    if (sample > 0) {
      const CgalGroundTruth cgal(a.mesh, b.mesh);
      for (std::size_t k = 0; k < sample; ++k) {
        std::size_t index = (2 * k + 1) * total_poses / (2 * sample);
        std::size_t g = 0;
        while (index >= scene.workload.groups[g].poses.size())
          index -= scene.workload.groups[g++].poses.size();
        const bool expected = (*truth)[g][index];
        if (cgal.collides(scene.workload.groups[g].poses[index]) != expected) {
          ++stats.cgal_mismatches;
          log("ground truth: CGAL disagrees on " + label + " at distance " +
              g17(scene.workload.groups[g].distance) + ", pose " + std::to_string(index) + " (truth says " +
              (expected ? "collision" : "none") + ")");
        }
        ++stats.cgal_checked;
      }
    }
    stats.truth_seconds += seconds_since(truth_start);
    for (std::size_t g = 0; g < scene.workload.groups.size(); ++g) {
      TruthSummary summary{label, scene.workload.groups[g].distance, (*truth)[g].size(), 0};
      for (auto t : (*truth)[g]) summary.colliding += t;
      output.truth.push_back(summary);
    }

    // The timed queries: every hierarchy and strategy on the same poses, distance by distance. The poses run
    // in blocks, each block through every series in turn, so a slow spell of a shared machine (another
    // process, frequency changes) spreads over all series instead of landing on one; within a block the
    // caches stay warm.
    for (std::size_t g = 0; g < scene.workload.groups.size(); ++g) {
      const PoseGroup& group = scene.workload.groups[g];
      const auto& expected = (*truth)[g];
      const auto& planned = plan.hierarchies;
      std::vector<std::vector<std::vector<QueryRecord>>> series(planned.size());
      for (std::size_t i = 0; i < planned.size(); ++i) series[i].resize(planned[i].variants.size());
      const std::span<const RigidTransform> poses(group.poses);
      for (std::size_t begin = 0; begin < poses.size(); begin += kPoseBlock) {
        const auto block = poses.subspan(begin, std::min(kPoseBlock, poses.size() - begin));
        for (std::size_t i = 0; i < planned.size(); ++i)
          for (std::size_t v = 0; v < planned[i].variants.size(); ++v) {
            prepared[i]->run(planned[i].variants[v], block, options.warmup_queries, block_records);
            series[i][v].insert(series[i][v].end(), block_records.begin(), block_records.end());
          }
        char distance[16];
        std::snprintf(distance, sizeof distance, "%g", group.distance);
        std::size_t done = 0;
        for (const auto& h : planned) done += h.variants.size() * block.size();
        progress.advance(done, label + " d=" + distance);
      }
      for (std::size_t i = 0; i < planned.size(); ++i) {
        const HierarchySpec& h = *planned[i].hierarchy;
        const PreparedHierarchy& hierarchy = *prepared[i];
        for (std::size_t v = 0; v < planned[i].variants.size(); ++v) {
          const StrategyVariant& variant = planned[i].variants[v];
          const std::vector<QueryRecord>& records = series[i][v];
          ResultRow row;
          row.mesh = label;
          row.hierarchy = h.name;
          row.bv = h.bv;
          row.annotation = hierarchy.model.annotation;
          row.strategy = variant.strategy;
          row.label = variant.label();
          row.exact_strategy = strategy_info(variant.strategy).exact;
          row.p_min = variant.value_or("p_min", -1);
          row.budget = variant.budget_label();
          row.distance = group.distance;
          row.queries = records.size();
          row.model_bytes = hierarchy.model.model_bytes;
          row.bytes_per_triangle = hierarchy.model.bytes_per_triangle;
          std::size_t fp = 0, fn = 0, truth_yes = 0, answer_yes = 0, inexact = 0, exhausted = 0;
          double sum_us = 0, max_us = 0;
          Counters counters;
          const bool calibrate = !row.exact_strategy;
          const std::string cal_key = label + "\x1f" + h.name + "\x1f" + variant.label();
          for (std::size_t k = 0; k < records.size(); ++k) {
            const QueryRecord& r = records[k];
            const bool truly = expected[k] != 0;
            fp += r.collides && !truly;
            fn += !r.collides && truly;
            truth_yes += truly;
            answer_yes += r.collides;
            inexact += !r.exact;
            exhausted += r.budget_exhausted;
            const double micros = std::max(0.0, r.micros - stats.clock_overhead_us);
            sum_us += micros;
            max_us = std::max(max_us, micros);
            counters += r.counters;
            if (calibrate) {
              auto& acc = calibration[cal_key];
              const std::size_t bin =
                  std::min<std::size_t>(9, static_cast<std::size_t>(std::max(0.0, r.probability) * 10));
              ++acc.count[bin];
              acc.probability_sum[bin] += r.probability;
              acc.colliding[bin] += truly;
            }
          }
          if (calibrate && !calibration_keys.count(cal_key)) {
            calibration_keys[cal_key] = CalibrationBin{label, h.name, row.strategy, row.budget, row.p_min};
            calibration_order.push_back(cal_key);
          }
          const double n = std::max<double>(1.0, double(records.size()));
          row.truth_colliding_rate = double(truth_yes) / n;
          row.answer_colliding_rate = double(answer_yes) / n;
          row.fp_rate = double(fp) / n;
          row.fn_rate = double(fn) / n;
          row.inexact_rate = double(inexact) / n;
          row.budget_exhausted_rate = double(exhausted) / n;
          row.mean_time_us = sum_us / n;
          row.max_time_us = max_us;
          if (hierarchy.has_counters()) {
            row.bv_tests_per_query = double(counters.bv_tests) / n;
            row.triangle_tests_per_query = double(counters.triangle_tests) / n;
            row.nodes_visited_per_query = double(counters.nodes_visited) / n;
          } else {
            row.bv_tests_per_query = row.triangle_tests_per_query = row.nodes_visited_per_query =
                kNotApplicable;
          }
          stats.queries += records.size();
          stats.query_seconds += sum_us * 1e-6;
          output.rows.push_back(row);
        }
      }
    }
  }

  for (const std::string& key : calibration_order) {
    const auto& acc = calibration.at(key);
    for (std::size_t bin = 0; bin < 10; ++bin) {
      CalibrationBin out = calibration_keys.at(key);
      out.bin_low = double(bin) / 10;
      out.bin_high = double(bin + 1) / 10;
      out.count = acc.count[bin];
      out.mean_probability =
          acc.count[bin] ? acc.probability_sum[bin] / double(acc.count[bin]) : kNotApplicable;
      out.collision_frequency =
          acc.count[bin] ? double(acc.colliding[bin]) / double(acc.count[bin]) : kNotApplicable;
      output.calibration.push_back(out);
    }
  }
  output.models = store.models();
  const auto& counts = store.cache().counts();
  stats.tree_cache_hits = counts.hits;
  stats.tree_cache_rejected = counts.rejected;
  stats.tree_cache_stored = counts.stored;
  stats.wall_seconds = seconds_since(wall_start);
  return output;
}

}  // namespace bvhlab
