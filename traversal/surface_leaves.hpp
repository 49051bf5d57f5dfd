// The leaf test of trees over points (traversal/point_leaves.hpp), apart from the queries that run it: the
// run-time layer hands it to every strategy's loop without including the loops here.
#pragma once

#include "../bvh/bvh.hpp"
#include "../bvh/point_surface.hpp"
#include "surface_side.hpp"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

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

}  // namespace bvhlab
