#include "bench/deform/deform.hpp"

#include "adb/update.hpp"
#include "bench/pairs/measure.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/report_tables.hpp"
#include "bvh/deform.hpp"
#include "bvh/mesh_sequence.hpp"
#include "engine/policies.hpp"
#include "engine/registry.hpp"

#ifdef BVHLAB_HAVE_FCL
#include <fcl/narrowphase/collision.h>
#include "bench/core/fcl_model.hpp"
#endif

#include <algorithm>
#include <map>

namespace bvhlab {

namespace {

/// The deforming object's mesh in each frame: procedural or read from its files.
class FrameSource {
 public:
  FrameSource(const DeformSpec& spec, Mesh rest) : spec_(spec), rest_(std::move(rest)) {
    if (!spec.frame_files.empty()) sequence_.emplace(spec.frame_files);
    if (!spec.deformation.empty()) deformation_ = parse_deformation(spec.deformation);
  }
  [[nodiscard]] Mesh frame(int f) const {
    if (sequence_) return sequence_->frame(static_cast<std::size_t>(f));
    // Frame 0 is the rest shape the trees are built on; frames 1..frames sample one period.
    return deform(rest_, deformation_,
                  frame_time(static_cast<std::size_t>(f), std::size_t(spec_.frames) + 1));
  }

