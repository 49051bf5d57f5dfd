// Proximity queries: the distance between two triangle trees with its closest points, the tolerance query
// (are they within eps?), and the anytime distance, which a budget may stop with a guaranteed interval.
//
// All three are configurations of the driver (driver.hpp), like every other strategy:
//   distance    DistanceHooks with BestFirst on the volumes' lower bound (the nearest pair first),
//               SplitLarger and no limit. A pair whose bound is no smaller than the best distance found is
//               dropped, and the first such pair taken off the queue ends the query: all left are farther.
//   anytime     the same under a BudgetLimit. When it stops, the best pair found is an upper bound and the
//               smallest bound left on the queue a lower one: the exact distance lies between them.
//   tolerance   ToleranceHooks, depth first: a pair is kept while its bound is at most eps, and the first
//               triangle pair within eps decides. eps = 0 is the exact intersection query itself.
// Each runs coherent too (a CoherentState per pair of trees, as traversal/coherent.hpp): the leaf pair that
// held the nearest triangles (or the pair within eps) is tried first at the next pose. Its distance seeds the
// best found, which prunes every pair whose bound is no nearer; the answer is still proven from the root.
// The volumes need a distance bound (the DistanceVolume refinement, volumes/concept.hpp); a tree of volumes
// without one does not compile here, and the run-time layer refuses it by name.
#pragma once

#include "../bvh/triangle_distance.hpp"
#include "coherent.hpp"
#include "coherent_state.hpp"
#include "distance_result.hpp"
#include "driver.hpp"
#include "exact.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace bvhlab {

/// The best pair a distance traversal has found so far: its distance, its points (A's frame) and triangles.
struct NearestPair {
  double distance = std::numeric_limits<double>::infinity();
  Vec3 on_a = Vec3::Zero(), on_b = Vec3::Zero();
  TrianglePair triangles;
  std::pair<std::uint32_t, std::uint32_t> leaves{};  ///< the leaf pair (node indices) that holds them
};

namespace distance_detail {

/// The one triangle-pair loop of a distance traversal: every triangle pair of leaf pair (i, j) whose
/// distance is below `nearest`'s replaces it. True when the triangles touch (distance 0: nothing is nearer).
/// The same loop as TreePair::intersecting_triangles, written out again: sharing it through a visitor made
/// GCC stop inlining the pose's transform there, and the exact query ran 4% more instructions (callgrind).
template <TreeVolume BV>
bool nearer_triangles(const TreePair<BV>& trees, std::uint32_t i, std::uint32_t j, NearestPair& nearest) {
  const TreeNode& na = trees.a.node(i);
  const TreeNode& nb = trees.b.node(j);
  const auto& tri_a = trees.a.triangles();
  const auto& tri_b = trees.b.triangles();
  for (std::uint32_t tb = nb.first; tb < nb.first + nb.count; ++tb) {
    const TrianglePoints moved = {trees.b_to_a.apply(tri_b[tb][0]), trees.b_to_a.apply(tri_b[tb][1]),
                                  trees.b_to_a.apply(tri_b[tb][2])};
    for (std::uint32_t ta = na.first; ta < na.first + na.count; ++ta) {
      if (triangles_farther_than(tri_a[ta], moved, nearest.distance)) continue;
      ++trees.counters.triangle_tests;
      const TriangleDistance d = triangle_distance(tri_a[ta], moved);
      if (d.distance >= nearest.distance) continue;
      nearest = {
          d.distance, d.on_p, d.on_q, {trees.a.triangle_ids()[ta], trees.b.triangle_ids()[tb]}, {i, j}};
      if (d.distance == 0) return true;
    }
  }
  return false;
}

}  // namespace distance_detail

