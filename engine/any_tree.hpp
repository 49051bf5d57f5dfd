// The run-time layer's one tree handle: a tree of any registered bounding volume and density, chosen by name
// at run time through the registry (engine/registry.hpp), and a query between two such trees, dispatched
// and configured once so that it runs over many poses without a virtual call per query. The CLI, the Python
// module and the scene runners all hold their trees through it; each policy combination behind it is
// compiled once, one translation unit per registered volume (engine/volume_slot.cpp.in).
#pragma once

#include "adb/concept.hpp"
#include "adb/saved_tree.hpp"
#include "bvh/mesh.hpp"
#include "bvh/point_cloud.hpp"
#include "bvh/topology.hpp"
#include "engine/specs.hpp"
#include "engine/timing.hpp"
#include "traversal/result.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

namespace bvhlab {

class CoherentState;  // traversal/coherent_state.hpp
// traversal/frame_budget.hpp
struct FrameOptions;
struct PairOutcome;
class FrameMemory;

/// The units of a mesh's coordinates as this module tracks them: what a saved tree records (the mesh file's
/// own units, or the protocol normalisation), then load_mesh's uniform scale, which a saved tree cannot
/// record (the runner's tree cache keys it instead).
struct MeshUnits {
  TreeUnits file;        ///< relative to the mesh file (or to the arrays the mesh was made from)
  double scaled_by = 1;  ///< applied after the normalisation, if any
  [[nodiscard]] bool operator==(const MeshUnits&) const = default;
  /// TreeUnits::describe(), then ", then scaled by 3" when scaled.
  [[nodiscard]] std::string describe() const;
};

/// A mesh and the units of its coordinates: what bvhlab.Mesh holds.
struct UnitMesh : Mesh {
  MeshUnits units;
};

/// A point cloud and the units of its coordinates (its mesh's when sampled from one): what
/// bvhlab.PointCloud holds.
struct UnitCloud : PointCloud {
  MeshUnits units;
};

/// What a tree is and what it cost: the fields `bvhlab info` and results.json report.
struct TreeInfo {
  std::string bv, density;  ///< registered names
  std::string annotation;   ///< the density's description: "none", "adb grid=2 tau=0.25"
  std::uint64_t triangles = 0, nodes = 0, depth = 0;
  std::uint64_t points = 0;  ///< a tree over a point cloud: its points (and no triangles)
  double model_bytes = 0;    ///< nodes, volumes and density data (what a query reads; no polygons)
  double density_bytes = 0;  ///< what the density adds to model_bytes
  double build_seconds = 0, annotate_seconds = 0;
  bool polygons = false;  ///< built from a mesh, or loaded with one: exact strategies can run on it
  MeshUnits units;        ///< its mesh's, or what its file records
};

/// Receives each pose's result, by the pose's index.
using ResultSink = std::function<void(std::size_t, const Result&)>;

/// A query between two trees with one strategy variant, checked and configured: running it cannot fail.
/// A coherent variant (StrategyVariant::coherent) starts each pose where the previous one ended: run and
/// time keep one state of their own over the poses of a call; run with a state continues the caller's.
class PreparedQuery {
 public:
  virtual ~PreparedQuery() = default;
  /// Queries every pose in order (poses already validated as rigid), handing each result to `sink`.
  virtual void run(std::span<const RigidTransform> poses, const ResultSink& sink) const = 0;
  /// The same, starting from `state` and leaving the last pose's front there, so that the next call
  /// continues the sequence. Throws std::logic_error when the variant is not coherent or another query is
  /// using the state, std::invalid_argument for a state used with other trees before.
  virtual void run(std::span<const RigidTransform> poses, const ResultSink& sink,
                   CoherentState& state) const = 0;
  /// Times every pose once after `warmup` untimed queries (timed_series, engine/timing.hpp).
  virtual void time(std::span<const RigidTransform> poses, int warmup,
                    std::vector<QueryRecord>& out) const = 0;
  /// The same, continuing from `state` and leaving the last pose's front there (a world's pair, frame after
  /// frame). The warm-up queries run on a copy of `state`: they must not hand the timed ones their answers.
  /// Throws as run(..., state) does.
  virtual void time(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                    CoherentState& state) const = 0;
  /// The same with one state per pose, each carried from call to call: pose k continues `states[k]` (a
  /// deforming object asked at the same poses frame after frame). The warm-up queries run on copies of the
  /// first poses' states. Throws std::invalid_argument unless there is one state per pose, and as
  /// run(..., state) does.
  virtual void time_per_pose(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                             std::span<CoherentState> states) const = 0;
  [[nodiscard]] virtual bool coherent() const = 0;
};

class AnyTree;
namespace engine_detail {
struct TreeModel;  ///< the typed tree behind a handle (engine/tree_model.hpp)
}

/// One pair of a frame budget: A fixed, B placed by `b_to_a`; `identity` names the pair across frames.
struct FramePairRef {
  const AnyTree* a = nullptr;
  const AnyTree* b = nullptr;
  RigidTransform b_to_a;
  std::optional<std::uint64_t> identity;
};

class AnyTree {
 public:
  /// Builds `mesh`'s tree of volume `bv` (and annotates it with `density`, if that is not "none"). Throws
  /// std::invalid_argument for an unknown name, bad parameters or a density that cannot annotate `bv`.
  /// options.progress hears the build's progress, then the annotation's; an exception it throws abandons
  /// the build (how Python stops it on Ctrl-C) and leaves this call.
  static AnyTree build(const Mesh& mesh, const MeshUnits& units, const std::string& bv,
                       const DensitySpec& density, const BuildOptions& options);
  static AnyTree build(const UnitMesh& mesh, const std::string& bv, const DensitySpec& density,
                       const BuildOptions& options) {
    return build(mesh, mesh.units, bv, density, options);
  }
  /// Builds the tree of a point cloud (Bvh<BV>::build(cloud), options.max_leaf_points per leaf) with its
  /// surface and sphere coverings, which point queries read; `density` is "none" or "adb" (counts from the
  /// points' areas: annotate_adb_points). Throws std::invalid_argument for an unknown name, another density
  /// or a cloud without areas under "adb", PointCloudError for a cloud its surface refuses.
  static AnyTree build_points(const UnitCloud& cloud, const std::string& bv, const DensitySpec& density,
                              const BuildOptions& options);
  /// Reads a saved tree (adb/saved_tree.hpp), typed by the names in its header, in the units it records;
  /// with `mesh`, re-attaches its polygons after checking that they are in those units and fit (the tree
  /// cache's check). Throws SavedTreeError naming the file, std::invalid_argument when `mesh` does not fit.
  static AnyTree load(const std::filesystem::path& file, const UnitMesh* mesh = nullptr);
  /// A saved tree from its bytes (`source` names them in errors), in the units its header records; with
  /// `mesh`, its polygons re-attached after the structural checks (std::runtime_error naming the defect).
  /// Throws SavedTreeError for bytes that are not a tree of a registered volume and density.
  static AnyTree from_bytes(std::span<const std::byte> bytes, const std::string& source,
                            const Mesh* mesh = nullptr);