 private:
  const DeformSpec& spec_;
  Mesh rest_;
  Deformation deformation_;
  std::optional<MeshSequence> sequence_;
};

/// What every hierarchy answers against in one frame.
struct FrameTruth {
  int frame = 0;
  const Mesh* mesh = nullptr;  ///< the deforming object this frame
  std::vector<RigidTransform> poses;
  std::vector<bool> collides;
};

/// Counts `answers` against the truth into `row` and sets its median query time.
void score(DeformRow& row, const FrameTruth& truth, const std::vector<QueryRecord>& answers) {
  std::vector<double> micros;
  for (std::size_t k = 0; k < answers.size(); ++k) {
    const bool truth_k = truth.collides[k], answer = answers[k].collides;
    row.colliding += truth_k;
    row.answered += answer;
    row.missed += truth_k && !answer;
    row.false_pairs += !truth_k && answer;
    micros.push_back(answers[k].micros);
  }
  row.queries = answers.size();
  for (double m : micros) row.query_total_micros += m;
  row.query_micros = report_tables::median(std::move(micros));
}

/// Every variant of the scene's strategies that runs on `h`: exact ones on plain trees, the others on
/// trees with a density.
std::vector<StrategyVariant> variants_on(const Scene& scene, const HierarchySpec& h, bool with_density) {
  std::vector<StrategyVariant> out;
  for (const StrategySpec& s : scene.strategies) {
    if (!scene.applies(s, h) || strategy_info(s.name).needs_density != with_density) continue;
    for (StrategyVariant& v : expand(s)) out.push_back(std::move(v));
  }
  return out;
}

/// Times `variant` on trees a and b over the frame's poses.
template <class TreeA, class TreeB>
std::vector<QueryRecord> answer(const StrategyVariant& variant, const TreeA& a, const TreeB& b,
                                const FrameTruth& truth, int warmup) {
  using D = typename TreeA::DensityType;
  std::vector<QueryRecord> out;
  with_strategy(variant.strategy, [&]<class S>(std::type_identity<S>) {
    if constexpr (S::template accepts<D>) {
      const auto options = strategy_options<S>(variant.values, variant.budget);
      timed_series(truth.poses, warmup, out,
                   [&](const RigidTransform& p) { return S::query(a, b, p, options); });
    } else {
      throw std::invalid_argument(strategy_info(variant.strategy).refusal(D::name()));
    }
  });
  return out;
}

/// Count error of `counts` against the exact recount: mean |difference| and the share counted below it.
std::pair<double, double> count_error(const AdbStorage& counts, const AdbStorage& exact) {
  const auto& c = counts.possible_collision_cells;
  const auto& e = exact.possible_collision_cells;
  double sum = 0;
  std::size_t under = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    sum += std::abs(int(c[i]) - int(e[i]));
    under += c[i] < e[i];
  }
  return {c.empty() ? 0 : sum / double(c.size()), c.empty() ? 0 : double(under) / double(c.size())};
}

/// One hierarchy of the scene, following the deforming object frame by frame.
class DeformHierarchy {
 public:
  virtual ~DeformHierarchy() = default;
  /// Brings the trees to the frame's mesh and answers its poses: appends the frame's rows.
  virtual void frame(const FrameTruth& truth, std::vector<DeformRow>& rows) = 0;
};

DeformRow row_of(const FrameTruth& truth, const HierarchySpec& h, std::string update,
                 const StrategyVariant& v) {
  DeformRow row;
  row.frame = truth.frame;
  row.hierarchy = h.name;
  row.update = std::move(update);
  row.series = v.label();
  row.exact_strategy = strategy_info(v.strategy).exact;
  return row;
}

/// An ADB tree kept up to date by one density-update policy; the policy's state is held by `update`.
template <class BV>
struct UpdatedTree {
  std::string label;
  Tree<BV, AdbDensity> tree;
  std::function<DensityUpdateStats(Tree<BV, AdbDensity>&)> update;  ///< after the tree was refitted
  std::function<void(Tree<BV, AdbDensity>&)> restart;               ///< after the tree was rebuilt
};

template <class BV>
UpdatedTree<BV> make_updated(const DensityUpdateSpec& spec, const Tree<BV, AdbDensity>& rest) {
  return with_density_update(spec.name, [&]<class U>(std::type_identity<U>) {
    const auto params = U::make_params(spec.values);
    auto state = std::make_shared<typename U::State>(U::start(rest.bvh, rest.density, params));
    UpdatedTree<BV> out{spec.label(), rest, {}, {}};
    out.update = [state](Tree<BV, AdbDensity>& t) {
      DensityUpdateStats stats;
      U::update(t.bvh, t.density, *state, AnnotationContext{1, {}}, &stats);
      return stats;
    };
    out.restart = [state, params](Tree<BV, AdbDensity>& t) { *state = U::start(t.bvh, t.density, params); };
    return out;
  });
}

template <class BV>
class BvhDeform final : public DeformHierarchy {
 public:
  BvhDeform(const Scene& scene, const HierarchySpec& h, const Mesh& rest, const Mesh& other, int warmup)
      : scene_(scene),
        h_(h),
        warmup_(warmup),
        refit_{Bvh<BV>::build(rest, h.build), {}},
        other_{Bvh<BV>::build(other, h.build), {}},
        exact_(variants_on(scene, h, false)),
        adb_(variants_on(scene, h, true)) {
    if (adb_.empty()) return;
    params_ = density_params<AdbDensity>(scene.density_of(h).values);
    const auto annotated_rest = annotate_tree<AdbDensity>(refit_.bvh, params_, {1, {}});
    other_adb_ = annotate_tree<AdbDensity>(other_.bvh, params_, {1, {}});
    for (const DensityUpdateSpec& spec : scene.deform->density_updates)
      updated_.push_back(make_updated<BV>(spec, annotated_rest));
  }

  void frame(const FrameTruth& truth, std::vector<DeformRow>& rows) override {
    const auto start = Clock::now();
    refit_.bvh.refit(*truth.mesh, scene_.deform->refit_by_fit ? RefitMethod::Fit : RefitMethod::Merge);
    const double degradation = refit_.bvh.degradation();
    const bool rebuilt = degradation > scene_.deform->rebuild_degradation;
    if (rebuilt) refit_.bvh = Bvh<BV>::build(*truth.mesh, h_.build);
    const double refit_micros = micros_since(start);
    const auto rebuild_start = Clock::now();
    const Tree<BV, NoDensity> rebuilt_tree{Bvh<BV>::build(*truth.mesh, h_.build), {}};
    const double rebuild_micros = micros_since(rebuild_start);
    for (const StrategyVariant& v : exact_) {
      DeformRow refit_row = row_of(truth, h_, "refit", v);
      refit_row.degradation = degradation;
      refit_row.rebuilt = rebuilt;
      refit_row.tree_micros = refit_micros;
      score(refit_row, truth, answer(v, refit_, other_, truth, warmup_));
      rows.push_back(std::move(refit_row));
      DeformRow rebuild_row = row_of(truth, h_, "rebuild", v);
      rebuild_row.tree_micros = rebuild_micros;
      score(rebuild_row, truth, answer(v, rebuilt_tree, other_, truth, warmup_));
      rows.push_back(std::move(rebuild_row));
    }
    if (!adb_.empty())
      adb_frame(truth, rebuilt, degradation, refit_micros, rebuilt_tree, rebuild_micros, rows);
  }

