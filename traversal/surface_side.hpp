// One side of a point query (traversal/point_leaves.hpp), apart from the leaf test: the run-time layer keeps
// it with a tree without compiling the traversal loops.
#pragma once

#include "../bvh/point_surface.hpp"

#include <span>

namespace bvhlab {

/// One side of a point query: a cloud's surface and its tree's coverings (sphere_coverings(tree, surface)),
/// or a mesh (neither).
struct SurfaceSide {
  const PointSurface* surface = nullptr;
  std::span<const SphereCovering> coverings;
  [[nodiscard]] bool is_cloud() const { return surface != nullptr; }
};
inline SurfaceSide cloud_side(const PointSurface& surface, std::span<const SphereCovering> coverings) {
  return {&surface, coverings};
}
inline SurfaceSide mesh_side() {
  return {};
}

}  // namespace bvhlab