/// The distance strategy's hooks: a pair's score is its volumes' lower bound (one BV test), the queue key
/// its negation (BestFirst takes the highest key: the nearest pair first). Pairs whose bound is 0 (their
/// volumes overlap) tie; among them the last admitted goes first, a positive key counting admissions: a dive
/// to the leaves, as the exact traversal's, finds a touching pair without visiting every overlapping one.
/// Under a budget (Limit other than Unlimited) the search also dives, whenever the dives so far have spent
/// less than a quarter of the tests: from the pair taken into the child of smallest bound down to a leaf
/// pair, whose triangles bring the upper end down early. Best first alone reaches its first leaf pair only
/// after every pair of smaller bound, which a small budget does not allow; the dives cost a few tests per
/// level, counted and capped. Under a cap of BV tests, its last four dives' worth of tests (all of a small
/// cap) hold one dive, taken when only a dive's tests are left, from the nearest pair the search reached.
/// Under a budget, a pair's bound is at least its parent's (its triangles are some of the parent's), which
/// keeps the lower end of a stopped search at every ancestor's bound where a child's volumes bound it looser.
template <DistanceVolume BV, class Limit = Unlimited>
class DistanceHooks {
 public:
  using Pair = QueuedPair<BV, double>;

  DistanceHooks(const TreePair<BV>& trees, NearestPair& nearest, const Limit& limit = {})
      : trees_(trees), nearest_(nearest), limit_(limit) {}

  [[gnu::always_inline]] double evaluate(const Pair& p) {
    ++trees_.counters.bv_tests;
    return distance_lower_bound_below<BV>(trees_.a.tested_volume(p.a), trees_.b.tested_volume(p.b),
                                          trees_.context, nearest_.distance);
  }
  [[gnu::always_inline]] Admission admit(Pair& p, double bound) {
    if constexpr (!Limit::never_stops) bound = std::max(bound, floor_);  // only a stopped search reads it
    if (bound >= nearest_.distance) return Admission::Drop;
    p.key = bound > 0 ? -bound : ++overlapping_;
    return Admission::Queue;
  }
  /// Every pair still queued is at least as far as this one: none can hold a nearer triangle pair.
  [[gnu::always_inline]] Step taken(const Pair& p) {
    const double bound = bound_of(p.key);
    if (bound >= nearest_.distance) return Step::Decided;
    if constexpr (!Limit::never_stops) {
      floor_ = bound;
      if (dive_due()) {
        const std::uint64_t before = trees_.counters.bv_tests;
        dive(p);
        dive_tests_ += trees_.counters.bv_tests - before + 1;
      }
    }
    return Step::Continue;
  }
  [[gnu::always_inline]] Step leaf_pair(const Pair& p) {
    return distance_detail::nearer_triangles(trees_, p.a, p.b, nearest_) ? Step::Decided : Step::Continue;
  }
  /// Stopped by the budget: the distance is at least the smallest bound left unexamined.
  template <class Queue>
  void finish(const Queue& queue, Ended ended) {
    if (ended != Ended::BudgetExhausted) return;
    stopped_ = true;
    // An empty queue here means the budget refused the root's test: nothing is known.
    unexamined_bound_ = queue.empty() ? 0 : bound_of(queue.top().key);
    if (!queue.empty() && !std::isfinite(nearest_.distance)) measure_below(queue.top());
  }

  [[nodiscard]] bool stopped() const { return stopped_; }
  /// The smallest lower bound of the pairs a stopped traversal left (infinity: none left).
  [[nodiscard]] double unexamined_bound() const { return unexamined_bound_; }

 private:
  /// The bound a queue key stands for (admit).
  static double bound_of(double key) { return key > 0 ? 0 : -key; }

  /// A dive is due while the dives have spent under a quarter of the tests, but under a cap, in its last
  /// four dives' worth of tests, only once, when a dive's tests are left. So a small cap is not spent on a
  /// dive from the root, which would leave the lower end at the root's bound.
  bool dive_due() {
    const std::uint64_t left = limit_.tests_left(trees_.counters);
    if (last_dive_due_ && left <= dive_reserve_) {
      last_dive_due_ = false;
      return true;
    }
    if (left < kDiveShare * dive_reserve_) return false;
    return trees_.counters.bv_tests >= kDiveShare * dive_tests_;
  }

