// The proximity strategies (concept: traversal/strategy.hpp): thin configurations of the queries in
// traversal/distance.hpp, which is not included here (traversal/strategy_types.hpp says why). They run on
// trees of volumes with a distance bound (the DistanceVolume refinement) and refuse the others by name
// (S::accepts_volume); the density does not matter to them.
#pragma once

#include "../adb/parameters.hpp"
#include "../bvh/wide_bvh.hpp"
#include "coherent_state.hpp"
#include "distance_result.hpp"
#include "strategy.hpp"
#include "strategy_names.hpp"

#include <span>

namespace bvhlab {

namespace distance_strategy_detail {

/// A distance answer in the currency of every strategy: `collides` when the distance is 0 (the touching
/// pair is the witness), `exact` when the interval is closed or the answer to "do they intersect" is proven
/// all the same. An anytime query stopped with [0, d > 0] answers "collision": it cannot rule one out.
inline Result as_result(const DistanceResult& d) {
  Result r;
  r.collides = d.lower_bound == 0;
  r.exact = d.exact || d.distance == 0 || d.lower_bound > 0;
  r.probability = r.collides ? 1 : 0;
  r.budget_exhausted = d.budget_exhausted;
  if (d.distance == 0) r.witness = d.triangles;
  r.counters = d.counters;
  Proximity& p = r.proximity.emplace();
  p.distance = d.distance;
  p.lower_bound = d.lower_bound;
  p.on_a = {d.on_a.x(), d.on_a.y(), d.on_a.z()};
  p.on_b = {d.on_b.x(), d.on_b.y(), d.on_b.z()};
  p.triangles = d.triangles;
  return r;
}

inline constexpr ParamSpec kTolerance[] = {
    {.name = "tolerance",
     .description = "answer \"within\" when the triangles come this close (in A's units; 0: intersect)",
     .min = 0,
     .max = 1e300,
     .sweep = true,
     .in_label = true},
};

/// What the proximity strategies share: triangles measured, any density, volumes with a distance bound.
struct ProximityTraits {
  static constexpr bool needs_polygons = true;
  template <class D>
  static constexpr bool accepts = true;
  static constexpr bool density_free = true;
  template <class BV>
  static constexpr bool accepts_volume = DistanceVolume<BV>;
  static constexpr bool coherent = true;
};

}  // namespace distance_strategy_detail

/// The distance between the two meshes, its closest points and triangles; 0 with a witness when they touch.
struct DistanceStrategy : distance_strategy_detail::ProximityTraits {
  struct Options {};
  static constexpr std::string_view name() { return kDistanceStrategyName; }
  static constexpr std::string_view description() {
    return "the distance, its closest points and triangles (0 with a witness when they intersect)";
  }
  static constexpr bool exact = true;
  static constexpr BudgetUse budget = BudgetUse::None;
  static std::span<const ParamSpec> parameters() { return {}; }
  static Options configure(const ParamValues&, const Budget&) { return {}; }
  template <class TreeA, class TreeB>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, Options) {
    return distance_strategy_detail::as_result(query_distance(a.bvh, b.bvh, b_to_a));
  }
  template <class TreeA, class TreeB>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, Options,
                               CoherentState& state) {
    return distance_strategy_detail::as_result(query_distance_coherent(a.bvh, b.bvh, b_to_a, state));
  }
  /// The wide walk (traversal/wide_distance.hpp) needs lanes with a distance bound: obb's.
  static constexpr bool wide = true;
  template <class BV>
  static constexpr bool walks_wide = HasWideDistance<BV>;
  template <class TreeA, class TreeB, class Lanes>
  static Result query_wide(const TreeA& a, const WideBvh<Lanes>& wide_a, const TreeB& b,
                           const WideBvh<Lanes>& wide_b, const RigidTransform& b_to_a, Options) {
    return distance_strategy_detail::as_result(query_distance_wide(a.bvh, wide_a, b.bvh, wide_b, b_to_a));
  }
};

/// The distance under a budget: a guaranteed interval [lower_bound, distance] and the nearest pair so far.
struct AnytimeDistanceStrategy : DistanceStrategy {
  using Options = Budget;
  static constexpr std::string_view name() { return "distance_anytime"; }
  static constexpr std::string_view description() {
    return "the distance under a budget: an interval that holds it, and the nearest pair found";
  }
  static constexpr bool exact = false;
  static constexpr BudgetUse budget = BudgetUse::Required;
  static constexpr bool wide = false;  // the budgeted search and its dives walk the binary trees
  static Options configure(const ParamValues&, const Budget& given) {
    distance_detail::check_anytime_budget(given);  // refused here, so that running cannot fail
    return given;
  }
  template <class TreeA, class TreeB>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, const Options& limit) {
    return distance_strategy_detail::as_result(query_distance_anytime(a.bvh, b.bvh, b_to_a, limit));
  }
  template <class TreeA, class TreeB>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a,
                               const Options& limit, CoherentState& state) {
    return distance_strategy_detail::as_result(
        query_distance_anytime_coherent(a.bvh, b.bvh, b_to_a, limit, state));
  }
};

/// Are the meshes within a tolerance of each other? Stops at the first triangle pair within it, or once
/// every pair is farther. Its "collision" is "within": exact as the intersection answer only at tolerance 0.
struct ToleranceStrategy : distance_strategy_detail::ProximityTraits {
  using Options = double;
  static constexpr std::string_view name() { return kToleranceStrategyName; }
  static constexpr std::string_view description() {
    return "within a tolerance of each other? (a triangle pair within it is the witness)";
  }
  static constexpr bool exact = false;
  static constexpr BudgetUse budget = BudgetUse::None;
  static std::span<const ParamSpec> parameters() { return distance_strategy_detail::kTolerance; }
  static Options configure(const ParamValues& values, const Budget&) {
    return parameter(values, "tolerance");
  }
  template <class TreeA, class TreeB>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, Options tolerance) {
    return answered(query_within(a.bvh, b.bvh, b_to_a, tolerance), tolerance);
  }
  template <class TreeA, class TreeB>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a,
                               Options tolerance, CoherentState& state) {
    return answered(query_within_coherent(a.bvh, b.bvh, b_to_a, tolerance, state), tolerance);
  }

 private:
  /// "Within" answers "do they intersect" only at tolerance 0: elsewhere it is not claimed exact.
  static Result answered(Result r, double tolerance) {
    r.exact = r.exact && tolerance == 0;
    return r;
  }
};

static_assert(Strategy<DistanceStrategy> && Strategy<AnytimeDistanceStrategy> && Strategy<ToleranceStrategy>);

}  // namespace bvhlab