  /// This plain tree (density "none") annotated with `density`: a copy, the plain tree stays. Throws
  /// std::invalid_argument when the density cannot annotate this volume, std::logic_error for a tree that
  /// already carries a density.
  [[nodiscard]] AnyTree annotated(const DensitySpec& density, const AnnotationContext& context,
                                  AnnotateStats* stats = nullptr) const;

  /// Saves without polygons, atomically, recording the tree's units. Throws std::invalid_argument for a tree
  /// of a scaled mesh (the format cannot record the scale) or of a point cloud (it records no points),
  /// SavedTreeError naming the file.
  void save(const std::filesystem::path& file) const;
  /// The saved-tree bytes save() writes (`source` names the tree in errors).
  [[nodiscard]] std::vector<std::byte> save_bytes(const std::string& source) const;
  [[nodiscard]] const TreeInfo& info() const;
  /// The bytes of the tree's wide layout (what a wide query walks beside the binary tree's leaves), built
  /// now if no wide query has built it yet. Throws std::invalid_argument for a volume without a layout or a
  /// point cloud's tree.
  [[nodiscard]] double wide_layout_bytes() const;
  /// The tree's world box when it is placed by `pose` (traversal/broad_phase/world_box.hpp).
  [[nodiscard]] Box world_box(const RigidTransform& pose) const;

  /// The query of `variant` with this tree as A (fixed) and `b` as B (moved by the poses); when either is a
  /// point cloud's, the strategy runs with the clouds' surface test at the leaves (query_exact_points,
  /// query_adb_points). The query keeps both trees alive. Throws std::invalid_argument when the trees differ
  /// in volume or density, the strategy does not run on the density, needs polygons a tree lacks, lists
  /// triangle pairs (all_contacts) of a cloud, or its parameters or budget are refused.
  [[nodiscard]] std::unique_ptr<PreparedQuery> prepare(const AnyTree& b,
                                                       const StrategyVariant& variant) const;

  /// One frame budget over many pairs of trees of one volume and probability density (schedule_frame,
  /// traversal/frame_budget.hpp), through the trees' own type. Throws std::invalid_argument for pairs of
  /// other types or a density without probabilities.
  static std::vector<PairOutcome> schedule_frame(std::span<const FramePairRef> pairs,
                                                 const FrameOptions& options, FrameMemory* memory = nullptr);

  /// Internal to engine/: the handle of a typed tree, and the typed tree behind it.
  explicit AnyTree(std::shared_ptr<const engine_detail::TreeModel> model) : model_(std::move(model)) {}
  [[nodiscard]] const std::shared_ptr<const engine_detail::TreeModel>& model() const { return model_; }

 private:
  std::shared_ptr<const engine_detail::TreeModel> model_;
};

/// The CLI's rule for a query between two trees: both normalised or neither, as one pose cannot be in both
/// units. Throws std::invalid_argument naming both.
void check_same_kind_of_units(const TreeInfo& a, const TreeInfo& b);

}  // namespace bvhlab
