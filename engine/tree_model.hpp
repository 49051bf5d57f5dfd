// Behind AnyTree (engine/any_tree.hpp): the typed tree's virtual operations, and the table of the
// constructors of one volume and density, which the generated translation units define
// (engine/typed_tree.hpp). Internal to engine/.
#pragma once

#include "engine/any_tree.hpp"
#include "traversal/broad_phase/world_box.hpp"

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace bvhlab::engine_detail {

struct FollowerModel;

/// The typed tree behind a handle: every operation that needs the tree's type is a virtual here.
struct TreeModel {
  virtual ~TreeModel() = default;
  [[nodiscard]] virtual std::vector<std::byte> save_bytes(const std::string& source) const = 0;
  /// `self` is this model's own shared pointer: the prepared query keeps both trees alive.
  [[nodiscard]] virtual std::unique_ptr<PreparedQuery> prepare(std::shared_ptr<const TreeModel> self,
                                                               std::shared_ptr<const TreeModel> b,
                                                               const StrategyVariant& variant) const = 0;
  [[nodiscard]] virtual Box world_box(const RigidTransform& pose) const = 0;
  /// AnyTree::wide_layout_bytes.
  [[nodiscard]] virtual double wide_layout_bytes() const = 0;
  /// schedule_frame on `pairs`, whose first A is this model.
  [[nodiscard]] virtual std::vector<PairOutcome> schedule(std::span<const FramePairRef> pairs,
                                                          const FrameOptions& options,
                                                          FrameMemory* memory) const = 0;
  /// A plain tree of a mesh refitted in place; its degradation() after (DeformingTree). Others refuse.
  virtual double refit(const Mesh& deformed, RefitMethod method) = 0;
  /// Policy `spec` started on this adb tree of a mesh (FollowingDensity). Others refuse.
  [[nodiscard]] virtual std::unique_ptr<FollowerModel> follow(const DensityUpdateSpec& spec) const = 0;
  TreeInfo info;
};

using ModelPtr = std::shared_ptr<const TreeModel>;

/// Behind FollowingDensity (engine/deforming.hpp): an adb tree and a density-update policy's state.
struct FollowerModel {
  virtual ~FollowerModel() = default;
  /// The volumes and polygons of `plain`, a plain tree of the same volume, copied in.
  virtual void take_volumes(const TreeModel& plain) = 0;
  virtual DensityUpdateStats update() = 0;
  /// The counts annotated anew and the policy started again (after the plain tree was rebuilt).
  virtual void restart() = 0;
  /// The counts against `exact`, an adb tree of the same volume (adb/update.hpp).
  [[nodiscard]] virtual CountError count_error(const TreeModel& exact) const = 0;
  /// The tree, shared: the follower changes it only while nothing else holds it.
  [[nodiscard]] virtual std::shared_ptr<TreeModel> model() const = 0;
};

/// The constructors of trees of one registered volume and density.
struct PairOps {
  ModelPtr (*build)(const Mesh& mesh, const MeshUnits& units, const DensitySpec& density,
                    const BuildOptions& options);
  ModelPtr (*build_points)(const UnitCloud& cloud, const DensitySpec& density, const BuildOptions& options);
  /// A saved tree's bytes, whose header names this volume and density; `mesh`: polygons re-attached.
  ModelPtr (*load)(std::span<const std::byte> bytes, const std::string& source, const Mesh* mesh,
                   const MeshUnits& units);
  /// `plain`, a mesh's tree of this volume without a density, annotated: a copy.
  ModelPtr (*annotate)(const TreeModel& plain, const DensitySpec& density, const AnnotationContext& context,
                       AnnotateStats* stats);
};

/// The operations of the V-th registered volume with the D-th registered density: defined in
/// volume_slot_<V>_<D>.cpp (generated from engine/volume_slot.cpp.in), so that each combination's
/// instantiations compile in a translation unit of their own, in parallel.
template <std::size_t V, std::size_t D>
const PairOps& slot_ops();

/// Whether this engine compiles the slots of the V-th registered volume and of the D-th density: every one,
/// unless the target defines BVHLAB_ENGINE_VOLUME_MASK and BVHLAB_ENGINE_DENSITY_MASK (a bit per volume or
/// density: the demo's engine, engine/CMakeLists.txt).
constexpr bool slot_compiled(std::size_t v, std::size_t d) {
#if defined(BVHLAB_ENGINE_VOLUME_MASK) && defined(BVHLAB_ENGINE_DENSITY_MASK)
  return v < 64 && d < 64 && ((BVHLAB_ENGINE_VOLUME_MASK >> v) & 1u) != 0 &&
         ((BVHLAB_ENGINE_DENSITY_MASK >> d) & 1u) != 0;
#else
  (void)v;
  (void)d;
  return true;
#endif
}

/// The operations of a volume and density this engine leaves out: refusals naming them (engine/refusals.hpp);
/// kVolumeCompiled: the engine has the volume with other densities.
template <std::size_t V, std::size_t D, bool kVolumeCompiled>
const PairOps& left_out_ops();

}  // namespace bvhlab::engine_detail
