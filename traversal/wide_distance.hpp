// The distance query on wide trees (bvh/wide_bvh.hpp): query_distance's best-first search, where one step
// bounds a volume of one tree against all four children of a node of the other at once (the lanes'
// distance_bounds_to_b and _to_a, e.g. Obb4's). The same distance as query_distance on the binary trees
// the wide ones were built from: the triangle pairs are measured by the same loop, and every pair whose
// bound is below the best distance found is opened, so the nearest pair is always reached; where several
// pairs lie at that distance, the points and triangles may be another of them.
//
// A layout takes part when its lanes have a distance bound (WideDistanceLanes, bvh/wide_bvh.hpp); the
// distance strategy refuses the others by name (traversal/distance_strategies.hpp).
//
// Counters: bv_tests counts four a step (each lane is a bound, occupied or not), as the wide exact walk;
// nodes_visited the pairs taken off the queue; triangle_tests the triangle pairs measured.
#pragma once

#include "distance.hpp"
#include "driver.hpp"
#include "wide_exact.hpp"

#include <array>
#include <cstdint>

namespace bvhlab {

namespace wide_distance_detail {

/// A pair on the queue: lane a_lane of A's wide node a_node against lane b_lane of B's b_node. The key is
/// the negated bound (the nearest first) or, for overlapping volumes (bound 0), a positive count of
/// admissions: the last admitted first, a dive to the leaves as in query_distance. The bounds are floats
/// (the lanes'), so a float key loses nothing, and 16 bytes a pair keep the heap's moves cheap.
struct QueuedPair {
  float key;
  std::uint32_t a_node, b_node;
  std::uint8_t a_lane, b_lane;
};
static_assert(sizeof(QueuedPair) == 16);

/// The queue: best first, which also spares the heap the nearest lane of a step when nothing queued is
/// nearer (BestFirst, traversal/driver.hpp).
using Queue = BestFirst::Queue<QueuedPair>;

/// Files the lanes of one step whose bound is below the best distance found.
class Admitter {
 public:
  explicit Admitter(const NearestPair& nearest) : nearest_(nearest) {}
  [[gnu::always_inline]] void admit(Queue& queue, const std::array<float, 4>& bounds, QueuedPair base,
                                    bool split_b) {
    for (std::uint8_t k = 0; k < 4; ++k) {
      const float bound = bounds[k];
      if (!(bound < nearest_.distance)) continue;
      QueuedPair p = base;
      (split_b ? p.b_lane : p.a_lane) = k;
      p.key = bound > 0 ? -bound : float(++overlapping_);
      queue.push(p);
    }
  }
  static double bound_of(float key) { return key > 0 ? 0 : -double(key); }

 private:
  const NearestPair& nearest_;
  std::uint32_t overlapping_ = 0;  // past 2^24 the keys tie: the order changes, never the answer
};

}  // namespace wide_distance_detail

/// The distance between the triangles of two binary trees, walking their wide trees (same contract as
/// query_distance). Throws std::invalid_argument for a non-rigid pose, a tree without triangles, or wide
/// trees of other binary trees. Const and thread-safe on shared trees.
template <WideDistanceLanes Lanes>
DistanceResult query_distance_wide(const Bvh<typename Lanes::Volume>& a, const WideBvh<Lanes>& wide_a,
                                   const Bvh<typename Lanes::Volume>& b, const WideBvh<Lanes>& wide_b,
                                   const RigidTransform& b_to_a) {
  using BV = typename Lanes::Volume;
  using Tree = WideBvh<Lanes>;
  using wide_distance_detail::Admitter;
  distance_detail::check_query(a, b, b_to_a, "wide distance query");
  DistanceResult result;
  if (a.empty() || b.empty()) {  // no pair at all: infinitely far, and exactly so
    result.lower_bound = result.distance;
    return result;
  }
  wide_detail::require_pair(a, wide_a, b, wide_b, "wide distance query");
  // The triangle loop reads no volume context (as in query_exact_wide).
  const typename VolumeWalker<BV>::Context unused_context{};
  const TreePair<BV> trees(a, b, b_to_a, unused_context, result.counters);
  const typename Lanes::PairContext lanes = Lanes::make_context(b_to_a, wide_a.origin(), wide_b.origin());
  Counters& counters = result.counters;
  NearestPair nearest;
  Admitter admitter(nearest);
  wide_distance_detail::Queue queue;

  counters.bv_tests += 1;
  const std::array<float, 4> root =
      Lanes::distance_bounds_to_b(wide_a.node(0).boxes, 0, wide_b.node(0).boxes, lanes);
  constexpr float kNone = std::numeric_limits<float>::infinity();  // the pseudo-node's empty lanes
  admitter.admit(queue, {root[0], kNone, kNone, kNone}, {0, 0, 0, 0, 0}, false);
  while (!queue.empty()) {
    const wide_distance_detail::QueuedPair p = queue.pop();
    // p is the nearest pair left: every other is at least as far, and none holds a nearer triangle pair.
    if (Admitter::bound_of(p.key) >= nearest.distance) break;
    ++counters.nodes_visited;
    const wide_detail::OpenedPair<Tree> q = wide_detail::open_pair(wide_a, wide_b, p);
    if (q.leaf_a && q.leaf_b) {
      if (distance_detail::nearer_triangles(trees, q.child_a & ~Tree::kLeaf, q.child_b & ~Tree::kLeaf,
                                            nearest))
        break;  // touching: nothing is nearer
      continue;
    }
    // Split the larger of the two (a leaf cannot be split): its four children against the other's volume.
    counters.bv_tests += 4;
    if (q.splits_b(p.a_lane, p.b_lane)) {
      const auto bounds =
          Lanes::distance_bounds_to_b(q.node_a.boxes, int(p.a_lane), wide_b.node(q.child_b).boxes, lanes);
      admitter.admit(queue, bounds, {0, p.a_node, q.child_b, p.a_lane, 0}, true);
    } else {
      const auto bounds =
          Lanes::distance_bounds_to_a(wide_a.node(q.child_a).boxes, q.node_b.boxes, int(p.b_lane), lanes);
      admitter.admit(queue, bounds, {0, q.child_a, p.b_node, 0, p.b_lane}, false);
    }
  }
  result.distance = nearest.distance;
  result.lower_bound = nearest.distance;
  result.exact = true;
  result.on_a = nearest.on_a;
  result.on_b = nearest.on_b;
  if (std::isfinite(nearest.distance)) result.triangles = nearest.triangles;
  return result;
}

}  // namespace bvhlab
