// Deadlines of the time-critical strategy, on every shipped volume: a query whose deadline passed is
// flagged however it ended (stopped, decided, queue empty); a deadline never reached changes nothing; a
// BV-test cap flags only a traversal it stopped. Flags and answers only: no assertion on speed.
#include "adb/adb_density.hpp"
#include "support/crude_annotation.hpp"
#include "support/generated_meshes.hpp"
#include "support/volume_lists.hpp"
#include "traversal/adb.hpp"

#include <gtest/gtest.h>

#include <random>
#include <type_traits>
#include <vector>

namespace bvhlab {
namespace {

template <class BV>
struct Scene {
  Mesh mesh_a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh mesh_b = testing::make_random_soup(500, 0.1, 3);
  Tree<BV, AdbDensity> a = testing::crude_adb_tree<BV>(mesh_a);
  Tree<BV, AdbDensity> b = testing::crude_adb_tree<BV>(mesh_b);
};

AdbOptions with_deadline(double deadline_us, double p_min = 0.9) {
  AdbOptions options;
  options.p_min = p_min;
  options.budget.deadline_us = deadline_us;
  return options;
}

template <class BV>
class Deadline : public ::testing::Test {};
TYPED_TEST_SUITE(Deadline, testing::TraversalTestVolumes);

TYPED_TEST(Deadline, ATinyDeadlineIsAlwaysFlagged) {
  const Scene<TypeParam> scene;
  std::mt19937_64 rng(5);
  int disproved = 0, stopped = 0;
  for (double p_min : {0.0, 0.9, 1.0})  // 0: an overlapping root decides; 1: nothing decides
    for (int k = 0; k < 60; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 2.0);
      const Result r = query_adb(scene.a, scene.b, pose, with_deadline(1e-3, p_min));
      ASSERT_TRUE(r.budget_exhausted) << "p_min " << p_min << ", pose " << k;
      // The deadline had passed before the first pop: nothing was taken off the queue.
      EXPECT_EQ(r.counters.nodes_visited, 0u);
      if (p_min == 1.0) (r.exact ? disproved : stopped) += 1;
    }
  // Both ends occur: the root disproved (the queue empty at once) and the loop stopped before its first pop.
  EXPECT_GT(disproved, 0);
  EXPECT_GT(stopped, 0);
}

TYPED_TEST(Deadline, AGenerousDeadlineChangesNothing) {
  const Scene<TypeParam> scene;
  std::mt19937_64 rng(7);
  int colliding = 0;
  for (int k = 0; k < 60; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 2.0);
    AdbOptions unbudgeted;
    unbudgeted.p_min = 0.99;
    const Result expected = query_adb(scene.a, scene.b, pose, unbudgeted);
    const Result r = query_adb(scene.a, scene.b, pose, with_deadline(1e9, 0.99));  // about 17 minutes
    ASSERT_FALSE(r.budget_exhausted) << "pose " << k;
    EXPECT_EQ(r.collides, expected.collides) << "pose " << k;
    EXPECT_EQ(r.exact, expected.exact) << "pose " << k;
    EXPECT_EQ(r.probability, expected.probability) << "pose " << k;
    EXPECT_EQ(r.counters.bv_tests, expected.counters.bv_tests) << "pose " << k;
    EXPECT_EQ(r.counters.nodes_visited, expected.counters.nodes_visited) << "pose " << k;
    colliding += r.collides;
  }
  EXPECT_GT(colliding, 0);  // both answers occur, or the comparison shows little
  EXPECT_LT(colliding, 60);
}

