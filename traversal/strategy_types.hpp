// The shipped traversal strategies (concept: traversal/strategy.hpp), declared: each is a thin
// configuration of the traversal loops in traversal/exact.hpp, adb.hpp and distance.hpp. The loops are not
// included here, so that the registry (engine/registry.hpp) and every file that only names the strategies
// are not compiled again when a loop changes; a strategy's query() finds its loop by argument-dependent
// lookup where it is instantiated. Include traversal/strategies.hpp to run the queries.
#pragma once

#include "../adb/parameters.hpp"
#include "../bvh/wide_bvh.hpp"
#include "adb_options.hpp"
#include "coherent_state.hpp"
#include "distance_strategies.hpp"
#include "exact_options.hpp"
#include "strategy.hpp"
#include "strategy_names.hpp"
#include "tree_pair.hpp"

#include <span>

namespace bvhlab {

/// The orders of ADB's queue (traversal/adb.hpp), named here as template arguments only.
struct AdbDepthFirst;
struct AdbLargerFirst;

namespace strategy_detail {

inline constexpr ParamSpec kPMinSweep{.name = "p_min",
                                      .description = "answer \"collision\" once a pair's estimate exceeds it",
                                      .min = 0,
                                      .max = 1,
                                      .default_value = 0.9,
                                      .sweep = true,
                                      .in_label = true};
inline constexpr ParamSpec kAdb[] = {
    kPMinSweep,
    {.name = "confirm_levels",
     .description =
         "decide \"collision\" only once this many generations below also exceed p_min (0: the paper)",
     .min = 0,
     .max = 32,
     .default_value = 0,
     .integer = true,
     .sweep = true,
     .in_label = true,
     .label_default = false},
};
inline constexpr ParamSpec kTimeCritical[] = {
    {.name = "p_min",
     .description = "answer \"collision\" once a pair's estimate exceeds it",
     .min = 0,
     .max = 1,
     .default_value = 0.9,
     .in_label = true},
    {.name = "best_effort_threshold",
     .description = "on an exhausted budget, \"collision\" iff the best estimate left is at least this",
     .min = 0,
     .max = 1,
     .default_value = 0.5},
};

}  // namespace strategy_detail

/// Exact first contact: depth-first simultaneous descent, exact triangle tests at the leaves.
struct ExactStrategy {
  using Options = ContactMode;
  static constexpr std::string_view name() { return kExactStrategyName; }
  static constexpr std::string_view description() { return "exact first contact, depth first"; }
  static constexpr bool exact = true;
  static constexpr BudgetUse budget = BudgetUse::None;
  static constexpr bool needs_polygons = true;
  template <class D>
  static constexpr bool accepts = true;
  static constexpr bool density_free = true;
  static std::span<const ParamSpec> parameters() { return {}; }
  static Options configure(const ParamValues&, const Budget&) { return ContactMode::First; }
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, Options mode,
                      const Leaves& leaves = kTriangleLeaves) {
    return query_exact(a.bvh, b.bvh, b_to_a, mode, leaves);
  }
  static constexpr bool coherent = true;
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, Options mode,
                               CoherentState& state, const Leaves& leaves = kTriangleLeaves) {
    return query_exact_coherent(a.bvh, b.bvh, b_to_a, state, mode, leaves);
  }
  static constexpr bool wide = true;
  template <class TreeA, class TreeB, class Lanes>
  static Result query_wide(const TreeA& a, const WideBvh<Lanes>& wide_a, const TreeB& b,
                           const WideBvh<Lanes>& wide_b, const RigidTransform& b_to_a, Options mode) {
    return query_exact_wide(a.bvh, wide_a, b.bvh, wide_b, b_to_a, mode);
  }
};

/// Every intersecting triangle pair (Result::contacts), exactly.
struct AllContactsStrategy : ExactStrategy {
  static constexpr std::string_view name() { return kAllContactsStrategyName; }
  static constexpr std::string_view description() { return "every intersecting triangle pair, exactly"; }
  static Options configure(const ParamValues&, const Budget&) { return ContactMode::All; }
};

/// The ADB order (best first by estimated probability) with exact leaf tests and no pruning: exact.
struct GuidedExactStrategy {
  using Options = AdbOptions;
  static constexpr std::string_view name() { return "guided_exact"; }
  static constexpr std::string_view description() {
    return "exact, visiting pairs best first by estimated probability";
  }
  static constexpr bool exact = true;
  static constexpr BudgetUse budget = BudgetUse::None;
  static constexpr bool needs_polygons = true;
  template <class D>
  static constexpr bool accepts = ProbabilityDensity<D>;
  static std::span<const ParamSpec> parameters() { return {}; }
  static Options configure(const ParamValues&, const Budget&) {
    Options options;
    options.p_min = 1;
    options.exact_leaves = true;
    return options;
  }
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, const Options& options,
                      const Leaves& leaves = kTriangleLeaves) {
    return query_adb(a, b, b_to_a, options, leaves);
  }
  static constexpr bool coherent = true;
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a,
                               const Options& options, CoherentState& state,
                               const Leaves& leaves = kTriangleLeaves) {
    return query_adb_coherent(a, b, b_to_a, options, state, leaves);
  }
};

