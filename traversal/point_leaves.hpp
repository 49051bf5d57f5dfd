// Point clouds through the pair-traversal driver (traversal/driver.hpp): the leaf test of trees over points,
// their implicit surfaces (bvh/point_surface.hpp), and the queries that hand it to the strategies' own
// loops. Nothing here is a second traversal: exact_points is query_exact, ADB and time-critical are
// query_adb, each with SurfaceLeaves in place of the triangle tests.
//
//   - Pruning: a pair of two cloud nodes whose volumes overlap is dropped unless their sphere coverings
//     (balls of radius + margin) meet: the volumes bound the points, the balls hug them.
//   - Leaf pairs: test_leaf_surfaces, in its two halves (surface_signs): f_B over A's leaf points and f_A
//     over B's. Each half depends on one leaf only (f_B is the whole cloud B's), so it is computed once per
//     leaf and query and reused for every leaf pair of that leaf.
//   - A mesh against a cloud: the mesh leaf's triangles are sampled at their vertices and edge midpoints,
//     and f of the cloud evaluated there: both signs mean a crossing. There is no f for the mesh, so the
//     cloud's points are not tested against it, and a triangle much larger than the cloud's support
//     (3 kernel radii) can cross the surface between its samples unseen.
#pragma once

#include "../bvh/point_surface.hpp"
#include "adb.hpp"
#include "exact.hpp"
#include "surface_leaves.hpp"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

/// exact_points: every overlapping pair (volumes and coverings) refined to the leaves, depth first;
/// "collides" iff some leaf pair's surfaces cross (SurfaceLeaves). A cloud against a cloud or a mesh, either
/// side. `exact` means exact on the surfaces, not on the meshes they were sampled from; there is no witness.
/// Throws std::invalid_argument as SurfaceLeaves and query_exact.
template <TreeVolume BV>
Result query_exact_points(const Bvh<BV>& a, SurfaceSide side_a, const Bvh<BV>& b, SurfaceSide side_b,
                          const RigidTransform& b_to_a) {
  b_to_a.validate();
  const SurfaceLeaves<BV> leaves(a, side_a, b, side_b, b_to_a);
  return query_exact(a, b, b_to_a, ContactMode::First, leaves);
}

/// ADB (p_min), time-critical (options.budget) or guided exact (options.exact_leaves) on trees annotated
/// from points (annotate_adb_points) or polygons: query_adb with SurfaceLeaves, which every leaf pair the
/// traversal reaches runs. A crossing there answers "collides" with exact = true; a "no" is exact (agrees
/// with exact_points) unless some overlapping pair was dropped on a zero estimate or the budget ran out.
/// The deadline counts from query_adb's start, after SurfaceLeaves is set up (one matrix inverse).
template <class Order = AdbBestFirst, TreeVolume BV, ProbabilityDensity D>
Result query_adb_points(const Tree<BV, D>& a, SurfaceSide side_a, const Tree<BV, D>& b, SurfaceSide side_b,
                        const RigidTransform& b_to_a, const AdbOptions& options) {
  b_to_a.validate();
  const SurfaceLeaves<BV> leaves(a.bvh, side_a, b.bvh, side_b, b_to_a);
  return query_adb<Order>(a, b, b_to_a, options, leaves);
}

}  // namespace bvhlab