TYPED_TEST(Deadline, ALateDecisionKeepsItsAnswerAndIsFlagged) {
  const Scene<TypeParam> scene;
  // p_min = 0 on one tree against itself: the root pair decides "collision" with the first test, before
  // the loop ever reads the clock. Only the check after the traversal sees the deadline passed.
  const Result on_time = query_adb(scene.a, scene.a, RigidTransform::identity(), with_deadline(1e9, 0.0));
  const Result late = query_adb(scene.a, scene.a, RigidTransform::identity(), with_deadline(1e-3, 0.0));
  ASSERT_TRUE(on_time.collides);
  EXPECT_EQ(late.counters.bv_tests, 1u);
  EXPECT_FALSE(on_time.budget_exhausted);
  EXPECT_TRUE(late.budget_exhausted);
  EXPECT_EQ(late.collides, on_time.collides);
  EXPECT_EQ(late.probability, on_time.probability);
}

TYPED_TEST(Deadline, ALateEmptyQueueKeepsItsExactAnswerAndIsFlagged) {
  const Scene<TypeParam> scene;
  // Far apart: the root test disproves contact and the queue is empty before the loop starts.
  const RigidTransform apart = RigidTransform::translate(Vec3(10, 0, 0));
  const Result late = query_adb(scene.a, scene.b, apart, with_deadline(1e-3));
  EXPECT_EQ(late.counters.bv_tests, 1u);
  EXPECT_FALSE(late.collides);
  EXPECT_TRUE(late.exact);  // the answer is complete: every pair was disproved
  EXPECT_TRUE(late.budget_exhausted);
  EXPECT_FALSE(query_adb(scene.a, scene.b, apart, with_deadline(1e9)).budget_exhausted);
}

TYPED_TEST(Deadline, ABvTestCapFlagsOnlyATraversalItStopped) {
  const Scene<TypeParam> scene;
  std::mt19937_64 rng(11);
  int stopped = 0;
  for (int k = 0; k < 40; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.0);
    AdbOptions unbudgeted;
    unbudgeted.p_min = 1.0;  // never decisive: the traversal runs until the queue empties
    const Result full = query_adb(scene.a, scene.b, pose, unbudgeted);
    AdbOptions capped = unbudgeted;
    capped.budget.max_bv_tests = full.counters.bv_tests;  // exactly enough
    const Result enough = query_adb(scene.a, scene.b, pose, capped);
    EXPECT_FALSE(enough.budget_exhausted) << "pose " << k;
    EXPECT_EQ(enough.counters.bv_tests, full.counters.bv_tests);
    EXPECT_EQ(enough.exact, full.exact);
    if (full.counters.bv_tests < 2) continue;
    capped.budget.max_bv_tests = full.counters.bv_tests - 1;  // one short
    const Result short_one = query_adb(scene.a, scene.b, pose, capped);
    EXPECT_TRUE(short_one.budget_exhausted) << "pose " << k;
    EXPECT_FALSE(short_one.exact);
    ++stopped;
  }
  EXPECT_GT(stopped, 0);
}

TEST(BudgetLimit, StopsOnlyAtItsDeadline) {
  BudgetLimit none(Budget{.max_bv_tests = 5, .deadline_us = 0});
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(none.allows_pop());
  EXPECT_FALSE(none.deadline_passed());
  EXPECT_TRUE(none.allows_test(Counters{.bv_tests = 4}));
  EXPECT_FALSE(none.allows_test(Counters{.bv_tests = 5}));
  // Two reads of the clock are more than a nanosecond apart: the first pop is refused.
  BudgetLimit tiny(Budget{.max_bv_tests = 0, .deadline_us = 1e-3});
  EXPECT_FALSE(tiny.allows_pop());
  EXPECT_TRUE(tiny.deadline_passed());
  EXPECT_TRUE(tiny.allows_test(Counters{.bv_tests = 1'000'000}));
  BudgetLimit roomy(Budget{.max_bv_tests = 0, .deadline_us = 1e9});
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(roomy.allows_pop());
  EXPECT_FALSE(roomy.deadline_passed());
  // Out-of-range deadlines neither overflow nor wrap into the past.
  BudgetLimit huge(Budget{.max_bv_tests = 0, .deadline_us = 1e300});
  EXPECT_TRUE(huge.allows_pop());
  EXPECT_FALSE(huge.deadline_passed());
}

}  // namespace
}  // namespace bvhlab