  /// Measures a leaf pair below `p`, reached through the trees' topology alone (the budget allows no more BV
  /// tests): a search stopped before any leaf pair still answers a finite upper end, near where it was.
  void measure_below(const Pair& p) {
    std::uint32_t i = p.a, j = p.b;
    while (!trees_.a.node(i).is_leaf()) i = trees_.a.node(i).left();
    while (!trees_.b.node(j).is_leaf()) j = trees_.b.node(j).left();
    distance_detail::nearer_triangles(trees_, i, j, nearest_);
  }

  /// From `p` into the child pair of smallest bound, down to a leaf pair, whose triangles are measured;
  /// where the budget's cap stops it on the way, it finishes by the topology (measure_below).
  void dive(Pair p) {
    while (!trees_.is_leaf_pair(p)) {
      NearestChild children{*this};
      const bool expanded = SplitLarger::expand(trees_, p, children);
      const bool nearer = children.bound < nearest_.distance;
      // The cap ran out on the way down: on by the topology, from the nearest child tested if any.
      if (!expanded) return measure_below(nearer ? children.pair : p);
      if (!nearer) return;  // no child is nearer than the best pair found
      p = children.pair;
    }
    distance_detail::nearer_triangles(trees_, p.a, p.b, nearest_);
  }
  /// The expansion's sink: each child bounded while the cap allows, the nearest kept.
  struct NearestChild {
    DistanceHooks& hooks;
    Pair pair{};
    double bound = std::numeric_limits<double>::infinity();
    bool child(Pair&& c) {
      if (!hooks.limit_.allows_test(hooks.trees_.counters)) return false;
      if (const double b = hooks.evaluate(c); b < bound) {
        bound = b;
        pair = c;
      }
      return true;
    }
  };

  const TreePair<BV>& trees_;
  NearestPair& nearest_;
  const Limit& limit_;
  /// The dives take at most about 1 / kDiveShare of the tests: the search's own lift the lower end.
  static constexpr std::uint64_t kDiveShare = 4;
  std::uint64_t dive_tests_ = 0;  ///< BV tests the dives spent (plus one per dive)
  /// The tests a dive from the root may take: two a level of both trees.
  std::uint64_t dive_reserve_ =
      Limit::never_stops ? 0 : 2 * (trees_.a.stats().depth + trees_.b.stats().depth);
  bool last_dive_due_ = true;  ///< the dive kept for when the cap's last reserve is reached
  double overlapping_ = 0;     ///< bound-0 pairs admitted so far: their keys
  double floor_ = 0;           ///< under a budget, the bound of the pair expanded: its children are no nearer
  bool stopped_ = false;
  double unexamined_bound_ = std::numeric_limits<double>::infinity();
};

namespace distance_detail {

template <DistanceVolume BV>
void check_query(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, const char* who) {
  b_to_a.validate();
  TriangleLeaves::require(a, b, who);
}

/// The distance traversal under `limit` (Unlimited or BudgetLimit). With `seed` (a coherent query's
/// remembered leaf pair), that pair's triangles are measured first; `seed` then names the nearest leaf pair.
template <DistanceVolume BV, class Limit>
DistanceResult run(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, Limit& limit,
                   std::optional<std::pair<std::uint32_t, std::uint32_t>>* seed = nullptr) {
  DistanceResult result;
  if (a.empty() || b.empty()) {  // no pair at all: infinitely far, and exactly so
    result.lower_bound = result.distance;
    return result;
  }
  const auto context = VolumeWalker<BV>::make_context(b_to_a);
  const TreePair<BV> trees(a, b, b_to_a, context, result.counters);
  NearestPair nearest;
  if (seed && *seed) nearer_triangles(trees, (*seed)->first, (*seed)->second, nearest);
  DistanceHooks<BV, Limit> hooks(trees, nearest, limit);
  traverse<BestFirst, SplitLarger>(trees, hooks, limit);
  if (seed) *seed = std::isfinite(nearest.distance) ? std::optional(nearest.leaves) : std::nullopt;
  result.distance = nearest.distance;
  result.on_a = nearest.on_a;
  result.on_b = nearest.on_b;
  if (std::isfinite(nearest.distance)) result.triangles = nearest.triangles;
  result.budget_exhausted = hooks.stopped();
  result.lower_bound = std::min(nearest.distance, hooks.unexamined_bound());
  result.exact = result.lower_bound == result.distance;
  return result;
}

}  // namespace distance_detail

