// Coherent ADB queries (traversal/coherent_adb.hpp): the node pair that decided the last query is tried
// first. Guided exact stays exact; ADB and time-critical keep their answers but where the remembered pair
// decides on its own estimate; volumes whose walkers carry state from the root run as the cold query.
#include "adb/adb_density.hpp"
#include "coherent_paths.hpp"
#include "support/errors.hpp"
#include "traversal/coherent.hpp"
#include "traversal/coherent_adb.hpp"
#include "volumes/aabb.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

namespace bvhlab::coherent_tests {
namespace {

template <class BV>
struct AdbTrees {
  Tree<BV, AdbDensity> a = annotate_adb(Bvh<BV>::build(torus()), 2, 0.25);
  Tree<BV, AdbDensity> b = annotate_adb(Bvh<BV>::build(soup()), 2, 0.25);
};

AdbOptions guided() {
  AdbOptions options;
  options.p_min = 1;
  options.exact_leaves = true;
  return options;
}

/// Cold and coherent along the path; how many answers differ, and the work of each.
struct Comparison {
  std::size_t disagreements = 0, colliding = 0;
  std::uint64_t cold_tests = 0, coherent_tests = 0, hits = 0;
};

template <class Order = AdbBestFirst, class BV>
Comparison compare(const AdbTrees<BV>& trees, const AdbOptions& options) {
  Comparison out;
  CoherentState state;
  for (const RigidTransform& pose : path(240)) {
    const Result cold = query_adb<Order>(trees.a, trees.b, pose, options);
    const Result r = query_adb_coherent<Order>(trees.a, trees.b, pose, options, state);
    out.disagreements += r.collides != cold.collides;
    out.colliding += cold.collides;
    out.cold_tests += cold.counters.bv_tests;
    out.coherent_tests += r.counters.bv_tests;
  }
  out.hits = state.witness_hits();
  return out;
}

TEST(CoherentAdb, GuidedExactStaysExactWithFewerTests) {
  const AdbTrees<Aabb> trees;
  CoherentState state;
  const auto poses = path(240);
  std::uint64_t cold_tests = 0, coherent_tests = 0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Result cold = query_adb(trees.a, trees.b, poses[k], guided());
    const Result r = query_adb_coherent(trees.a, trees.b, poses[k], guided(), state);
    ASSERT_EQ(r.collides, path_truth()[k]) << "pose " << k;
    EXPECT_TRUE(r.exact) << "pose " << k;
    if (r.collides) {
      ASSERT_TRUE(witness_intersects(r, poses[k])) << "pose " << k;
    }
    cold_tests += cold.counters.bv_tests;
    coherent_tests += r.counters.bv_tests;
  }
  EXPECT_GT(state.witness_hits(), 0u);
  EXPECT_LT(coherent_tests, cold_tests);
}

TEST(CoherentAdb, AdbKeepsItsAnswersWithFewerTestsOnEveryOrder) {
  const AdbTrees<Obb> trees;
  AdbOptions options;
  options.p_min = 0.9;
  for (const Comparison& c : {compare(trees, options), compare<AdbDepthFirst>(trees, options),
                              compare<AdbLargerFirst>(trees, options)}) {
    EXPECT_GT(c.colliding, 0u);
    EXPECT_GT(c.hits, 0u);
    EXPECT_LT(c.coherent_tests, c.cold_tests);
    // The remembered pair decides as the traversal would on reaching it; the cold traversal may not reach
    // it (an ancestor's estimate of 0 drops the branch), so a few answers may differ, never many.
    EXPECT_LE(c.disagreements, 240u / 50) << c.disagreements;
  }
}

TEST(CoherentAdb, TimeCriticalRecallsWithinItsBudget) {
  const AdbTrees<Obb> trees;
  AdbOptions options;
  // A budget that lets the traversal decide below the root: a query the budget stops leaves no pair.
  options.budget.max_bv_tests = 400;
  const Comparison c = compare(trees, options);
  EXPECT_GT(c.hits, 0u);
  EXPECT_LT(c.coherent_tests, c.cold_tests) << c.hits << " hits, " << c.colliding << " colliding";
  EXPECT_LE(c.disagreements, 240u / 50) << c.disagreements;
}

TEST(CoherentAdb, VolumesWithStateFromTheRootRunAsTheColdQuery) {
  const AdbTrees<RestrictedBox> trees;
  AdbOptions options;
  CoherentState state;
  for (const RigidTransform& pose : path(240)) {
    const Result cold = query_adb(trees.a, trees.b, pose, options);
    const Result r = query_adb_coherent(trees.a, trees.b, pose, options, state);
    ASSERT_EQ(r.collides, cold.collides);
    ASSERT_EQ(r.counters.bv_tests, cold.counters.bv_tests);
  }
  EXPECT_EQ(state.witness_hits(), 0u);
}

TEST(CoherentAdb, AStateServesOneKindOfQueryAtATime) {
  const AdbTrees<Obb> trees;
  const auto poses = path(240);
  CoherentState state;
  const AdbOptions options;
  std::size_t k = 0;  // the first pose whose answer the remembered pair gives
  while (k < poses.size() && state.witness_hits() == 0)
    (void)query_adb_coherent(trees.a, trees.b, poses[k++], options, state);
  ASSERT_EQ(state.witness_hits(), 1u);
  const RigidTransform pose = poses[k - 1];
  // The exact query starts the state afresh (ADB's deciding pair is no colliding leaf pair), and so does
  // the ADB query after it: no recall at the very pose the ADB query just recalled at.
  EXPECT_EQ(query_exact_coherent(trees.a.bvh, trees.b.bvh, pose, state).collides, path_truth()[k - 1]);
  const Result after = query_adb_coherent(trees.a, trees.b, pose, options, state);
  CoherentState fresh;
  const Result from_fresh = query_adb_coherent(trees.a, trees.b, pose, options, fresh);
  EXPECT_EQ(after.collides, from_fresh.collides);
  EXPECT_EQ(after.counters.bv_tests, from_fresh.counters.bv_tests);
  EXPECT_EQ(state.witness_hits(), 1u);
  // Trees of another volume are refused by name.
  const AdbTrees<Aabb> others;
  EXPECT_NE(testing::error_of([&] {
              (void)query_adb_coherent(others.a, others.b, pose, options, state);
            }).find("other trees"),
            std::string::npos);
}

}  // namespace
}  // namespace bvhlab::coherent_tests
