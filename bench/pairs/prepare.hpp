// The prepare stage of the bench pipeline (parse -> plan -> prepare -> measure -> aggregate -> write): the
// objects a plan names, loaded on first use, and the trees (or FCL models) of each planned hierarchy, from
// this run's memory, else the disk cache, else built and annotated. Internal to the runner
// (bench/pairs/run.cpp).
#pragma once

#include "bench/pairs/plan.hpp"
#include "bench/run.hpp"
#include "engine/any_tree.hpp"
#include "engine/timing.hpp"
#include "traversal/result.hpp"

#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace bvhlab {

using LogFn = std::function<void(const std::string&)>;
/// `v` with all 17 significant digits (cache keys, messages that must name a value exactly).
std::string g17(double v);

/// One object's mesh as the run uses it.
struct ObjectData {
  const SceneObject* spec = nullptr;
  Mesh mesh;
  TreeUnits units;  ///< the normalisation applied to the file's coordinates, if any (saved with its trees)
  std::string key;  ///< mesh checksum and every transform applied to it
  std::vector<std::string> warnings;  ///< the loader's (bvh/mesh_io.hpp, MeshReport::warnings)
};
/// Loads the object's mesh and computes its key. Throws MeshError.
ObjectData load_object(const SceneObject& spec);

/// The size and time fields of `m` from a tree's account of itself.
void describe_tree(ModelInfo& m, const TreeInfo& tree);

/// A planned hierarchy's trees for one pair of objects, ready to time.
class PreparedHierarchy {
 public:
  virtual ~PreparedHierarchy() = default;
  /// Times `variant` on every pose (one dispatch to the strategy's type per series, none per query).
  virtual void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
                   std::vector<QueryRecord>& out) const = 0;
  /// The same for a coherent variant, continuing from `state` (PreparedQuery::time with a state). FCL
  /// models run no coherent queries: std::logic_error (scenes refuse them when parsed).
  virtual void run(const StrategyVariant& variant, std::span<const RigidTransform> poses, int warmup,
                   std::vector<QueryRecord>& out, CoherentState& state) const;
  /// Exact first-contact answer (the ground truth's source).
  [[nodiscard]] virtual bool exact_collides(const RigidTransform& pose) const = 0;
  [[nodiscard]] virtual bool has_counters() const { return true; }
  /// One untimed query with the full result (witness, contacts).
  [[nodiscard]] virtual Result query(const StrategyVariant& variant, const RigidTransform& pose) const = 0;
  /// A's world box when A is placed by `pose` (its root volume; traversal/broad_phase/world_box.hpp).
  [[nodiscard]] virtual Box world_box(const RigidTransform& pose) const = 0;
  /// The two trees, for code that runs many prepared pairs at once (a frame budget); nulls for FCL models.
  [[nodiscard]] virtual std::pair<const AnyTree*, const AnyTree*> trees() const { return {nullptr, nullptr}; }
  ModelInfo model;  ///< A's tree
};

/// One scene pair with every planned hierarchy prepared, in plan order.
struct PreparedPair {
  std::string label;
  const ObjectData* a = nullptr;
  const ObjectData* b = nullptr;
  std::vector<std::unique_ptr<PreparedHierarchy>> hierarchies;
};

class TreeStore;

/// The prepare stage: objects and trees, each made once per run, counted in `stats`.
class Preparation {
 public:
  Preparation(const std::filesystem::path& cache_dir, RunStats& stats, LogFn log, unsigned threads);
  ~Preparation();
  Preparation(const Preparation&) = delete;
  Preparation& operator=(const Preparation&) = delete;

  /// The object's mesh, loaded on first use.
  const ObjectData& object(const SceneObject& spec);
  /// The pair's objects and every planned hierarchy's trees for them.
  PreparedPair pair(const Scene& scene, const ScenePair& pair, const RunPlan& plan);
  /// The planned hierarchy's trees (or FCL models) for objects a and b.
  std::unique_ptr<PreparedHierarchy> hierarchy(const PlannedHierarchy& planned, const ObjectData& a,
                                               const ObjectData& b);
  /// Plain AABB trees of a and b: the exact traversal for the ground truth of an FCL-only scene.
  std::unique_ptr<PreparedHierarchy> plain_aabb(const ObjectData& a, const ObjectData& b);

  /// Every tree or model made or loaded so far, in that order.
  [[nodiscard]] std::vector<ModelInfo> models() const;
  /// Copies the tree cache's hit, reject and store counts into `stats`.
  void count_cache(RunStats& stats) const;

 private:
  std::unique_ptr<TreeStore> store_;
  std::map<std::string, ObjectData> objects_;
  RunStats& stats_;
  LogFn log_;
};

}  // namespace bvhlab
