// The one place where run-time names meet compile-time policies: bounding volumes, densities and traversal
// strategies. A new policy is named here (one line in its list) and nowhere else outside its own header.
// Only the run-time layer (engine/) includes it: everything else reaches the policies through its handle
// (engine/any_tree.hpp) and its tables (engine/policies.hpp), so each combination is compiled once.
#pragma once

#include "adb/adb_density.hpp"
#include "adb/adb_normal_density.hpp"
#include "adb/adb_paper_density.hpp"
#include "adb/tree.hpp"
#include "engine/specs.hpp"
#include "traversal/strategy_types.hpp"
#include "volumes/shipped.hpp"

#include <string>
#include <string_view>
#include <vector>

#ifdef BVHLAB_TEST_POLICIES
// The test-only policies (tests/support/): built into the test variant of the runner and CLI only.
#include "tests/support/test_density.hpp"
#include "tests/support/test_strategy.hpp"
#endif

namespace bvhlab {

/// The shipped volume models, listed once in volumes/shipped.hpp (the typed volume tests use that list too).
#if defined(BVHLAB_TEST_POLICIES)
/// The test variant proves the density and strategy axes, not the volumes: one volume keeps its second copy
/// of the engine cheap to compile (every volume multiplies the density x strategy instantiations).
using RegisteredVolumes = TypeList<Aabb>;
#elif defined(BVHLAB_LEAN_VOLUMES)
/// The sanitizer builds (volumes/shipped.hpp): the runner's instantiations are most of their time.
using RegisteredVolumes = LeanVolumes;
#else
using RegisteredVolumes = ShippedVolumes;
#endif

#ifndef BVHLAB_TEST_POLICIES
using RegisteredDensities = TypeList<NoDensity, AdbDensity, AdbPaperDensity, AdbNormalDensity>;
using RegisteredStrategies =
    TypeList<ExactStrategy, AllContactsStrategy, GuidedExactStrategy, AdbStrategy, TimeCriticalStrategy,
             GuidedExactDfsStrategy, AdbDfsStrategy, AdbLargerStrategy, DistanceStrategy, ToleranceStrategy,
             AnytimeDistanceStrategy>;
#else
/// The test variant adds one density and one strategy next to a few shipped ones: enough to show that a new
/// policy needs nothing but its header and its line, while each left-out policy saves its instantiations
/// in this second copy of the runner and CLI.
using RegisteredDensities = TypeList<NoDensity, AdbDensity, testing::TriangleCountDensity>;
using RegisteredStrategies = TypeList<ExactStrategy, AllContactsStrategy, GuidedExactStrategy, AdbStrategy,
                                      TimeCriticalStrategy, testing::RootOverlapStrategy>;
#endif

/// Calls f(std::type_identity<BV>{}) for the BV whose name() is `name`; throws naming the choices.
template <class F>
auto with_volume(std::string_view name, F&& f) {
  return with_named_type("bounding volume", name, std::forward<F>(f), RegisteredVolumes{});
}
/// Calls f(std::type_identity<BV>{}) for every registered BV, in registration order.
template <class F>
void with_each_volume(F&& f) {
  for_each_type(std::forward<F>(f), RegisteredVolumes{});
}

/// Calls f(std::type_identity<D>{}) for the density whose name() is `name`; throws naming the choices.
template <class F>
auto with_density(std::string_view name, F&& f) {
  return with_named_type("density", name, std::forward<F>(f), RegisteredDensities{});
}
template <class F>
void with_each_density(F&& f) {
  for_each_type(std::forward<F>(f), RegisteredDensities{});
}

/// Calls f(std::type_identity<S>{}) for the strategy whose name() is `name`; throws naming the choices.
template <class F>
auto with_strategy(std::string_view name, F&& f) {
  return with_named_type("strategy", name, std::forward<F>(f), RegisteredStrategies{});
}
template <class F>
void with_each_strategy(F&& f) {
  for_each_type(std::forward<F>(f), RegisteredStrategies{});
}

}  // namespace bvhlab