/// The distance between the triangles of two trees, with the closest points and the triangles they lie on;
/// 0 with a touching pair when they intersect. `b_to_a` maps B's frame into A's. Exact to the rounding of
/// triangle_distance (bvh/triangle_distance.hpp). Throws std::invalid_argument for a non-rigid pose or a
/// tree without triangles. Thread-safe on shared trees.
template <DistanceVolume BV>
DistanceResult query_distance(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a) {
  distance_detail::check_query(a, b, b_to_a, "distance query");
  Unlimited limit;
  return distance_detail::run(a, b, b_to_a, limit);
}

/// The anytime distance: query_distance stopped by `budget` (BV tests and/or a deadline). The result's
/// [lower_bound, distance] always holds the exact distance, and narrows as the budget grows. Throws
/// std::invalid_argument for a budget that allows nothing (no cap and no deadline: use query_distance) or a
/// deadline that is negative or NaN, before any work.
template <DistanceVolume BV>
DistanceResult query_distance_anytime(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                                      const Budget& budget) {
  distance_detail::check_anytime_budget(budget);
  distance_detail::check_query(a, b, b_to_a, "anytime distance query");
  BudgetLimit limit(budget);
  return distance_detail::run(a, b, b_to_a, limit);
}

namespace distance_detail {

/// The distance traversal of a coherent query: `state` bound to these trees and held for the query, its
/// remembered leaf pair measured first and replaced by this query's nearest.
template <DistanceVolume BV, class Limit>
DistanceResult run_coherent(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, Limit& limit,
                            CoherentState& state) {
  const CoherentState::InUse in_use(state);
  coherent_detail::attach(state, a, b);
  state.serve(CoherentState::Use::Distance);
  return run(a, b, b_to_a, limit, &state.witness);
}

}  // namespace distance_detail

/// query_distance starting from `state` (traversal/coherent_state.hpp), the memory of the previous queries
/// on the same two trees: the leaf pair nearest last time is measured first. Same answer as query_distance
/// (the distance is proven from the root); the counters say what this query did. Throws as query_distance,
/// std::invalid_argument for a state made for other trees, std::logic_error for one another query is using.
template <DistanceVolume BV>
DistanceResult query_distance_coherent(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                                       CoherentState& state) {
  distance_detail::check_query(a, b, b_to_a, "coherent distance query");
  Unlimited limit;
  return distance_detail::run_coherent(a, b, b_to_a, limit, state);
}

/// query_distance_anytime starting from `state`, as query_distance_coherent: the remembered pair's distance
/// is an upper bound before the first BV test.
template <DistanceVolume BV>
DistanceResult query_distance_anytime_coherent(const Bvh<BV>& a, const Bvh<BV>& b,
                                               const RigidTransform& b_to_a, const Budget& budget,
                                               CoherentState& state) {
  distance_detail::check_anytime_budget(budget);
  distance_detail::check_query(a, b, b_to_a, "coherent anytime distance query");
  BudgetLimit limit(budget);
  return distance_detail::run_coherent(a, b, b_to_a, limit, state);
}

/// The tolerance strategy's hooks: a pair is kept while its volumes may hold points within eps; the first
/// triangle pair within eps decides.
template <DistanceVolume BV>
class ToleranceHooks {
 public:
  using Pair = QueuedPair<BV>;

  ToleranceHooks(const TreePair<BV>& trees, double tolerance, Result& result)
      : trees_(trees),
        tolerance_(tolerance),
        cutoff_(std::nextafter(tolerance, std::numeric_limits<double>::infinity())),
        result_(result) {}

