// ADB strategies: guided exact equals exact; budgets are honoured; p_min behaves at its ends.
#include "adb/tree.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"
#include "volumes/restricted_box.hpp"

#include <gtest/gtest.h>

#include <random>

namespace bvhlab {
namespace {

// A crude stand-in annotation, independent of adb/annotate: pc = min(g^3, triangles below the node).
template <int G, class BV = Aabb>
Tree<BV, AdbDensity<G>> crude_annotation(Bvh<BV> bvh, double tau) {
  Tree<BV, AdbDensity<G>> tree{std::move(bvh), {}};
  const auto ranges = node_triangle_ranges(tree.bvh.nodes());
  for (const auto& [begin, end] : ranges)
    tree.density.possible_collision_cells.push_back(
        static_cast<std::uint8_t>(std::min<std::uint32_t>(AdbDensity<G>::cells, end - begin)));
  tree.density.tau = tau;
  return tree;
}

struct Scene {
  Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh b = testing::make_random_soup(500, 0.1, 3);
  Tree<Aabb, AdbDensity<2>> tree_a = crude_annotation<2>(Bvh<Aabb>::build(a), 0.5);
  Tree<Aabb, AdbDensity<2>> tree_b = crude_annotation<2>(Bvh<Aabb>::build(b), 0.5);
  AdbModel model{2, 0.5};
};

TEST(AdbTraversal, GuidedExactEqualsExactTraversal) {
  const Scene scene;
  AdbOptions options;
  options.exact_leaves = true;
  std::mt19937_64 rng(17);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result guided = query_adb(scene.tree_a, scene.tree_b, pose, scene.model, options);
    const Result exact = query_exact(scene.tree_a.bvh, scene.tree_b.bvh, pose);
    ASSERT_EQ(guided.collides, exact.collides) << "pose " << k;
    ASSERT_TRUE(guided.exact);
    colliding += exact.collides;
  }
  EXPECT_GT(colliding, 30);
  EXPECT_LT(colliding, 270);
}

TEST(AdbTraversal, GuidedExactOnTheRestrictedBoxtree) {
  const Scene scene;
  const auto tree_a = crude_annotation<2>(Bvh<RestrictedBox>::build(scene.a), 0.5);
  const auto tree_b = crude_annotation<2>(Bvh<RestrictedBox>::build(scene.b), 0.5);
  AdbOptions guided;
  guided.exact_leaves = true;
  std::mt19937_64 rng(31);
  for (int k = 0; k < 200; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result r = query_adb(tree_a, tree_b, pose, scene.model, guided);
    ASSERT_EQ(r.collides, query_exact(scene.tree_a.bvh, scene.tree_b.bvh, pose).collides) << "pose " << k;
  }
}

TEST(AdbTraversal, BvTestBudgetIsNeverExceeded) {
  const Scene scene;
  std::mt19937_64 rng(23);
  for (std::uint64_t budget : {1u, 2u, 5u, 17u, 100u}) {
    AdbOptions options;
    options.p_min = 1.0;  // never decisive: the traversal runs until the budget stops it
    options.budget.max_bv_tests = budget;
    for (int k = 0; k < 50; ++k) {
      const Result r =
          query_adb(scene.tree_a, scene.tree_b, testing::random_pose(rng, 0.5), scene.model, options);
      EXPECT_LE(r.counters.bv_tests, budget);
      if (r.budget_exhausted) {
        EXPECT_FALSE(r.exact);
        EXPECT_GE(r.probability, 0.0);
        EXPECT_LE(r.probability, 1.0);
        EXPECT_EQ(r.collides, r.probability >= options.best_effort_threshold);
      }
    }
  }
}

TEST(AdbTraversal, PMinEnds) {
  const Scene scene;
  const RigidTransform overlapping = RigidTransform::identity();
  AdbOptions eager;
  eager.p_min = 0.0;  // any positive estimate decides
  const Result r0 = query_adb(scene.tree_a, scene.tree_a, overlapping, scene.model, eager);
  EXPECT_TRUE(r0.collides);
  EXPECT_FALSE(r0.exact);
  EXPECT_GT(r0.probability, 0.0);

  AdbOptions never;
  never.p_min = 1.0;  // no estimate exceeds 1: the queue drains, leaves are dropped, the answer is inexact
  const Result r1 = query_adb(scene.tree_a, scene.tree_a, overlapping, scene.model, never);
  EXPECT_FALSE(r1.collides);
  EXPECT_FALSE(r1.exact);
}

TEST(AdbTraversal, CombiningLeafEvidenceOnlyAddsCollisionsAndNeverCostsMore) {
  const Scene scene;
  std::mt19937_64 rng(37);
  int changed = 0;
  for (double p_min : {0.5, 0.9, 0.99})
    for (int k = 0; k < 150; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 1.2);
      AdbOptions literal;
      literal.p_min = p_min;
      literal.combine_leaf_evidence = false;
      AdbOptions combined = literal;
      combined.combine_leaf_evidence = true;
      const Result a = query_adb(scene.tree_a, scene.tree_b, pose, scene.model, literal);
      const Result b = query_adb(scene.tree_a, scene.tree_b, pose, scene.model, combined);
      // Same traversal order until the combined evidence decides, so a literal "collision" is found too.
      if (a.collides) {
        EXPECT_TRUE(b.collides) << "pose " << k;
      }
      EXPECT_LE(b.counters.bv_tests, a.counters.bv_tests);
      EXPECT_TRUE(b.probability >= 0 && b.probability <= 1);
      changed += a.collides != b.collides;
    }
  EXPECT_GT(changed, 0);  // the option must matter on this scene, or the test shows nothing
}

