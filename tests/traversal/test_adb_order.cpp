// The ADB traversal's orders: best first (the paper's), probability-ordered depth first, and best first
// splitting only the larger node. Guided exact stays exact in either order; adb in depth-first order gives
// adb's answers; budgets and the best-effort answer hold for a stack; depth first reaches a leaf pair
// sooner; splitting the larger node stays honest and spends fewer tests on objects of very different size.
#include "adb/adb_density.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"
#include "volumes/dop24.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"
#include "volumes/sphere.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace bvhlab {
namespace {

// A crude stand-in annotation (pc = min(g^3, triangles below the node)): the estimates order the descent;
// their quality does not matter here.
template <class BV>
Tree<BV, AdbDensity> crude_annotation(Bvh<BV> bvh) {
  std::vector<std::uint8_t> counts;
  for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
    counts.push_back(static_cast<std::uint8_t>(std::min(8u, end - begin)));
  return {std::move(bvh), AdbDensity::make_storage({2, 0.5}, std::move(counts))};
}

template <class BV>
struct OrderScene {
  Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh b = testing::make_random_soup(500, 0.1, 3);
  Tree<BV, AdbDensity> tree_a = crude_annotation(Bvh<BV>::build(a));
  Tree<BV, AdbDensity> tree_b = crude_annotation(Bvh<BV>::build(b));
};

AdbOptions guided_exact() {
  AdbOptions options;
  options.p_min = 1;
  options.exact_leaves = true;
  return options;
}

template <class BV>
class GuidedExactDepthFirst : public ::testing::Test {};
using Volumes = ::testing::Types<Aabb, Obb, Dop24, Sphere, RestrictedBox>;
TYPED_TEST_SUITE(GuidedExactDepthFirst, Volumes);

TYPED_TEST(GuidedExactDepthFirst, EqualsTheExactAnswer) {
  const OrderScene<TypeParam> scene;
  std::mt19937_64 rng(59);
  int colliding = 0;
  for (int k = 0; k < 250; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result dfs = query_adb<AdbDepthFirst>(scene.tree_a, scene.tree_b, pose, guided_exact());
    Result all = query_exact(scene.tree_a.bvh, scene.tree_b.bvh, pose, ContactMode::All);
    const bool collides = !all.contacts.empty();
    ASSERT_EQ(dfs.collides, collides) << "pose " << k;
    ASSERT_TRUE(dfs.exact);
    EXPECT_FALSE(dfs.budget_exhausted);
    if (collides) {
      // The witness is a real contact.
      ASSERT_TRUE(dfs.witness.has_value());
      std::sort(all.contacts.begin(), all.contacts.end());
      EXPECT_TRUE(std::binary_search(all.contacts.begin(), all.contacts.end(), *dfs.witness)) << "pose " << k;
    }
    colliding += collides;
  }
  EXPECT_GT(colliding, 25);
  EXPECT_LT(colliding, 225);
}

// Without a budget, decisions are made as pairs are filed, and the pairs filed until the queue runs empty do
// not depend on the order: depth first must give best first's answer, pose by pose.
TEST(AdbDepthFirst, GivesTheBestFirstAnswersAndIsHonest) {
  const OrderScene<Aabb> scene;
  std::mt19937_64 rng(61);
  int collisions = 0, inexact_no = 0, differing_work = 0;
  for (double p_min : {0.3, 0.7, 0.9, 0.99}) {
    for (bool combine : {true, false}) {
      AdbOptions options;
      options.p_min = p_min;
      options.combine_leaf_evidence = combine;
      for (int k = 0; k < 100; ++k) {
        const RigidTransform pose = testing::random_pose(rng, 2.0);
        const Result best = query_adb(scene.tree_a, scene.tree_b, pose, options);
        const Result dfs = query_adb<AdbDepthFirst>(scene.tree_a, scene.tree_b, pose, options);
        ASSERT_EQ(dfs.collides, best.collides) << "p_min " << p_min << ", pose " << k;
        ASSERT_EQ(dfs.exact, best.exact) << "p_min " << p_min << ", pose " << k;
        EXPECT_GE(dfs.probability, 0.0);
        EXPECT_LE(dfs.probability, 1.0);
        EXPECT_FALSE(dfs.budget_exhausted);
        if (dfs.collides) {
          EXPECT_GT(dfs.probability, p_min);  // a decision exceeds p_min
        }
        // Exact only when really exact: then it is the exact answer.
        if (dfs.exact) {
          EXPECT_EQ(dfs.collides, query_exact(scene.tree_a.bvh, scene.tree_b.bvh, pose).collides);
        }
        collisions += dfs.collides;
        inexact_no += !dfs.collides && !dfs.exact;
        differing_work += dfs.counters.bv_tests != best.counters.bv_tests;
      }
    }
  }
  // Both kinds of answer occur, and the orders do differ in their work (on this scene most answers come
  // from the first few pairs, whatever the order).
  EXPECT_GT(collisions, 200);
  EXPECT_GT(inexact_no, 50);
  EXPECT_GT(differing_work, 3);
}

/// AdbHooks that, at finish, also record the highest key still queued by taking every pair off a copy of
/// the queue: an independent check of what the best-effort answer must see.
template <class Estimate>
struct InspectedHooks : AdbHooks<Aabb, Estimate> {
  using AdbHooks<Aabb, Estimate>::AdbHooks;
  double highest_left = -1, top_left = -1;
  template <class Queue>
  void finish(const Queue& queue, Ended why) {
    AdbHooks<Aabb, Estimate>::finish(queue, why);
    Queue copy = queue;
    if (!copy.empty()) top_left = copy.top().key;
    while (!copy.empty()) highest_left = std::max(highest_left, copy.pop().key);
  }
};

template <class Order>
Result budgeted(const OrderScene<Aabb>& scene, const RigidTransform& pose, const AdbOptions& options,
                double* highest_left, double* top_left) {
  Result result;
  BudgetLimit limit(options.budget);
  const auto context = VolumeWalker<Aabb>::make_context(pose);
  const TreePair<Aabb> trees(scene.tree_a.bvh, scene.tree_b.bvh, pose, context, result.counters);
  const auto model = AdbDensity::estimator(scene.tree_a.density, scene.tree_b.density);
  const auto estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                            std::uint32_t j) { return model(i, box_a, j, box_b, overlap); };
  InspectedHooks<decltype(estimate)> hooks(trees, result, options, estimate);
  traverse<typename Order::Queue, typename Order::Descent>(trees, hooks, limit);
  *highest_left = hooks.highest_left;
  *top_left = hooks.top_left;
  return result;
}