 private:
  void adb_frame(const FrameTruth& truth, bool rebuilt, double degradation, double refit_micros,
                 const Tree<BV, NoDensity>& rebuilt_tree, double rebuild_micros,
                 std::vector<DeformRow>& rows) {
    const auto annotate_start = Clock::now();
    const auto fresh = annotate_tree<AdbDensity>(rebuilt_tree.bvh, params_, {1, {}});
    const double annotate_micros = micros_since(annotate_start);
    add_adb_rows(truth, "rebuild + annotate", fresh, rebuild_micros, annotate_micros, 1, false, nullptr,
                 rows);
    const AdbStorage recount = AdbDensity::annotate(refit_.bvh, params_, {1, {}}, nullptr);
    for (UpdatedTree<BV>& u : updated_) {
      u.tree.bvh = refit_.bvh;
      const auto update_start = Clock::now();
      if (rebuilt) {
        u.tree.density = AdbDensity::annotate(u.tree.bvh, params_, {1, {}}, nullptr);
        u.restart(u.tree);
      } else {
        u.update(u.tree);
      }
      const double update_micros = micros_since(update_start);
      add_adb_rows(truth, "refit + " + u.label, u.tree, refit_micros, update_micros, degradation, rebuilt,
                   &recount, rows);
    }
  }

  void add_adb_rows(const FrameTruth& truth, const std::string& update, const Tree<BV, AdbDensity>& tree,
                    double tree_micros, double density_micros, double degradation, bool rebuilt,
                    const AdbStorage* recount, std::vector<DeformRow>& rows) {
    for (const StrategyVariant& v : adb_) {
      DeformRow row = row_of(truth, h_, update, v);
      row.tree_micros = tree_micros;
      row.density_micros = density_micros;
      row.degradation = degradation;
      row.rebuilt = rebuilt;
      std::tie(row.count_error, row.under_counted) =
          recount ? count_error(tree.density, *recount) : std::pair<double, double>{0, 0};
      score(row, truth, answer(v, tree, other_adb_, truth, warmup_));
      rows.push_back(std::move(row));
    }
  }

  const Scene& scene_;
  const HierarchySpec& h_;
  int warmup_;
  Tree<BV, NoDensity> refit_, other_;
  std::vector<StrategyVariant> exact_, adb_;
  AdbParams params_;
  Tree<BV, AdbDensity> other_adb_;
  std::vector<UpdatedTree<BV>> updated_;
};

#ifdef BVHLAB_HAVE_FCL
/// An FCL hierarchy: its model of A updated and refitted (FCL's own bottom-up refit), or rebuilt.
template <class FclBV>
class FclDeform final : public DeformHierarchy {
 public:
  FclDeform(const Scene& scene, const HierarchySpec& h, const Mesh& rest, const Mesh& other, int warmup)
      : h_(h),
        warmup_(warmup),
        exact_(variants_on(scene, h, false)),
        refit_(make_fcl_model<FclBV>(rest)),
        other_(make_fcl_model<FclBV>(other)) {}

  void frame(const FrameTruth& truth, std::vector<DeformRow>& rows) override {
    const auto start = Clock::now();
    refit_->beginUpdateModel();
    refit_->updateSubModel(fcl_points(*truth.mesh));
    refit_->endUpdateModel(true, true);
    const double refit_micros = micros_since(start);
    const auto rebuild_start = Clock::now();
    const auto rebuilt = make_fcl_model<FclBV>(*truth.mesh);
    const double rebuild_micros = micros_since(rebuild_start);
    for (const StrategyVariant& v : exact_) {
      add_row(truth, "fcl refit", v, *refit_, refit_micros, rows);
      add_row(truth, "fcl rebuild", v, *rebuilt, rebuild_micros, rows);
    }
  }