  /// A bound at or past the cutoff drops the pair whatever its value, so the volume may stop refining there.
  [[gnu::always_inline]] bool evaluate(const Pair& p) {
    ++trees_.counters.bv_tests;
    return distance_lower_bound_below<BV>(trees_.a.tested_volume(p.a), trees_.b.tested_volume(p.b),
                                          trees_.context, cutoff_) <= tolerance_;
  }
  static Admission admit(Pair&, bool near) { return near ? Admission::Queue : Admission::Drop; }
  [[gnu::always_inline]] Step leaf_pair(const Pair& p) { return within(p.a, p.b); }
  /// Decides when a triangle pair of leaf pair (i, j) lies within the tolerance.
  Step within(std::uint32_t i, std::uint32_t j) {
    NearestPair nearest;
    nearest.distance = cutoff_;
    distance_detail::nearer_triangles(trees_, i, j, nearest);
    if (!(nearest.distance <= tolerance_)) return Step::Continue;
    result_.collides = true;
    result_.probability = 1;
    result_.witness = nearest.triangles;
    deciding_ = nearest.leaves;
    return Step::Decided;
  }
  template <class Queue>
  static void finish(const Queue&, Ended) {}
  /// The leaf pair that decided "within", if one did.
  [[nodiscard]] const std::optional<std::pair<std::uint32_t, std::uint32_t>>& deciding() const {
    return deciding_;
  }

 private:
  const TreePair<BV>& trees_;
  double tolerance_;
  double cutoff_;  ///< the least double above the tolerance
  Result& result_;
  std::optional<std::pair<std::uint32_t, std::uint32_t>> deciding_;
};

namespace distance_detail {

/// query_within, coherent when `state` is given.
template <DistanceVolume BV>
Result within(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, double tolerance,
              CoherentState* state) {
  if (!(tolerance >= 0) || std::isinf(tolerance))
    throw std::invalid_argument("tolerance query: the tolerance must be finite and >= 0, not " +
                                std::to_string(tolerance));
  if (tolerance == 0) return state ? query_exact_coherent(a, b, b_to_a, *state) : query_exact(a, b, b_to_a);
  check_query(a, b, b_to_a, "tolerance query");
  std::optional<CoherentState::InUse> in_use;
  if (state) {
    in_use.emplace(*state);
    coherent_detail::attach(*state, a, b);
    state->serve(CoherentState::Use::Tolerance);
  }
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  const auto context = VolumeWalker<BV>::make_context(b_to_a);
  const TreePair<BV> trees(a, b, b_to_a, context, result.counters);
  ToleranceHooks<BV> hooks(trees, tolerance, result);
  if (state && state->witness &&
      hooks.within(state->witness->first, state->witness->second) == Step::Decided) {
    state->count_witness_hit();
    return result;
  }
  Unlimited limit;
  traverse<DepthFirst, SplitLarger>(trees, hooks, limit);
  if (state) state->witness = hooks.deciding();
  return result;
}

}  // namespace distance_detail

/// Are the two trees' triangles within `tolerance` of each other (distance <= tolerance)? `collides` says
/// so, and `witness` names a triangle pair within it. With tolerance 0 this is query_exact. Throws
/// std::invalid_argument for a negative or non-finite tolerance (before any work), a non-rigid pose or a
/// tree without triangles.
template <DistanceVolume BV>
Result query_within(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, double tolerance) {
  return distance_detail::within(a, b, b_to_a, tolerance, nullptr);
}

/// query_within starting from `state`, as query_distance_coherent: the leaf pair that was within the
/// tolerance last time is tried first (with tolerance 0: query_exact_coherent). Same answers. Throws as
/// query_within, and as query_distance_coherent for the state.
template <DistanceVolume BV>
Result query_within_coherent(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                             double tolerance, CoherentState& state) {
  return distance_detail::within(a, b, b_to_a, tolerance, &state);
}

}  // namespace bvhlab
