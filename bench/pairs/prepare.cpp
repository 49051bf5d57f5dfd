#include "bench/pairs/prepare.hpp"

#include "bench/pairs/measure.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/content_hash.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/tree_cache.hpp"
#include "traversal/strategy_names.hpp"

#ifdef BVHLAB_HAVE_FCL
#include <fcl/narrowphase/collision.h>
#include "bench/core/fcl_model.hpp"
#endif

#include <algorithm>
#include <cstdio>
#include <thread>
#include <type_traits>

namespace bvhlab {

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void describe_tree(ModelInfo& m, const TreeInfo& tree) {
  m.bv = tree.bv;
  m.annotation = tree.annotation;
  m.units = tree.units.file;
  m.triangles = tree.triangles;
  m.nodes = tree.nodes;
  m.depth = tree.depth;
  m.density_bytes = tree.density_bytes;
  m.model_bytes = tree.model_bytes;
  m.bytes_per_triangle = tree.triangles ? m.model_bytes / double(tree.triangles) : 0;
  m.build_seconds = tree.build_seconds;
  m.annotate_seconds = tree.annotate_seconds;
}

void PreparedHierarchy::run(const StrategyVariant& variant, std::span<const RigidTransform>, int,
                            std::vector<QueryRecord>&, CoherentState&) const {
  throw std::logic_error("runner: " + variant.label() + " runs coherent on bvhlab trees only");
}

namespace {

/// Two trees of the run-time layer, each series prepared once per call (no dispatch per query).
class BvhlabHierarchy final : public PreparedHierarchy {
 public:
  BvhlabHierarchy(AnyTree a, AnyTree b)
      : a_(std::move(a)), b_(std::move(b)), exact_(a_.prepare(b_, StrategyVariant{})) {}

  void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
           std::vector<QueryRecord>& out) const override {
    a_.prepare(b_, variant)->time(poses, warmup, out);
  }
  void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
           std::vector<QueryRecord>& out, CoherentState& state) const override {
    a_.prepare(b_, variant)->time(poses, warmup, out, state);
  }
  [[nodiscard]] Result query(const StrategyVariant& variant, const RigidTransform& pose) const override {
    Result result;
    a_.prepare(b_, variant)->run(std::span(&pose, 1), [&](std::size_t, const Result& r) { result = r; });
    return result;
  }
  [[nodiscard]] bool exact_collides(const RigidTransform& pose) const override {
    bool collides = false;
    exact_->run(std::span(&pose, 1), [&](std::size_t, const Result& r) { collides = r.collides; });
    return collides;
  }
  [[nodiscard]] Box world_box(const RigidTransform& pose) const override { return a_.world_box(pose); }
  [[nodiscard]] std::pair<const AnyTree*, const AnyTree*> trees() const override { return {&a_, &b_}; }