 private:
  void add_row(const FrameTruth& truth, const std::string& update, const StrategyVariant& v,
               const fcl::BVHModel<FclBV>& model, double micros, std::vector<DeformRow>& rows) const {
    DeformRow row = row_of(truth, h_, update, v);
    row.tree_micros = micros;
    std::vector<QueryRecord> answers;
    timed_series(truth.poses, warmup_, answers, [&](const RigidTransform& pose) {
      Result r;
      r.collides = fcl_collides(model, *other_, pose);
      return r;
    });
    score(row, truth, answers);
    rows.push_back(std::move(row));
  }

  const HierarchySpec& h_;
  int warmup_;
  std::vector<StrategyVariant> exact_;
  std::shared_ptr<fcl::BVHModel<FclBV>> refit_, other_;
};
#endif

std::unique_ptr<DeformHierarchy> make_hierarchy(const Scene& scene, const HierarchySpec& h, const Mesh& rest,
                                                const Mesh& other, int warmup) {
  if (h.is_fcl()) {
#ifdef BVHLAB_HAVE_FCL
    if (h.bv == "fcl_obb") return std::make_unique<FclDeform<fcl::OBBd>>(scene, h, rest, other, warmup);
    return std::make_unique<FclDeform<fcl::OBBRSSd>>(scene, h, rest, other, warmup);
#else
    throw std::invalid_argument("hierarchy " + h.name + ": this build has no FCL");
#endif
  }
  std::unique_ptr<DeformHierarchy> out;
  with_volume(h.bv, [&]<class BV>(std::type_identity<BV>) {
    out = std::make_unique<BvhDeform<BV>>(scene, h, rest, other, warmup);
  });
  return out;
}

std::vector<RigidTransform> all_poses(const DeformSpec& spec) {
  std::vector<RigidTransform> poses;
  for (const PoseGroup& g : spec.poses) poses.insert(poses.end(), g.poses.begin(), g.poses.end());
  return poses;
}

/// The truth of one frame: a fresh AABB tree of the deformed mesh, exact traversal against B's.
FrameTruth frame_truth(int frame, const Mesh& mesh, const Bvh<Aabb>& other,
                       std::vector<RigidTransform> poses) {
  FrameTruth truth{frame, &mesh, std::move(poses), {}};
  const Bvh<Aabb> tree = Bvh<Aabb>::build(mesh);
  for (const RigidTransform& pose : truth.poses)
    truth.collides.push_back(query_exact(tree, other, pose).collides);
  return truth;
}

}  // namespace

DeformOutput run_deform(const Scene& scene, const RunOptions& options) {
  if (!scene.deform) throw std::invalid_argument("run_deform: the scene has no \"deform\" section");
  const DeformSpec& spec = *scene.deform;
  const ObjectData object = load_object(*scene.object(spec.object));
  const ObjectData other = load_object(*scene.object(spec.other));
  // Frame files replace the object's own mesh: the first file is the rest shape.
  const FrameSource source(spec, object.mesh);
  const Mesh rest = spec.frame_files.empty() ? object.mesh : source.frame(0);
  DeformOutput out;
  out.scene = scene.name;
  out.object = spec.object;
  out.other = spec.other;
  out.deformation = spec.frame_files.empty() ? spec.deformation : "frame files";
  out.triangles = rest.triangle_count();
  out.frames = spec.frame_files.empty() ? spec.frames : spec.frames - 1;
  out.notes = scene.notes;
  std::vector<std::unique_ptr<DeformHierarchy>> hierarchies;
  for (const HierarchySpec& h : scene.hierarchies)
    hierarchies.push_back(make_hierarchy(scene, h, rest, other.mesh, options.warmup_queries));
  const Bvh<Aabb> other_tree = Bvh<Aabb>::build(other.mesh);
  const std::vector<RigidTransform> poses = all_poses(spec);
  out.poses = poses.size();
  for (int f = 1; f <= out.frames; ++f) {
    const Mesh mesh = source.frame(f);
    const FrameTruth truth = frame_truth(f, mesh, other_tree, poses);
    for (auto& h : hierarchies) h->frame(truth, out.rows);
    if (options.log)
      options.log("frame " + std::to_string(f) + " of " + std::to_string(out.frames) + " done");
  }
  return out;
}

}  // namespace bvhlab
