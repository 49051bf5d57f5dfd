// A strategy that exists only under tests/, to prove that the strategy axis takes a new policy through its
// header and one registry line (engine/registry.hpp, under BVHLAB_TEST_POLICIES): nothing else in
// traversal/ or bench/ names it, yet scenes, the CLI, the runner, the report and the plot script run it
// (tests/bench/test_policies.cpp; the test CLI `bvhlab_test_policies`, tests/bench/CMakeLists.txt).
#pragma once

#include "traversal/strategy.hpp"
#include "traversal/tree_access.hpp"

#include <span>
#include <string_view>

namespace bvhlab::testing {

/// "collision" iff the root volumes overlap: the cheapest inexact answer, on any tree, without polygons.
struct RootOverlapStrategy {
  struct Options {};
  static constexpr std::string_view name() { return "root_overlap"; }
  static constexpr std::string_view description() { return "collision iff the root volumes overlap"; }
  static constexpr bool exact = false;
  static constexpr BudgetUse budget = BudgetUse::None;
  static constexpr bool needs_polygons = false;
  template <class D>
  static constexpr bool accepts = true;
  static std::span<const ParamSpec> parameters() { return {}; }
  static Options configure(const ParamValues&, const Budget&) { return {}; }
  template <class TreeA, class TreeB>
  static Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a, const Options&) {
    using Walker = VolumeWalker<typename TreeA::Volume>;
    Result result;
    result.exact = false;
    if (a.bvh.empty() || b.bvh.empty()) return result;
    const auto context = Walker::make_context(b_to_a);
    ++result.counters.bv_tests;
    result.collides = Walker::overlap(a.bvh, 0, Walker::root_a(a.bvh, context), b.bvh, 0,
                                      Walker::root_b(b.bvh, context), context);
    result.probability = result.collides ? 1 : 0;
    return result;
  }
};
static_assert(Strategy<RootOverlapStrategy>);

}  // namespace bvhlab::testing
