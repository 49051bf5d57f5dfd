// The C++ side of the Python module, free of Python: a tree of any registered bounding volume and density,
// chosen by name at run time through the registry (bench/core/registry.hpp), and a query between two such
// trees, dispatched and configured once so that it can run over many poses without the interpreter.
#pragma once

#include "adb/saved_tree.hpp"
#include "bench/core/scene.hpp"
#include "bvh/mesh.hpp"
#include "bvh/point_cloud.hpp"
#include "bvh/topology.hpp"
#include "traversal/result.hpp"

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>

namespace bvhlab::python {

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
  double build_seconds = 0, annotate_seconds = 0;
  bool polygons = false;  ///< built from a mesh, or loaded with one: exact strategies can run on it
  MeshUnits units;        ///< its mesh's, or what its file records
};

/// Receives each pose's result, by the pose's index.
using ResultSink = std::function<void(std::size_t, const Result&)>;

/// A query between two trees with one strategy variant, checked and configured: running it cannot fail.
class PreparedQuery {
 public:
  virtual ~PreparedQuery() = default;
  /// Queries every pose in order (poses already validated as rigid), handing each result to `sink`.
  virtual void run(std::span<const RigidTransform> poses, const ResultSink& sink) const = 0;
};

class AnyTree {
 public:
  /// Builds `mesh`'s tree of volume `bv` (and annotates it with `density`, if that is not "none"). Throws
  /// std::invalid_argument for an unknown name, bad parameters or a density that cannot annotate `bv`.
  static AnyTree build(const UnitMesh& mesh, const std::string& bv, const DensitySpec& density,
                       const BuildOptions& options);
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

  /// Saves without polygons, atomically, recording the tree's units. Throws std::invalid_argument for a tree
  /// of a scaled mesh (the format cannot record the scale) or of a point cloud (it records no points),
  /// SavedTreeError naming the file.
  void save(const std::filesystem::path& file) const;
  [[nodiscard]] const TreeInfo& info() const;

  /// The query of `variant` with this tree as A (fixed) and `b` as B (moved by the poses); when either is a
  /// point cloud's, the strategy runs with the clouds' surface test at the leaves (query_exact_points,
  /// query_adb_points). Throws std::invalid_argument when one tree is normalised and the other not (the
  /// CLI's rule: a pose cannot be in both units), the trees differ in volume or density, the strategy does
  /// not run on the density, needs polygons a tree lacks, lists triangle pairs (all_contacts) of a cloud, or
  /// its parameters or budget are refused.
  [[nodiscard]] std::unique_ptr<PreparedQuery> prepare(const AnyTree& b,
                                                       const StrategyVariant& variant) const;

  struct Model;  ///< the typed tree behind the handle

 private:
  explicit AnyTree(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  std::shared_ptr<const Model> model_;
};

/// `given` checked against the density's parameter table, defaults filled in. Throws std::invalid_argument.
DensitySpec density_spec(const std::string& name, const ParamValues& given);
/// A strategy variant from its name, given parameters and budget, checked as `bvhlab query` checks them.
/// Throws std::invalid_argument.
StrategyVariant strategy_variant(const std::string& name, const ParamValues& given, const Budget& budget);

}  // namespace bvhlab::python
