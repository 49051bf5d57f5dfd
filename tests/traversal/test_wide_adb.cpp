// ADB on wide trees (traversal/wide_adb.hpp): guided exact stays exact on every layout it walks; with p_min
// its answers are honest (an exact "no" only where no pair's volumes overlap, a "collision" only above
// p_min), its errors against the exact answer are of the binary walk's size, and budgets hold.
#include "adb/adb_density.hpp"
#include "support/crude_annotation.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/exact.hpp"
#include "traversal/wide_adb.hpp"
#include "volumes/dop24.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace bvhlab {
namespace {

template <class Lanes>
struct WideTrees {
  using BV = typename Lanes::Volume;
  Mesh mesh_a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh mesh_b = testing::make_random_soup(500, 0.1, 3);
  Tree<BV, AdbDensity> a = testing::crude_adb_tree<BV>(mesh_a), b = testing::crude_adb_tree<BV>(mesh_b);
  WideBvh<Lanes> wide_a = WideBvh<Lanes>::build(a.bvh), wide_b = WideBvh<Lanes>::build(b.bvh);
  template <class Order = AdbBestFirst>
  Result query(const RigidTransform& pose, const AdbOptions& options) const {
    return query_adb_wide<Order>(a, wide_a, b, wide_b, pose, options);
  }
};

using LaneTypes = ::testing::Types<Aabb4, Sphere4, Obb4, KDop4<dop_sets::Zachmann24>>;
template <class Lanes>
class WideAdb : public ::testing::Test {};
TYPED_TEST_SUITE(WideAdb, LaneTypes);

TYPED_TEST(WideAdb, EveryBinaryLeafIsOneLane) {
  const WideTrees<TypeParam> t;
  const auto& wide = t.wide_a;
  std::vector<int> seen(t.a.bvh.nodes().size(), 0);
  for (std::uint32_t n = 0; n < wide.size(); ++n)
    for (std::uint32_t lane = 0; lane < 4; ++lane)
      if (n == 0 ? lane == 0 : wide.node(n).child[lane] != 0)  // no node's child is the pseudo-node 0
        ++seen[wide.binary_node(n, lane)];
  EXPECT_EQ(wide.binary_node(0, 0), 0u);  // the pseudo-node's lane is the binary root
  for (std::uint32_t i = 0; i < seen.size(); ++i)
    EXPECT_EQ(seen[i], t.a.bvh.node(i).is_leaf() ? 1 : std::min(seen[i], 1)) << "binary node " << i;
}

TYPED_TEST(WideAdb, GuidedExactEqualsTheExactAnswer) {
  const WideTrees<TypeParam> t;
  AdbOptions guided;
  guided.exact_leaves = true;
  std::mt19937_64 rng(17);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result wide = t.query(pose, guided);
    const Result exact = query_exact(t.a.bvh, t.b.bvh, pose);
    ASSERT_EQ(wide.collides, exact.collides) << "pose " << k;
    ASSERT_TRUE(wide.exact);
    colliding += exact.collides;
  }
  EXPECT_GT(colliding, 30);
  EXPECT_LT(colliding, 270);
}

TYPED_TEST(WideAdb, AnswersAreHonestAndErrAsOftenAsTheBinaryWalk) {
  const WideTrees<TypeParam> t;
  std::mt19937_64 rng(29);
  for (const double p_min : {0.5, 0.9}) {
    AdbOptions options;
    options.p_min = p_min;
    int wrong_wide = 0, wrong_binary = 0, poses = 0;
    for (int k = 0; k < 300; ++k, ++poses) {
      const RigidTransform pose = testing::random_pose(rng, 1.5);
      const bool truth = query_exact(t.a.bvh, t.b.bvh, pose).collides;
      const Result wide = t.query(pose, options);
      if (wide.exact) ASSERT_EQ(wide.collides, truth) << "pose " << k;  // an exact "no" is a proof
      if (wide.collides) ASSERT_GT(wide.probability, p_min) << "pose " << k;
      ASSERT_EQ(wide.collides, t.template query<AdbDepthFirst>(pose, options).collides)
          << "the order changes the work, not the answer; pose " << k;
      wrong_wide += wide.collides != truth;
      wrong_binary += query_adb(t.a, t.b, pose, options).collides != truth;
    }
    // Another set of pairs estimated, so not the same answers; but not a walk that errs by construction.
    EXPECT_LE(wrong_wide, wrong_binary + poses / 10) << "p_min " << p_min;
  }
}