TEST(AdbDepthFirst, BudgetsHoldAndTheBestEffortSeesTheWholeStack) {
  const OrderScene<Aabb> scene;
  std::mt19937_64 rng(67);
  int exhausted = 0, top_was_not_best = 0;
  for (std::uint64_t budget : {1u, 2u, 5u, 17u, 60u, 200u}) {
    AdbOptions options;
    options.p_min = 1.0;  // never decisive: the traversal runs until the budget stops it
    options.combine_leaf_evidence = false;
    options.budget.max_bv_tests = budget;
    for (int k = 0; k < 60; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 0.5);
      // Through query_adb: the budget is never exceeded, and an exhausted one is flagged.
      const Result r = query_adb<AdbDepthFirst>(scene.tree_a, scene.tree_b, pose, options);
      EXPECT_LE(r.counters.bv_tests, budget);
      EXPECT_GE(r.probability, 0.0);
      EXPECT_LE(r.probability, 1.0);
      if (!r.budget_exhausted) continue;
      ++exhausted;
      EXPECT_FALSE(r.exact);
      EXPECT_EQ(r.collides, r.probability >= options.best_effort_threshold);
      // The same run, inspected: its probability is at least every estimate still queued.
      double highest = -1, top = -1;
      const Result inspected = budgeted<AdbDepthFirst>(scene, pose, options, &highest, &top);
      ASSERT_TRUE(inspected.budget_exhausted);
      EXPECT_EQ(inspected.probability, r.probability);
      EXPECT_GE(r.probability, highest) << "budget " << budget << ", pose " << k;
      top_was_not_best += top < highest;
    }
  }
  EXPECT_GT(exhausted, 150);
  // A stack's top is often not its most probable pair: the check above matters.
  EXPECT_GT(top_was_not_best, 40);
}

/// Guided-exact hooks that note the BV tests spent when the first leaf pair is taken off the queue.
template <class Estimate>
struct FirstLeafHooks : AdbHooks<Aabb, Estimate> {
  using Base = AdbHooks<Aabb, Estimate>;
  FirstLeafHooks(const TreePair<Aabb>& trees, Result& result, const AdbOptions& options, const Estimate& e)
      : Base(trees, result, options, e), counters(trees.counters) {}
  const Counters& counters;
  std::uint64_t bv_tests_at_first_leaf = 0;
  Step leaf_pair(const typename Base::Pair& p) {
    if (bv_tests_at_first_leaf == 0) bv_tests_at_first_leaf = counters.bv_tests;
    return Base::leaf_pair(p);
  }
};

template <class Order>
std::uint64_t bv_tests_to_first_leaf(const Tree<Aabb, AdbDensity>& tree, const RigidTransform& pose) {
  Result result;
  const AdbOptions options = guided_exact();
  const auto context = VolumeWalker<Aabb>::make_context(pose);
  const TreePair<Aabb> trees(tree.bvh, tree.bvh, pose, context, result.counters);
  const auto model = AdbDensity::estimator(tree.density, tree.density);
  const auto estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                            std::uint32_t j) { return model(i, box_a, j, box_b, overlap); };
  FirstLeafHooks<decltype(estimate)> hooks(trees, result, options, estimate);
  Unlimited limit;
  traverse<typename Order::Queue, typename Order::Descent>(trees, hooks, limit);
  return hooks.bv_tests_at_first_leaf;
}

