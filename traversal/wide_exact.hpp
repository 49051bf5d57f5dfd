// Exact first-contact (or all-contacts) query on wide trees of boxes (bvh/wide_bvh.hpp): depth-first, like
// query_exact on the binary trees, but one step tests a box of one tree against all four children of a
// node of the other at once (Aabb4::overlap). The same answers as query_exact<Aabb> on the binary trees
// the wide ones were built from: the triangle tests are the same, the box tests conservative.
//
// Counters: bv_tests counts four a vector test (each lane is a box test, occupied or not: a node of fewer
// than four children pays for four), nodes_visited the pairs taken off the stack, triangle_tests as usual.
#pragma once

#include "../bvh/wide_bvh.hpp"
#include "exact.hpp"

#include <stdexcept>
#include <vector>

namespace bvhlab {

namespace wide_detail {

/// A pair on the walk's stack: A's box (lane a_lane of wide node a_node) and B's, kept already placed in
/// A's frame (Aabb4::place, lane `from` of `b_placed` when it was pushed) together with where it sits in B's
/// tree, so that splitting A tests A's children against it without placing it again.
struct WidePair {
  std::uint32_t a_node, a_lane, b_node, b_lane;
  float center[3], half[3], mag;
};

inline void require_pair(const Bvh<Aabb>& a, const WideAabbTree& wide_a, const Bvh<Aabb>& b,
                         const WideAabbTree& wide_b) {
  if (wide_a.binary_identity() != a.identity())
    throw std::invalid_argument("wide exact query: wide tree A was not built from binary tree A");
  if (wide_b.binary_identity() != b.identity())
    throw std::invalid_argument("wide exact query: wide tree B was not built from binary tree B");
}

}  // namespace wide_detail

/// Exact query on the wide trees of two binary AABB trees (same contract as query_exact<Aabb>; throws
/// std::invalid_argument for a non-rigid pose or wide trees of other binary trees). Const and thread-safe
/// on shared trees.
inline Result query_exact_wide(const Bvh<Aabb>& a, const WideAabbTree& wide_a, const Bvh<Aabb>& b,
                               const WideAabbTree& wide_b, const RigidTransform& b_to_a,
                               ContactMode mode = ContactMode::First) {
  check_exact_query<TriangleLeaves>(b_to_a, mode);
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  wide_detail::require_pair(a, wide_a, b, wide_b);
  TriangleLeaves::require(a, b, "wide exact query");
  const auto context = Aabb::make_context(b_to_a);
  const TreePair<Aabb> trees(a, b, b_to_a, context, result.counters);
  const Aabb4::PairContext lanes = Aabb4::make_context(b_to_a, wide_a.origin(), wide_b.origin());
  Counters& counters = result.counters;

  std::vector<wide_detail::WidePair> stack;
  stack.reserve(64);
  // Pushes the pairs of A's lane (node_a, lane_a) and B's lanes of `placed` (node_b's boxes, placed) that
  // `hits` marks, last to first: the first is taken first, as in the binary walk.
  const auto push_b_lanes = [&](std::uint32_t a_node, std::uint32_t a_lane, std::uint32_t b_node,
                                const Aabb4& placed, unsigned hits) {
    for (int k = Aabb4::kLanes - 1; k >= 0; --k)
      if (hits & (1u << k))
        stack.push_back({a_node,
                         a_lane,
                         b_node,
                         std::uint32_t(k),
                         {placed.cx[k], placed.cy[k], placed.cz[k]},
                         {placed.hx[k], placed.hy[k], placed.hz[k]},
                         placed.mag[k]});
  };
  // The roots, as any pair: B's root box placed against A's.
  counters.bv_tests += 1;
  {
    const Aabb4 placed = Aabb4::place(wide_b.node(0).boxes, lanes);
    push_b_lanes(0, 0, 0, placed, Aabb4::overlap_placed(wide_a.node(0).boxes, placed, lanes) & 1u);
  }
  while (!stack.empty()) {
    const wide_detail::WidePair p = stack.back();
    stack.pop_back();
    ++counters.nodes_visited;
    const WideAabbTree::Node& node_a = wide_a.node(p.a_node);
    const WideAabbTree::Node& node_b = wide_b.node(p.b_node);
    const std::uint32_t child_a = node_a.child[p.a_lane], child_b = node_b.child[p.b_lane];
    const bool leaf_a = (child_a & WideAabbTree::kLeaf) != 0, leaf_b = (child_b & WideAabbTree::kLeaf) != 0;
    if (leaf_a && leaf_b) {
      const bool done = trees.intersecting_triangles(
          child_a & ~WideAabbTree::kLeaf, child_b & ~WideAabbTree::kLeaf, [&](const TrianglePair& hit) {
            result.collides = true;
            result.probability = 1;
            if (!result.witness) result.witness = hit;
            if (mode == ContactMode::First) return true;
            result.contacts.push_back(hit);
            return false;
          });
      if (done) return result;
      continue;
    }
    // Split the larger of the two (a leaf cannot be split): its four children against the other's box.
    counters.bv_tests += Aabb4::kLanes;
    if (leaf_a || (!leaf_b && node_b.boxes.volume(int(p.b_lane)) > node_a.boxes.volume(int(p.a_lane)))) {
      const Aabb4 placed = Aabb4::place(wide_b.node(child_b).boxes, lanes);
      push_b_lanes(p.a_node, p.a_lane, child_b, placed,
                   Aabb4::overlap_placed(Aabb4::broadcast(node_a.boxes, int(p.a_lane)), placed, lanes));
    } else {
      const Aabb4 placed_b = Aabb4::splat(p.center, p.half, p.mag);
      const unsigned hits = Aabb4::overlap_placed(wide_a.node(child_a).boxes, placed_b, lanes);
      for (int k = Aabb4::kLanes - 1; k >= 0; --k)
        if (hits & (1u << k)) {
          wide_detail::WidePair child = p;
          child.a_node = child_a;
          child.a_lane = std::uint32_t(k);
          stack.push_back(child);
        }
    }
  }
  return result;
}

}  // namespace bvhlab
