#include "bench/deform/deform.hpp"

#include "bench/pairs/prepare.hpp"
#include "bench/report_tables.hpp"
#include "bvh/deform.hpp"
#include "bvh/mesh_sequence.hpp"
#include "engine/deforming.hpp"
#include "engine/policies.hpp"
#include "traversal/coherent_state.hpp"

#ifdef BVHLAB_HAVE_FCL
#include <fcl/narrowphase/collision.h>
#include "bench/core/fcl_model.hpp"
#endif

#include <algorithm>
#include <map>
#include <optional>

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
    row.bv_tests += answers[k].counters.bv_tests;
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

/// One state per pose for a coherent series, carried from frame to frame while its tree is refitted.
using PoseStates = std::vector<CoherentState>;

/// Times `variant` with `a` fixed and `b` moved over the frame's poses. A coherent variant continues each
/// pose's state in `states` (made when empty): the same pose, one frame later.
std::vector<QueryRecord> answer(const StrategyVariant& variant, const AnyTree& a, const AnyTree& b,
                                const FrameTruth& truth, int warmup, PoseStates& states) {
  std::vector<QueryRecord> out;
  const auto prepared = a.prepare(b, variant);
  if (!prepared->coherent()) {
    prepared->time(truth.poses, warmup, out);
    return out;
  }
  if (states.empty()) states.resize(truth.poses.size());
  prepared->time_per_pose(truth.poses, warmup, out, states);
  return out;
}