/// ADB with p_min: "collision" once a pair's estimated probability exceeds p_min (adb/README.md, section 3).
struct AdbStrategy : GuidedExactStrategy {
  static constexpr std::string_view name() { return "adb"; }
  static constexpr std::string_view description() {
    return "average-case: collision once a pair's estimated probability exceeds p_min";
  }
  static constexpr bool exact = false;
  static constexpr bool needs_polygons = false;
  static std::span<const ParamSpec> parameters() { return strategy_detail::kAdb; }
  static Options configure(const ParamValues& values, const Budget&) {
    Options options;
    options.p_min = parameter(values, "p_min");
    options.confirm_levels = static_cast<std::uint8_t>(parameter(values, "confirm_levels"));
    options.validate();
    return options;
  }
  /// On the wide layout (traversal/wide_adb.hpp): the same rule on fewer pairs, so other answers.
  static constexpr bool wide = true;
  template <class BV>
  static constexpr bool walks_wide = StatelessWalk<BV>;
  template <class TreeA, class TreeB, class Lanes>
  static Result query_wide(const TreeA& a, const WideBvh<Lanes>& wide_a, const TreeB& b,
                           const WideBvh<Lanes>& wide_b, const RigidTransform& b_to_a,
                           const Options& options) {
    return query_adb_wide(a, wide_a, b, wide_b, b_to_a, options);
  }
};

/// `Base` (a strategy running query_adb) in another order (`Order`: AdbDepthFirst, AdbLargerFirst). On the
/// default density only: every (volume, density) pair a strategy accepts is one more traversal for the
/// runner, the CLI and Python to compile, and the order does not depend on the density.
template <class Base, class Order>
struct InOrder : Base {
  static constexpr bool wide = false;  // the wide walk has its own order
  template <class D>
  static constexpr bool accepts = ProbabilityDensity<D>&& D::name() == std::string_view("adb");
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a,
                      const typename Base::Options& options, const Leaves& leaves = kTriangleLeaves) {
    return query_adb<Order>(a, b, b_to_a, options, leaves);
  }
  template <class TreeA, class TreeB, class Leaves = TriangleLeaves>
  static Result query_coherent(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a,
                               const typename Base::Options& options, CoherentState& state,
                               const Leaves& leaves = kTriangleLeaves) {
    return query_adb_coherent<Order>(a, b, b_to_a, options, state, leaves);
  }
};
/// The depth-first order: the most probable child of the pair just expanded next.
template <class Base>
using InDepthFirstOrder = InOrder<Base, AdbDepthFirst>;

/// Guided exact in the depth-first order.
struct GuidedExactDfsStrategy : InDepthFirstOrder<GuidedExactStrategy> {
  static constexpr std::string_view name() { return "guided_exact_dfs"; }
  static constexpr std::string_view description() {
    return "exact, depth first into the most probable child pair";
  }
};

/// ADB with p_min in the depth-first order: the same answers as `adb`, reached by diving.
struct AdbDfsStrategy : InDepthFirstOrder<AdbStrategy> {
  static constexpr std::string_view name() { return "adb_dfs"; }
  static constexpr std::string_view description() {
    return "adb's answers, depth first into the most probable child pair";
  }
};

/// ADB with p_min splitting only the larger node of a pair: for objects of very different size.
struct AdbLargerStrategy : InOrder<AdbStrategy, AdbLargerFirst> {
  static constexpr std::string_view name() { return "adb_larger"; }
  static constexpr std::string_view description() {
    return "adb, splitting only the larger node of a pair (the exact traversal's descent)";
  }
};

/// ADB under a budget of BV tests and/or a deadline; on exhaustion, a best-effort answer.
struct TimeCriticalStrategy : AdbStrategy {
  static constexpr std::string_view name() { return "time_critical"; }
  static constexpr std::string_view description() {
    return "ADB under a budget of BV tests and/or microseconds, best effort on exhaustion";
  }
  static constexpr BudgetUse budget = BudgetUse::Required;
  static std::span<const ParamSpec> parameters() { return strategy_detail::kTimeCritical; }
  static Options configure(const ParamValues& values, const Budget& budget) {
    Options options;
    options.p_min = parameter(values, "p_min");
    options.best_effort_threshold = parameter(values, "best_effort_threshold");
    options.budget = budget;
    options.validate();
    return options;
  }
};

static_assert(Strategy<ExactStrategy> && Strategy<AllContactsStrategy> && Strategy<GuidedExactStrategy> &&
              Strategy<AdbStrategy> && Strategy<TimeCriticalStrategy> && Strategy<GuidedExactDfsStrategy> &&
              Strategy<AdbDfsStrategy> && Strategy<AdbLargerStrategy>);

}  // namespace bvhlab
