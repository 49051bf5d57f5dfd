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

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

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

/// The leaf test (driver.hpp, TriangleLeaves' shape) of a cloud against a cloud or a mesh, for one query:
/// it keeps each leaf's half of the test, so it is made per query (query_exact_points, query_adb_points)
/// and is not shared between threads.
template <TreeVolume BV>
class SurfaceLeaves {
 public:
  static constexpr bool kTriangles = false;
  static constexpr bool kTestedByEstimates = true;

  /// Throws std::invalid_argument naming the side and the problem: no side is a cloud; a cloud side whose
  /// tree holds no points, was built over another cloud (point counts differ) or whose coverings are not
  /// one per node; a mesh side whose tree holds points (pass its surface) or no polygons.
  SurfaceLeaves(const Bvh<BV>& a, SurfaceSide side_a, const Bvh<BV>& b, SurfaceSide side_b,
                const RigidTransform& b_to_a)
      : a_(a), b_(b), side_a_(side_a), side_b_(side_b), b_to_a_(b_to_a), a_to_b_(b_to_a.inverse()) {
    if (!side_a.is_cloud() && !side_b.is_cloud())
      throw std::invalid_argument("point query: neither side is a cloud; query meshes with query_exact");
    check(a, side_a, "A");
    check(b, side_b, "B");
  }

  /// After the volumes overlap: do the two nodes' coverings meet? (Always, unless both sides are clouds.)
  [[gnu::always_inline]] bool may_touch(std::uint32_t i, std::uint32_t j) const {
    if (!side_a_.is_cloud() || !side_b_.is_cloud()) return true;
    const SphereCovering& ca = side_a_.coverings[i];
    const SphereCovering& cb = side_b_.coverings[j];
    const double reach = ca.radius + ca.margin + cb.radius + cb.margin;
    for (std::uint32_t y = 0; y < cb.count; ++y) {
      const Vec3 centre = b_to_a_.apply(cb.centres[y]);
      for (std::uint32_t x = 0; x < ca.count; ++x)
        if ((ca.centres[x] - centre).squaredNorm() <= reach * reach) return true;
    }
    return false;
  }

  /// Leaf pair (i, j): does f_B change sign over A's leaf, or f_A over B's (a mesh side: its samples)?
  bool crossing(std::uint32_t i, std::uint32_t j) const {
    return (side_b_.is_cloud() && crosses(memo_a_, a_, side_a_, i, *side_b_.surface, a_to_b_)) ||
           (side_a_.is_cloud() && crosses(memo_b_, b_, side_b_, j, *side_a_.surface, b_to_a_));
  }

 private:
  enum Known : std::uint8_t { kUnknown, kCrosses, kClear };

  static void check(const Bvh<BV>& tree, SurfaceSide side, const char* name) {
    const std::string who = std::string("point query: tree ") + name;
    if (!side.is_cloud()) {
      if (tree.has_points()) throw std::invalid_argument(who + " holds points but was given no surface");
      if (!tree.empty() && !tree.has_polygons()) throw std::invalid_argument(who + " holds no polygons");
      return;
    }
    if (!tree.has_points()) throw std::invalid_argument(who + " is given a surface but holds no points");
    if (side.surface->points().size() != tree.point_ids().size())
      throw std::invalid_argument(who + " was built over " + std::to_string(tree.point_ids().size()) +
                                  " points, its surface over " +
                                  std::to_string(side.surface->points().size()));
    if (side.coverings.size() != tree.nodes().size())
      throw std::invalid_argument(who + " has " + std::to_string(tree.nodes().size()) + " nodes but " +
                                  std::to_string(side.coverings.size()) +
                                  " sphere coverings (sphere_coverings(tree, surface))");
  }

  /// Whether f of `other` changes sign over leaf `leaf` of `tree`, computed once per leaf.
  bool crosses(std::vector<std::uint8_t>& memo, const Bvh<BV>& tree, SurfaceSide side, std::uint32_t leaf,
               const PointSurface& other, const RigidTransform& into) const {
    if (memo.empty()) memo.assign(tree.nodes().size(), kUnknown);
    if (memo[leaf] == kUnknown) {
      const std::span<const Vec3> samples =
          side.is_cloud() ? node_points(tree, leaf) : triangle_samples(tree, leaf);
      memo[leaf] = surface_signs(other, samples, into, /*stop_at_both=*/true).both ? kCrosses : kClear;
    }
    return memo[leaf] == kCrosses;
  }

  /// A mesh leaf's triangles at their vertices and edge midpoints.
  std::span<const Vec3> triangle_samples(const Bvh<BV>& tree, std::uint32_t leaf) const {
    const TreeNode& node = tree.node(leaf);
    samples_.clear();
    for (std::uint32_t t = node.first; t < node.first + node.count; ++t) {
      const TrianglePoints& tri = tree.triangles()[t];
      for (int k = 0; k < 3; ++k) {
        samples_.push_back(tri[k]);
        samples_.push_back(0.5 * (tri[k] + tri[(k + 1) % 3]));
      }
    }
    return samples_;
  }

  const Bvh<BV>& a_;
  const Bvh<BV>& b_;
  SurfaceSide side_a_, side_b_;
  const RigidTransform& b_to_a_;
  const RigidTransform a_to_b_;
  mutable std::vector<std::uint8_t> memo_a_, memo_b_;  ///< per node of A (B): kUnknown, kCrosses, kClear
  mutable std::vector<Vec3> samples_;                  ///< a mesh leaf's samples, reused
};

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