 private:
  AnyTree a_, b_;
  std::unique_ptr<PreparedQuery> exact_;  ///< the ground truth's query, made once
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
    if (variant.wide)  // the scene parser refuses it (fcl_refusal)
      throw std::logic_error("runner: FCL hierarchies have no wide layout (" + variant.label() + ")");
    if (variant.strategy == kDistanceStrategyName)
      timed_series(poses, warmup, out, [&](const RigidTransform& p) { return distance(p); });
    else if (variant.strategy == kExactStrategyName)
      timed_series(poses, warmup, out, [&](const RigidTransform& p) { return query(p); });
    else
      throw std::logic_error("runner: FCL hierarchies run the exact and distance strategies only");
  }
  [[nodiscard]] bool exact_collides(const RigidTransform& pose) const override {
    return query(pose).collides;
  }
  [[nodiscard]] bool has_counters() const override { return false; }
  [[nodiscard]] Box world_box(const RigidTransform&) const override {
    throw std::invalid_argument(
        "FCL models give no world boxes here (bench_broad_phase times FCL's managers)");
  }
  [[nodiscard]] Result query(const StrategyVariant& variant, const RigidTransform& pose) const override {
    if (variant.strategy == kDistanceStrategyName) return distance(pose);
    if (variant.strategy != kExactStrategyName)
      throw std::invalid_argument("FCL hierarchies answer exact first-contact and distance queries only");
    return query(pose);
  }

 private:
  Result query(const RigidTransform& pose) const {
    Result r;
    r.collides = fcl_collides(*a_, *b_, pose);
    r.probability = r.collides ? 1 : 0;
    return r;
  }
  /// fcl::distance, as the distance strategy answers it (FCL's OBB has no distance: scenes refuse it).
  Result distance(const RigidTransform& pose) const {
    if constexpr (!std::is_same_v<FclBV, fcl::OBBRSSd>) {
      throw std::logic_error("runner: FCL's OBB models have no distance");
    } else {
      const FclDistance d = fcl_distance(*a_, *b_, pose);
      Result r;
      r.collides = d.distance == 0;
      r.probability = r.collides ? 1 : 0;
      r.proximity = Proximity{d.distance,
                              d.distance,
                              {d.on_a.x(), d.on_a.y(), d.on_a.z()},
                              {d.on_b.x(), d.on_b.y(), d.on_b.z()},
                              std::nullopt};
      return r;
    }
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

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Trees: from the run's memory, else the disk cache, else built (and then cached).

class TreeStore {
 public:
  TreeStore(const std::filesystem::path& cache_dir, RunStats& stats, LogFn log, unsigned threads)
      : cache_(cache_dir.empty() ? cache_dir : cache_dir / "trees", log),
        stats_(stats),
        log_(std::move(log)),
        threads_(threads) {}

  /// The tree of `object` for hierarchy `h` with `density`: from this run's memory, else the disk cache,
  /// else built (a density starts from the plain tree, itself remembered).
  AnyTree tree(const ObjectData& object, const HierarchySpec& h, const DensitySpec& density,
               ModelInfo* info = nullptr) {
    const std::string annotation = density.label();
    const std::string key = plain_key(object, h) + (annotation == "none" ? "" : "|" + annotation);
    if (auto hit = trees_.find(key); hit != trees_.end()) {
      if (info) *info = infos_.at(key);
      return hit->second;
    }
    CachedTreeTimes times;
    auto start = Clock::now();
    std::optional<AnyTree> tree = cache_.load(key, h.bv, object.mesh, &times, annotation);
    stats_.preprocess_seconds += seconds_since(start);
    const bool from_cache = tree.has_value();
    if (!tree) {
      tree.emplace(make_tree(object, h, density, times));
      cache_.store(key, *tree, times);
    }
    trees_.emplace(key, *tree);
    remember(key, describe(tree->info(), object, h, annotation, times, from_cache), info);
    return *tree;
  }

#ifdef BVHLAB_HAVE_FCL
  template <class FclBV>
  std::shared_ptr<const fcl::BVHModel<FclBV>> fcl_model(const ObjectData& object, const HierarchySpec& h,
                                                        ModelInfo* info) {
    const std::string key = "fcl|" + h.bv + "|" + object.key;
    using Model = fcl::BVHModel<FclBV>;
    if (auto hit = models_.find(key); hit != models_.end()) {
      *info = infos_.at(key);
      return std::static_pointer_cast<const Model>(hit->second);
    }
    log_("building " + h.bv + " model of " + object.spec->name);
    const auto start = Clock::now();
    const auto model = make_fcl_model<FclBV>(object.mesh);
    ++stats_.fcl_models_built;
    ModelInfo m;
    m.object = object.spec->name;
    m.hierarchy = h.name;
    m.bv = h.bv;
    m.annotation = "none";
    m.units = object.units;
    m.triangles = object.mesh.triangle_count();
    m.nodes = static_cast<std::size_t>(model->getNumBVs());
    m.model_bytes = double(m.nodes) * double(sizeof(fcl::BVNode<FclBV>));
    m.bytes_per_triangle = m.triangles ? m.model_bytes / double(m.triangles) : 0;
    m.build_seconds = seconds_since(start);
    stats_.preprocess_seconds += m.build_seconds;
    models_[key] = model;
    remember(key, m, info);
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
  AnyTree make_tree(const ObjectData& object, const HierarchySpec& h, const DensitySpec& density,
                    CachedTreeTimes& times) {
    if (density.name == "none") {
      log_("building " + h.bv + " tree of " + object.spec->name + " (" +
           std::to_string(object.mesh.triangle_count()) + " triangles)");
      BuildOptions options = h.build;
      options.threads = threads_;
      options.progress = percent_logger(log_, "building: triangles placed", object.mesh.triangle_count());
      AnyTree built = AnyTree::build(object.mesh, MeshUnits{object.units, 1}, h.bv, DensitySpec{}, options);
      ++stats_.trees_built;
      times.build_seconds = built.info().build_seconds;
      return built;
    }
    ModelInfo plain_info;
    const AnyTree plain = tree(object, h, DensitySpec{}, &plain_info);
    const auto start = Clock::now();
    log_("annotating " + h.bv + " tree of " + object.spec->name + " (" + density.label() + ")");
    AnnotationContext context;
    context.threads = threads_;
    context.progress = percent_logger(log_, "annotating", object.mesh.triangle_count());
    AnnotateStats annotate_stats;
    AnyTree annotated = plain.annotated(density, context, &annotate_stats);
    ++stats_.trees_annotated;
    stats_.annotation_clip_calls += annotate_stats.clip_calls;
    times.build_seconds = plain_info.build_seconds;
    times.annotate_seconds = annotate_stats.seconds;
    stats_.preprocess_seconds += seconds_since(start);
    return annotated;
  }

  static std::string plain_key(const ObjectData& object, const HierarchySpec& h) {
    return "bvhlab-tree v1|" + object.key + "|bv=" + h.bv +
           "|split=" + std::string(to_string(h.build.split)) +
           "|leaf=" + std::to_string(h.build.max_leaf_triangles);
  }

  static ModelInfo describe(const TreeInfo& tree, const ObjectData& object, const HierarchySpec& h,
                            const std::string& annotation, const CachedTreeTimes& times, bool from_cache) {
    ModelInfo m;
    describe_tree(m, tree);
    m.object = object.spec->name;
    m.hierarchy = h.name;
    m.bv = h.bv;
    m.annotation = annotation;
    m.units = object.units;
    m.build_seconds = times.build_seconds;
    m.annotate_seconds = times.annotate_seconds;
    m.from_cache = from_cache;
    return m;
  }

  void remember(const std::string& key, const ModelInfo& info, ModelInfo* out) {
    infos_[key] = info;
    order_.push_back(key);
    if (out) *out = info;
  }

  TreeCache cache_;
  RunStats& stats_;
  LogFn log_;
  unsigned threads_;
  std::map<std::string, AnyTree> trees_;
  std::map<std::string, std::shared_ptr<const void>> models_;  ///< FCL's
  std::map<std::string, ModelInfo> infos_;
  std::vector<std::string> order_;
};
// ---------------------------------------------------------------------------------------------------------
// Objects.

namespace {

/// The object's mesh, normalised (if asked), scaled and placed; `units` receives the normalisation and
/// `warnings` (if given) the loader's warnings.
Mesh load_scene_mesh(const SceneObject& object, TreeUnits& units,
                     std::vector<std::string>* warnings = nullptr) {
  if (object.path.empty()) throw MeshError(object.mesh + ": mesh not found");
  LoadedMesh loaded = load_mesh(object.path);
  if (warnings) *warnings = std::move(loaded.report.warnings);
  Mesh mesh = std::move(loaded.mesh);
  units = object.normalize ? normalize_mesh(mesh) : TreeUnits{};
  for (Vec3& v : mesh.vertices) v = object.placement.apply(v * object.scale);
  return mesh;
}

}  // namespace

Mesh load_scene_object(const SceneObject& object) {
  TreeUnits units;
  return load_scene_mesh(object, units);
}

ObjectData load_object(const SceneObject& spec) {
  ObjectData out;
  out.spec = &spec;
  out.mesh = load_scene_mesh(spec, out.units, &out.warnings);
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

// ---------------------------------------------------------------------------------------------------------
// The stage: objects once per run, trees through the store.

Preparation::Preparation(const std::filesystem::path& cache_dir, RunStats& stats, LogFn log, unsigned threads)
    : store_(std::make_unique<TreeStore>(cache_dir, stats, log, threads)),
      stats_(stats),
      log_(std::move(log)) {}

Preparation::~Preparation() = default;

const ObjectData& Preparation::object(const SceneObject& spec) {
  auto it = objects_.find(spec.name);
  if (it == objects_.end()) {
    const auto start = Clock::now();
    it = objects_.emplace(spec.name, load_object(spec)).first;
    if (it->second.units.normalized) log_(spec.name + ": " + it->second.units.describe());
    for (const std::string& warning : it->second.warnings) log_(spec.name + ": warning: " + warning);
    ++stats_.meshes_loaded;
    stats_.preprocess_seconds += seconds_since(start);
  }
  return it->second;
}

PreparedPair Preparation::pair(const Scene& scene, const ScenePair& pair, const RunPlan& plan) {
  PreparedPair out;
  out.a = &object(*scene.object(pair.a));
  out.b = &object(*scene.object(pair.b));
  out.label = pair.label();
  for (const PlannedHierarchy& h : plan.hierarchies) out.hierarchies.push_back(hierarchy(h, *out.a, *out.b));
  return out;
}

/// The planned hierarchy's trees (or FCL models) for objects a and b, ready to time.
std::unique_ptr<PreparedHierarchy> Preparation::hierarchy(const PlannedHierarchy& planned,
                                                          const ObjectData& a, const ObjectData& b) {
  const HierarchySpec& h = *planned.hierarchy;
  std::unique_ptr<PreparedHierarchy> out;
  ModelInfo info;
  if (h.is_fcl()) {
#ifdef BVHLAB_HAVE_FCL
    if (h.bv == "fcl_obb") {
      auto ma = store_->fcl_model<fcl::OBBd>(a, h, &info);
      ModelInfo ignored;
      auto mb = store_->fcl_model<fcl::OBBd>(b, h, &ignored);
      out = std::make_unique<FclHierarchy<fcl::OBBd>>(ma, mb);
    } else {
      auto ma = store_->fcl_model<fcl::OBBRSSd>(a, h, &info);
      ModelInfo ignored;
      auto mb = store_->fcl_model<fcl::OBBRSSd>(b, h, &ignored);
      out = std::make_unique<FclHierarchy<fcl::OBBRSSd>>(ma, mb);
    }
#else
    throw std::invalid_argument("hierarchy " + h.name + " needs FCL, which this build lacks");
#endif
  } else {
    const DensitySpec& density = planned.density;  // the plan decided whether the trees are annotated
    AnyTree ta = store_->tree(a, h, density, &info);
    AnyTree tb = &a == &b ? ta : store_->tree(b, h, density);
    if (std::any_of(planned.variants.begin(), planned.variants.end(),
                    [](const StrategyVariant& v) { return v.wide; }))
      info.wide_bytes = ta.wide_layout_bytes();
    out = std::make_unique<BvhlabHierarchy>(std::move(ta), std::move(tb));
  }
  out->model = info;
  return out;
}

std::unique_ptr<PreparedHierarchy> Preparation::plain_aabb(const ObjectData& a, const ObjectData& b) {
  HierarchySpec aabb;
  aabb.bv = aabb.name = "aabb";
  return std::make_unique<BvhlabHierarchy>(store_->tree(a, aabb, {}), store_->tree(b, aabb, {}));
}

std::vector<ModelInfo> Preparation::models() const {
  return store_->models();
}

void Preparation::count_cache(RunStats& stats) const {
  const auto& counts = store_->cache().counts();
  stats.tree_cache_hits = counts.hits;
  stats.tree_cache_rejected = counts.rejected;
  stats.tree_cache_stored = counts.stored;
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
  const std::vector<std::byte> bytes =
      store.tree(data, hierarchy, density, &outcome.model).save_bytes(output.string());
  saved_tree_detail::write_file_atomically(output, bytes);
  outcome.file_bytes = std::filesystem::file_size(output);
  return outcome;
}

}  // namespace bvhlab