// A fine torus against itself, deeply overlapping: many node pairs look alike, so best first widens level
// by level before it takes a leaf pair; depth first dives.
TEST(AdbDepthFirst, ReachesTheFirstLeafPairInFewerBvTests) {
  const auto tree = crude_annotation(Bvh<Aabb>::build(testing::make_torus(0.7, 0.25, 120, 60)));
  std::mt19937_64 rng(71);
  std::uint64_t best_total = 0, dfs_total = 0;
  int dfs_sooner = 0;
  const int poses = 40;
  for (int k = 0; k < poses; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 0.3);
    const std::uint64_t best = bv_tests_to_first_leaf<AdbBestFirst>(tree, pose);
    const std::uint64_t dfs = bv_tests_to_first_leaf<AdbDepthFirst>(tree, pose);
    ASSERT_GT(best, 0u) << "pose " << k;  // a leaf pair was reached at all
    ASSERT_GT(dfs, 0u) << "pose " << k;
    best_total += best;
    dfs_total += dfs;
    dfs_sooner += dfs < best;
  }
  EXPECT_GT(dfs_sooner, poses * 3 / 4);
  EXPECT_LT(dfs_total * 10, best_total);
}

/// A torus of size ~2 and one a hundred times smaller, annotated as shipped (2x2x2 cells, default tau).
template <class BV>
struct SizePair {
  Mesh large = testing::make_torus(0.7, 0.25, 60, 30);
  Mesh small = testing::make_torus(0.007, 0.0025, 16, 8);
  Tree<BV, AdbDensity> tree_a = annotate_adb(Bvh<BV>::build(large));
  Tree<BV, AdbDensity> tree_b = annotate_adb(Bvh<BV>::build(small));
};

/// The small torus placed on a vertex of the large one, turned at random and moved by up to `jitter`:
/// about half the poses touch.
RigidTransform on_the_surface(const Mesh& large, std::mt19937_64& rng, double jitter) {
  RigidTransform pose = testing::random_pose(rng, jitter);
  std::uniform_int_distribution<std::size_t> vertex(0, large.vertices.size() - 1);
  pose.translation += large.vertices[vertex(rng)];
  return pose;
}

/// adb_larger's and adb's work over poses of the small torus on the large one's surface, with adb_larger's
/// honesty checked pose by pose: a colliding pose never gets probability 0, a decision exceeds p_min, and an
/// answer marked exact is the exact one.
struct SizePairTally {
  int poses = 200, colliding = 0, agreeing = 0;
  std::uint64_t larger_tests = 0, both_tests = 0;
};
template <class BV>
SizePairTally run_size_pair() {
  const SizePair<BV> scene;
  std::mt19937_64 rng(73);
  AdbOptions options;
  options.p_min = 0.9;
  SizePairTally tally;
  for (int k = 0; k < tally.poses; ++k) {
    const RigidTransform pose = on_the_surface(scene.large, rng, 0.02);
    const Result larger = query_adb<AdbLargerFirst>(scene.tree_a, scene.tree_b, pose, options);
    const Result both = query_adb(scene.tree_a, scene.tree_b, pose, options);
    const bool truth = query_exact(scene.tree_a.bvh, scene.tree_b.bvh, pose).collides;
    if (truth) {
      EXPECT_GT(larger.probability, 0.0) << "pose " << k;
    }
    if (larger.collides) {
      EXPECT_GT(larger.probability, options.p_min) << "pose " << k;
    }
    if (larger.exact) {
      EXPECT_EQ(larger.collides, truth) << "pose " << k;
    }
    tally.colliding += truth;
    tally.agreeing += larger.collides == truth;
    tally.larger_tests += larger.counters.bv_tests;
    tally.both_tests += both.counters.bv_tests;
  }
  EXPECT_GT(tally.colliding, tally.poses / 5);  // both kinds of pose occur
  EXPECT_LT(tally.colliding, tally.poses * 4 / 5);
  return tally;
}

TEST(AdbLargerFirst, IsHonestOnObjectsOfVeryDifferentSizeOnAabbs) {
  run_size_pair<Aabb>();
}

// On OBBs, which fit the large torus's slanted triangles closely, splitting both nodes opens the small tree
// against every level of the large one; splitting the larger node does not, and its answers still follow
// the truth. (On AABBs the large nodes' boxes hold the small torus whole, and neither order helps much.)
TEST(AdbLargerFirst, SpendsFewerTestsThanSplittingBothOnObbs) {
  const SizePairTally tally = run_size_pair<Obb>();
  EXPECT_GT(tally.agreeing, tally.poses * 3 / 4);
  EXPECT_LT(2 * tally.larger_tests, tally.both_tests);
}

}  // namespace
}  // namespace bvhlab