/// What a tree made anew this frame carries over: nothing.
std::vector<QueryRecord> answer_fresh(const StrategyVariant& variant, const AnyTree& a, const AnyTree& b,
                                      const FrameTruth& truth, int warmup) {
  PoseStates fresh;
  return answer(variant, a, b, truth, warmup, fresh);
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

/// An ADB tree kept up to date by one density-update policy.
struct UpdatedCounts {
  std::string label;
  FollowingDensity counts;
};

/// Trees of a registered volume (engine/deforming.hpp): refitted, rebuilt, and with ADB counts, updated.
class BvhDeform final : public DeformHierarchy {
 public:
  BvhDeform(const Scene& scene, const HierarchySpec& h, const Mesh& rest, const Mesh& other, int warmup)
      : scene_(scene),
        h_(h),
        warmup_(warmup),
        refit_(rest, h.bv, h.build),
        other_(AnyTree::build(other, {}, h.bv, {}, h.build)),
        exact_(variants_on(scene, h, false)),
        adb_(variants_on(scene, h, true)) {
    if (adb_.empty()) return;
    density_ = scene.density_of(h);
    const AnyTree annotated_rest = refit_.tree().annotated(density_, one_thread());
    other_adb_ = other_.annotated(density_, one_thread());
    for (const DensityUpdateSpec& spec : scene.deform->density_updates)
      updated_.push_back({spec.label(), FollowingDensity(spec, annotated_rest)});
  }

  void frame(const FrameTruth& truth, std::vector<DeformRow>& rows) override {
    const auto start = Clock::now();
    const double degradation =
        refit_.refit(*truth.mesh, scene_.deform->refit_by_fit ? RefitMethod::Fit : RefitMethod::Merge);
    const bool rebuilt = degradation > scene_.deform->rebuild_degradation;
    if (rebuilt) {
      refit_.rebuild(*truth.mesh);
      states_.clear();  // their node pairs index the old topology
    }
    const double refit_micros = micros_since(start);
    const auto rebuild_start = Clock::now();
    const AnyTree rebuilt_tree = AnyTree::build(*truth.mesh, {}, h_.bv, {}, h_.build);
    const double rebuild_micros = micros_since(rebuild_start);
    for (const StrategyVariant& v : exact_) {
      DeformRow refit_row = row_of(truth, h_, "refit", v);
      refit_row.degradation = degradation;
      refit_row.rebuilt = rebuilt;
      refit_row.tree_micros = refit_micros;
      score(refit_row, truth,
            answer(v, refit_.tree(), other_, truth, warmup_, states_["refit " + v.label()]));
      rows.push_back(std::move(refit_row));
      DeformRow rebuild_row = row_of(truth, h_, "rebuild", v);
      rebuild_row.tree_micros = rebuild_micros;
      score(rebuild_row, truth, answer_fresh(v, rebuilt_tree, other_, truth, warmup_));
      rows.push_back(std::move(rebuild_row));
    }
    if (!adb_.empty())
      adb_frame(truth, {degradation, rebuilt, refit_micros}, rebuilt_tree, rebuild_micros, rows);
  }

 private:
  /// The runner annotates on one thread, so that the density's times compare with the updates'.
  static AnnotationContext one_thread() { return {1, {}}; }

  /// What the frame's refit did.
  struct Refit {
    double degradation = 1;
    bool rebuilt = false;
    double micros = 0;
    bool fresh = false;  ///< the tree queried was made anew this frame
  };

  void adb_frame(const FrameTruth& truth, const Refit& refit, const AnyTree& rebuilt_tree,
                 double rebuild_micros, std::vector<DeformRow>& rows) {
    const auto annotate_start = Clock::now();
    const AnyTree fresh = rebuilt_tree.annotated(density_, one_thread());
    const double annotate_micros = micros_since(annotate_start);
    // Counted anew: no error against an exact count.
    add_adb_rows(truth, "rebuild + annotate", fresh, {1, false, rebuild_micros, true}, annotate_micros,
                 CountError{}, rows);
    const AnyTree recount = refit_.tree().annotated(density_, one_thread());
    for (UpdatedCounts& u : updated_) {
      u.counts.take_volumes(refit_.tree());
      const auto update_start = Clock::now();
      if (refit.rebuilt)
        u.counts.restart();
      else
        u.counts.update();
      const double update_micros = micros_since(update_start);
      add_adb_rows(truth, "refit + " + u.label, u.counts.tree(), refit, update_micros,
                   u.counts.count_error(recount), rows);
    }
  }

  void add_adb_rows(const FrameTruth& truth, const std::string& update, const AnyTree& tree,
                    const Refit& refit, double density_micros, const CountError& error,
                    std::vector<DeformRow>& rows) {
    for (const StrategyVariant& v : adb_) {
      DeformRow row = row_of(truth, h_, update, v);
      row.tree_micros = refit.micros;
      row.density_micros = density_micros;
      row.degradation = refit.degradation;
      row.rebuilt = refit.rebuilt;
      row.count_error = error.mean_difference;
      row.under_counted = error.under_counted;
      // A tree annotated anew carries nothing over; the followers' trees keep their topology.
      if (refit.fresh)
        score(row, truth, answer_fresh(v, tree, *other_adb_, truth, warmup_));
      else
        score(row, truth, answer(v, tree, *other_adb_, truth, warmup_, states_[update + " " + v.label()]));
      rows.push_back(std::move(row));
    }
  }

  const Scene& scene_;
  const HierarchySpec& h_;
  int warmup_;
  DeformingTree refit_;
  AnyTree other_;
  std::vector<StrategyVariant> exact_, adb_;
  DensitySpec density_;
  std::optional<AnyTree> other_adb_;
  std::vector<UpdatedCounts> updated_;
  std::map<std::string, PoseStates> states_;  ///< a coherent series' states, by update and series label
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
  return std::make_unique<BvhDeform>(scene, h, rest, other, warmup);
}

std::vector<RigidTransform> all_poses(const DeformSpec& spec) {
  std::vector<RigidTransform> poses;
  for (const PoseGroup& g : spec.poses) poses.insert(poses.end(), g.poses.begin(), g.poses.end());
  return poses;
}

/// The truth of one frame: a fresh AABB tree of the deformed mesh, exact traversal against B's.
FrameTruth frame_truth(int frame, const Mesh& mesh, const AnyTree& other, std::vector<RigidTransform> poses) {
  const std::size_t count = poses.size();
  FrameTruth truth{frame, &mesh, std::move(poses), std::vector<bool>(count)};
  const AnyTree tree = AnyTree::build(mesh, {}, "aabb", {}, {});
  tree.prepare(other, strategy_variant("exact", {}, {}))
      ->run(truth.poses, [&](std::size_t k, const Result& r) { truth.collides[k] = r.collides; });
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
  const AnyTree other_tree = AnyTree::build(other.mesh, {}, "aabb", {}, {});
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
