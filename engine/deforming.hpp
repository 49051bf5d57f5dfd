// Trees that follow a deforming mesh, through the run-time layer: a plain tree refitted in place as the
// mesh moves (Bvh::refit) or rebuilt, and ADB counts kept up to date by a density-update policy
// (adb/update.hpp) while their tree is refitted. What the deform scenes run (bench/deform/); the typed
// operations compile in the engine's slot files, once per volume, like every other operation of a tree.
//
//   DeformingTree a(rest, "obb", {});
//   FollowingDensity counts({"recount_moved", values}, a.tree().annotated(adb, {}));
//   const double degradation = a.refit(deformed, RefitMethod::Merge);
//   counts.take_volumes(a.tree());
//   counts.update();  // then query a.tree() (exact) or counts.tree() (ADB)
//
// A refit changes the tree in place, so it is refused while anything else holds it (a prepared query, a
// copy of the handle): prepare queries between refits and let them go before the next one.
#pragma once

#include "bvh/bvh.hpp"
#include "engine/any_tree.hpp"

#include <memory>
#include <string>

namespace bvhlab {

namespace engine_detail {
struct FollowerModel;
}

/// A plain tree (density "none") of a mesh that one caller refits in place as the mesh deforms, or rebuilds.
class DeformingTree {
 public:
  /// The tree of volume `bv` on `rest`, built with `options` (kept for rebuild()). Throws
  /// std::invalid_argument for an unknown volume, as AnyTree::build does.
  DeformingTree(const Mesh& rest, const std::string& bv, const BuildOptions& options);
  /// Refits the tree to `deformed` (the rest mesh's triangles, moved vertices; Bvh::refit) and returns its
  /// degradation() (bvh/bvh.hpp). Throws std::invalid_argument for a mesh that does not fit,
  /// std::logic_error while a prepared query or a copy of tree() holds the tree.
  double refit(const Mesh& deformed, RefitMethod method);
  /// Builds the tree anew on `deformed`, with the options it was made with.
  void rebuild(const Mesh& deformed);
  [[nodiscard]] const AnyTree& tree() const { return tree_; }

 private:
  AnyTree tree_;
  BuildOptions options_;
};

/// ADB counts kept up to date by one density-update policy: a copy of an annotated rest tree whose volumes
/// follow a DeformingTree's, and whose counts the policy updates.
class FollowingDensity {
 public:
  /// Starts policy `spec` (its parameters as given; defaults filled in) on `annotated_rest`, a mesh's tree
  /// with density adb. Throws std::invalid_argument for another density, a tree without polygons, an
  /// unknown policy or a refused parameter.
  FollowingDensity(const DensityUpdateSpec& spec, const AnyTree& annotated_rest);
  FollowingDensity(FollowingDensity&&) noexcept;
  FollowingDensity& operator=(FollowingDensity&&) noexcept;
  ~FollowingDensity();

  /// Copies in the volumes and polygons of `refitted`, a plain tree of the same volume: not part of an
  /// update's cost. Throws std::invalid_argument for another tree, std::logic_error while tree() is held.
  void take_volumes(const AnyTree& refitted);
  /// The policy's update of the counts to the volumes taken, on one thread (as restart() annotates), so
  /// that the policies' times compare.
  DensityUpdateStats update();
  /// After the plain tree was rebuilt: the counts annotated anew on one thread, the policy started again.
  void restart();
  /// The counts against `exact`, this tree's volumes annotated anew (AnyTree::annotated of the plain tree).
  [[nodiscard]] CountError count_error(const AnyTree& exact) const;
  /// The tree with the current counts; hold it only between updates.
  [[nodiscard]] AnyTree tree() const;

 private:
  /// Refuses a change while anything but this object holds the tree.
  void check_unshared(const char* what) const;
  std::unique_ptr<engine_detail::FollowerModel> model_;
};

}  // namespace bvhlab