TEST(AdbTraversal, ConfirmationNeverDecidesOnASingleCoarsePair) {
  const Scene scene;
  AdbOptions confirm;
  confirm.p_min = 0.0;  // every overlapping pair exceeds p_min: without confirmation the root decides
  confirm.confirm_with_children = true;
  const Result r = query_adb(scene.tree_a, scene.tree_a, RigidTransform::identity(), scene.model, confirm);
  EXPECT_TRUE(r.collides);
  EXPECT_GT(r.counters.bv_tests, 1u);  // the root's children were consulted
  AdbOptions literal = confirm;
  literal.confirm_with_children = false;
  EXPECT_EQ(query_adb(scene.tree_a, scene.tree_a, RigidTransform::identity(), scene.model, literal)
                .counters.bv_tests,
            1u);
}

TEST(AdbTraversal, DisjointIsAnExactNo) {
  const Scene scene;
  const Result r =
      query_adb(scene.tree_a, scene.tree_b, RigidTransform::translate(Vec3(10, 0, 0)), scene.model, {});
  EXPECT_FALSE(r.collides);
  EXPECT_TRUE(r.exact);
  EXPECT_EQ(r.counters.bv_tests, 1u);
}

TEST(AdbTraversal, NonsenseOptionsAndMismatchedTauAreRejected) {
  const Scene scene;
  AdbOptions bad;
  bad.p_min = std::nan("");
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, scene.model, bad), std::invalid_argument);
  bad.p_min = 1.5;
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, scene.model, bad), std::invalid_argument);
  const AdbModel other_tau(2, 0.25);
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, other_tau, {}), std::invalid_argument);
}

Box cube(double side) {
  return {Vec3::Zero(), Vec3::Constant(side)};
}

TEST(AdbModel, EqualSizesReduceToThePaperCaseAndDifferentSizesScale) {
  const AdbModel model(2, 0.5);
  // Equal volumes fully overlapping: s = 8, s_A = pc_A, s_B = pc_B: exactly the table entry.
  EXPECT_DOUBLE_EQ(model.estimate(cube(2), cube(2), 8.0, 3, 5), model.table().lookup(8, 3, 5));
  // Half overlap: s = 4, s_A = pc_A / 2.
  EXPECT_DOUBLE_EQ(model.estimate(cube(2), cube(2), 4.0, 4, 2), model.table().lookup(4, 2, 1));
  // B eight times smaller (cell side ratio 1/2) inside A: s = Vol(B) / c_A = 1 coarse cell; A's count is
  // scaled by overlap / Vol(A) = 1/8, B's by the face-area ratio 1/4: s_a = 1, s_b = min(2, s) = 1.
  EXPECT_DOUBLE_EQ(model.estimate(cube(2), cube(1), 1.0, 8, 8), model.table().lookup(1, 1, 1));
  // Symmetric in the roles of A and B.
  EXPECT_DOUBLE_EQ(model.estimate(cube(1), cube(2), 1.0, 8, 8), model.estimate(cube(2), cube(1), 1.0, 8, 8));
  // Fractional expected counts interpolate: halfway between the integer entries.
  const double mid = model.estimate(cube(2), cube(2), 8.0 * 0.75, 2, 2);  // s = 6, s_a = s_b = 1.5
  EXPECT_NEAR(mid,
              0.25 * (model.table().lookup(6, 1, 1) + model.table().lookup(6, 2, 1) +
                      model.table().lookup(6, 1, 2) + model.table().lookup(6, 2, 2)),
              1e-15);
  // No possible collision cell on one side: probability 0.
  EXPECT_EQ(model.estimate(cube(2), cube(2), 8.0, 0, 8), 0.0);
  // Never outside [0, 1], never NaN, on a sweep including flat, tiny and huge boxes.
  const Box flat{Vec3::Zero(), Vec3(1, 1, 0)};
  for (const Box& a : {cube(0), cube(1e-300), flat, cube(1), cube(1e100)})
    for (double ov : {0.0, 1e-300, 0.5, 1.0, 1e300})
      for (int pa : {0, 1, 8})
        for (int pb : {0, 1, 8}) {
          const double q = model.estimate(a, cube(1), ov, pa, pb);
          EXPECT_TRUE(q >= 0 && q <= 1) << a.max.x() << " " << ov << " " << pa << " " << pb << " -> " << q;
        }
}

}  // namespace
}  // namespace bvhlab
