// The Strategy concept: what a traversal strategy must provide so that scenes, the CLI, the runner, the
// report and the plot script can name it, configure it and run it. The shipped strategies are
// traversal/strategies.hpp; the registry that names them at run time is engine/registry.hpp.
//
// Concept `Strategy<S>` (in the manner of a CGAL concept page)
// ------------------------------------------------------------
// Constants and types
//   S::name()              Stable identifier ("exact", "adb"): scene "type", CLI --strategy, result rows.
//   S::description()       One line for help texts and reports.
//   S::exact               constexpr bool: every answer agrees with the exact ground truth (such a
//                          strategy may serve as a report's baseline; an inexact one reports its errors).
//   S::budget              constexpr BudgetUse: whether a Budget (BV tests and/or a deadline) is
//                          refused, optional or required.
//   S::needs_polygons      constexpr bool: the query tests triangles, so trees saved without polygons
//                          cannot serve it.
//   S::accepts<D>          constexpr bool (a variable template): it runs on trees with density D, e.g.
//                          only ProbabilityDensity models for the ADB strategies.
//   S::Options             What one configured query needs.
//   S::accepts_volume<BV>  Optional constexpr bool (a variable template): it runs on trees of volume BV
//                          (the distance strategies need DistanceVolume); every volume when absent.
// Operations
//   S::parameters()                 std::span<const ParamSpec>: its parameters (adb/parameters.hpp). A
//                                   `sweep` parameter may be given as a list: one variant per value.
//   S::configure(values, budget)    Options from resolved values and a budget (unlimited when S::budget is
//                                   None); throws std::invalid_argument for a bad combination.
//   S::query(a, b, b_to_a, options) Result for two Tree<BV, D> with accepts<D>; const and thread-safe.
//   S::query(..., options, leaves)  The same with another leaf test (traversal/driver.hpp): the shipped
//                                   strategies take SurfaceLeaves for point clouds
//                                   (traversal/point_leaves.hpp); optional for a new strategy.
//   S::density_free        Optional constexpr bool true: the queries read only the trees' `bvh`, never
//                          their density (exact, all contacts, the proximity strategies). S::query may then
//                          be given any two objects with a member `bvh`, and the run-time layer compiles
//                          the strategy once per volume instead of once per volume and density.
// Optional: running coherent over a sequence of poses (traversal/coherent.hpp)
//   S::coherent            constexpr bool true: the strategy offers
//   S::query_coherent(a, b, b_to_a, options, state[, leaves])
//                          Result of S::query, starting from `state` (a CoherentState the caller keeps for
//                          this pair of trees) and leaving its own front there. Its answers are those of
//                          S::query: a state makes a query faster, never other.
// Optional: running on the trees' wide layout (bvh/wide_bvh.hpp, traversal/wide_exact.hpp)
//   S::wide                constexpr bool true: the strategy offers
//   S::query_wide(a, wide_a, b, wide_b, b_to_a, options)
//                          Result of S::query, walking the wide trees built from a.bvh and b.bvh (four
//                          children a node tested at once). The same answers as S::query for the exact
//                          strategies; ADB's wide walk estimates other pairs (traversal/wide_adb.hpp).
//   S::walks_wide<BV>      optional constexpr bool: whether the wide walk runs on trees of volume BV
//   (default:
//                          every volume with a wide layout); the run-time layer refuses the others by name.
#pragma once

#include "../adb/parameters.hpp"
#include "../adb/tree.hpp"
#include "budget.hpp"
#include "result.hpp"

#include <concepts>
#include <span>
#include <string>
#include <string_view>

namespace bvhlab {

enum class BudgetUse { None, Optional, Required };

template <class S>
concept Strategy = requires(const ParamValues& values, const Budget& budget) {
  { S::name() } -> std::convertible_to<std::string_view>;
  { S::description() } -> std::convertible_to<std::string_view>;
  { S::exact } -> std::convertible_to<bool>;
  { S::budget } -> std::convertible_to<BudgetUse>;
  { S::needs_polygons } -> std::convertible_to<bool>;
  { S::template accepts<NoDensity> } -> std::convertible_to<bool>;
  { S::parameters() } -> std::same_as<std::span<const ParamSpec>>;
  { S::configure(values, budget) } -> std::same_as<typename S::Options>;
};

/// Whether S runs coherent (S::coherent and S::query_coherent, above).
template <class S>
inline constexpr bool kRunsCoherent = requires {
  requires S::coherent;
};

/// Whether S runs on the trees' wide layout (S::wide and S::query_wide, above).
template <class S>
inline constexpr bool kRunsWide = requires {
  requires S::wide;
};

/// Whether S's wide walk runs on trees of volume BV (S::walks_wide<BV>, above; by default it does).
template <class S, class BV>
inline constexpr bool kWalksWideOn = [] {
  if constexpr (requires { S::template walks_wide<BV>; })
    return bool(S::template walks_wide<BV>);
  else
    return true;
}();

/// Whether S reads only the trees' hierarchies (S::density_free, above).
template <class S>
inline constexpr bool kDensityFree = requires {
  requires S::density_free;
};

/// Whether S runs on trees of volume BV (S::accepts_volume, above).
template <class S, class BV>
inline constexpr bool kAcceptsVolume = [] {
  if constexpr (requires { S::template accepts_volume<BV>; })
    return bool(S::template accepts_volume<BV>);
  else
    return true;
}();

/// "bv_tests=200", "deadline_us=20", "bv_tests=200;deadline_us=20", or "" when unlimited.
/// Appends in place: GCC 12 warns (-Wrestrict, falsely) on the temporaries of string concatenation here.
inline std::string budget_label(const Budget& budget) {
  std::string out;
  if (budget.max_bv_tests) out.append("bv_tests=").append(std::to_string(budget.max_bv_tests));
  if (budget.deadline_us > 0) {
    if (!out.empty()) out.push_back(';');
    out.append("deadline_us=").append(parameter_text(budget.deadline_us));
  }
  return out;
}

/// The options of S from name/value pairs and a budget: values checked against S::parameters() (defaults
/// filled in), the budget against S::budget. Throws std::invalid_argument naming the strategy and problem.
template <Strategy S>
typename S::Options strategy_options(const ParamValues& given = {}, const Budget& budget = {}) {
  const std::string owner(S::name());
  if (S::budget == BudgetUse::None && !budget.unlimited())
    throw std::invalid_argument(owner + ": takes no budget (" + budget_label(budget) + " given)");
  if (S::budget == BudgetUse::Required && budget.unlimited())
    throw std::invalid_argument(owner + ": needs a budget (BV tests and/or a deadline)");
  return S::configure(resolve_parameters(S::parameters(), given, owner), budget);
}

}  // namespace bvhlab