TYPED_TEST(WideAdb, TheRootPairIsEstimatedAsTheBinaryWalkEstimatesIt) {
  const WideTrees<TypeParam> t;
  AdbOptions eager;
  eager.p_min = 0;  // the root pair decides
  const RigidTransform pose = RigidTransform::translate(Vec3(0.3, 0, 0));
  const Result wide = t.query(pose, eager), binary = query_adb(t.a, t.b, pose, eager);
  ASSERT_TRUE(wide.collides && binary.collides);
  EXPECT_NEAR(wide.probability, binary.probability, 1e-12);
  EXPECT_EQ(wide.counters.bv_tests, 1u);
}

TYPED_TEST(WideAdb, BudgetsHoldWithinOneStep) {
  const WideTrees<TypeParam> t;
  std::mt19937_64 rng(23);
  for (const std::uint64_t budget : {1u, 2u, 5u, 17u, 100u}) {
    AdbOptions options;
    options.p_min = 1.0;  // never decisive: the walk runs until the budget stops it
    options.budget.max_bv_tests = budget;
    for (int k = 0; k < 50; ++k) {
      const Result r = t.query(testing::random_pose(rng, 0.5), options);
      EXPECT_LE(r.counters.bv_tests, budget + 3);  // a step tests four lanes
      if (!r.budget_exhausted) continue;
      EXPECT_FALSE(r.exact);
      EXPECT_TRUE(r.probability >= 0 && r.probability <= 1);
      EXPECT_EQ(r.collides, r.probability >= options.best_effort_threshold);
    }
  }
}

TEST(WideAdbDeadline, APassedDeadlineGivesTheBestEffortAnswerFlagged) {
  const WideTrees<Aabb4> t;
  AdbOptions options;
  options.p_min = 1.0;                // never decisive: only the deadline ends the walk early
  options.budget.deadline_us = 1e-6;  // passed before the first pop
  const Result r = t.query(RigidTransform::identity(), options);
  EXPECT_TRUE(r.budget_exhausted);
  EXPECT_FALSE(r.exact);
  EXPECT_EQ(r.collides, r.probability >= options.best_effort_threshold);
  EXPECT_LE(r.counters.nodes_visited, 1u);  // the clock is read before the first pop
}

TEST(WideAdbInput, RefusesWideTreesOfOtherTreesAndNonRigidPoses) {
  const WideTrees<Aabb4> t;
  const WideAabbTree other = WideAabbTree::build(Bvh<Aabb>::build(testing::make_random_soup(50, 0.1, 9)));
  EXPECT_THROW(query_adb_wide(t.a, other, t.b, t.wide_b, RigidTransform::identity(), {}),
               std::invalid_argument);
  RigidTransform sheared = RigidTransform::identity();
  sheared.rotation(0, 1) = 0.5;
  EXPECT_THROW(t.query(sheared, {}), std::invalid_argument);
  AdbOptions bad;
  bad.p_min = std::nan("");
  EXPECT_THROW(t.query(RigidTransform::identity(), bad), std::invalid_argument);
}

TEST(WideAdbInput, ApartIsAnExactNoFromOneTest) {
  const WideTrees<Aabb4> t;
  const Result r = t.query(RigidTransform::translate(Vec3(10, 0, 0)), {});
  EXPECT_FALSE(r.collides);
  EXPECT_TRUE(r.exact);
  EXPECT_EQ(r.counters.bv_tests, 1u);
}

}  // namespace
}  // namespace bvhlab
