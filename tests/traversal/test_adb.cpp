// ADB strategies: guided exact equals exact; budgets are honoured; p_min behaves at its ends.
#include "adb/adb_density.hpp"
#include "adb/adb_paper_density.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace bvhlab {
namespace {

// A crude stand-in annotation, independent of adb/annotate: pc = min(g^3, triangles below the node).
template <int G, class BV = Aabb, class D = AdbDensity>
Tree<BV, D> crude_annotation(Bvh<BV> bvh, double tau) {
  std::vector<std::uint8_t> counts;
  for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
    counts.push_back(static_cast<std::uint8_t>(std::min<std::uint32_t>(G * G * G, end - begin)));
  return {std::move(bvh), D::make_storage({G, tau}, std::move(counts))};
}

struct Scene {
  Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh b = testing::make_random_soup(500, 0.1, 3);
  Tree<Aabb, AdbDensity> tree_a = crude_annotation<2>(Bvh<Aabb>::build(a), 0.5);
  Tree<Aabb, AdbDensity> tree_b = crude_annotation<2>(Bvh<Aabb>::build(b), 0.5);
};

TEST(AdbTraversal, GuidedExactEqualsExactTraversal) {
  const Scene scene;
  AdbOptions options;
  options.exact_leaves = true;
  std::mt19937_64 rng(17);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result guided = query_adb(scene.tree_a, scene.tree_b, pose, options);
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
    const Result r = query_adb(tree_a, tree_b, pose, guided);
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
      const Result r = query_adb(scene.tree_a, scene.tree_b, testing::random_pose(rng, 0.5), options);
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
  const Result r0 = query_adb(scene.tree_a, scene.tree_a, overlapping, eager);
  EXPECT_TRUE(r0.collides);
  EXPECT_FALSE(r0.exact);
  EXPECT_GT(r0.probability, 0.0);

  AdbOptions never;
  never.p_min = 1.0;  // no estimate exceeds 1: the queue drains, leaves are dropped, the answer is inexact
  const Result r1 = query_adb(scene.tree_a, scene.tree_a, overlapping, never);
  EXPECT_FALSE(r1.collides);
  EXPECT_FALSE(r1.exact);
}

// On the paper's rule (adb_paper), where leaf pairs of this scene stay below p_min often enough for the
// option to matter; the default rule's estimates of small leaves are higher and seldom leave any evidence.
TEST(AdbTraversal, CombiningLeafEvidenceOnlyAddsCollisionsAndNeverCostsMore) {
  const Scene plain;
  const struct {
    Tree<Aabb, AdbPaperDensity> tree_a, tree_b;
  } scene{crude_annotation<2, Aabb, AdbPaperDensity>(Bvh<Aabb>::build(plain.a), 0.5),
          crude_annotation<2, Aabb, AdbPaperDensity>(Bvh<Aabb>::build(plain.b), 0.5)};
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
      const Result a = query_adb(scene.tree_a, scene.tree_b, pose, literal);
      const Result b = query_adb(scene.tree_a, scene.tree_b, pose, combined);
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
  const Result r = query_adb(scene.tree_a, scene.tree_a, RigidTransform::identity(), confirm);
  EXPECT_TRUE(r.collides);
  EXPECT_GT(r.counters.bv_tests, 1u);  // the root's children were consulted
  AdbOptions literal = confirm;
  literal.confirm_with_children = false;
  EXPECT_EQ(query_adb(scene.tree_a, scene.tree_a, RigidTransform::identity(), literal).counters.bv_tests, 1u);
}

TEST(AdbTraversal, ConfirmLevelsDecideOnlyThatManyGenerationsDown) {
  const Scene scene;
  for (std::uint8_t levels : {1, 2, 3}) {
    AdbOptions confirm;
    confirm.p_min = 0.0;  // every overlapping pair is a candidate: each generation confirms the one above
    confirm.confirm_levels = levels;
    // Depth first dives: the root, then one pair expanded per generation (both sides split: four children).
    const Result dive =
        query_adb<AdbDepthFirst>(scene.tree_a, scene.tree_a, RigidTransform::identity(), confirm);
    EXPECT_TRUE(dive.collides);
    EXPECT_FALSE(dive.exact);
    EXPECT_EQ(dive.counters.bv_tests, 1u + 4u * levels) << int(levels) << " levels";
    // Best first may expand a more probable pair of an earlier generation in between: never fewer.
    const Result best = query_adb(scene.tree_a, scene.tree_a, RigidTransform::identity(), confirm);
    EXPECT_TRUE(best.collides);
    EXPECT_GE(best.counters.bv_tests, 1u + 4u * levels) << int(levels) << " levels";
  }
}

TEST(AdbTraversal, ConfirmLevelsOnlyTakeCollisionsAway) {
  const Scene scene;
  std::mt19937_64 rng(41);
  int removed = 0;
  for (double p_min : {0.5, 0.9})
    for (int k = 0; k < 150; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 1.2);
      AdbOptions literal;
      literal.p_min = p_min;
      AdbOptions confirm = literal;
      confirm.confirm_levels = 3;
      const Result a = query_adb(scene.tree_a, scene.tree_b, pose, literal);
      const Result b = query_adb(scene.tree_a, scene.tree_b, pose, confirm);
      // Where no pair exceeds p_min both traversals are the same, so a literal "no" stays "no".
      if (b.collides) {
        EXPECT_TRUE(a.collides) << "pose " << k;
      }
      removed += a.collides && !b.collides;
    }
  EXPECT_GT(removed, 0);  // the option must matter on this scene, or the test shows nothing
}

TEST(AdbTraversal, DisjointIsAnExactNo) {
  const Scene scene;
  const Result r = query_adb(scene.tree_a, scene.tree_b, RigidTransform::translate(Vec3(10, 0, 0)), {});
  EXPECT_FALSE(r.collides);
  EXPECT_TRUE(r.exact);
  EXPECT_EQ(r.counters.bv_tests, 1u);
}

TEST(AdbTraversal, NonsenseOptionsAndMismatchedTauAreRejected) {
  const Scene scene;
  AdbOptions bad;
  bad.p_min = std::nan("");
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, bad), std::invalid_argument);
  bad.p_min = 1.5;
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, bad), std::invalid_argument);
  AdbOptions both;  // two confirmation rules at once: refused, not one silently ignored
  both.confirm_with_children = true;
  both.confirm_levels = 2;
  EXPECT_THROW(query_adb(scene.tree_a, scene.tree_b, {}, both), std::invalid_argument);
  // Trees annotated with another tau (or grid) cannot share one model: refused, not mixed.
  const auto other_tau = crude_annotation<2>(Bvh<Aabb>::build(scene.b), 0.25);
  EXPECT_THROW(query_adb(scene.tree_a, other_tau, {}, AdbOptions{}), std::invalid_argument);
  const auto other_grid = crude_annotation<3>(Bvh<Aabb>::build(scene.b), 0.5);
  EXPECT_THROW(query_adb(scene.tree_a, other_grid, {}, AdbOptions{}), std::invalid_argument);
}

Box cube(double side) {
  return {Vec3::Zero(), Vec3::Constant(side)};
}

TEST(AdbModel, EqualSizesReduceToThePaperCaseUnderBothRules) {
  const AdbModel model(2, 0.5);
  // Equal volumes fully overlapping: s = 8, s_A = pc_A, s_B = pc_B: exactly the table entry.
  EXPECT_DOUBLE_EQ(model.estimate<kAdbSizedRule>(cube(2), cube(2), 8.0, 3, 5), model.table().lookup(8, 3, 5));
  EXPECT_DOUBLE_EQ(model.estimate<kAdbPaperRule>(cube(2), cube(2), 8.0, 3, 5), model.table().lookup(8, 3, 5));
  // Half overlap: s = 4, s_A = pc_A / 2.
  EXPECT_DOUBLE_EQ(model.estimate<kAdbSizedRule>(cube(2), cube(2), 4.0, 4, 2), model.table().lookup(4, 2, 1));
  EXPECT_DOUBLE_EQ(model.estimate<kAdbPaperRule>(cube(2), cube(2), 4.0, 4, 2), model.table().lookup(4, 2, 1));
  // Fractional expected counts interpolate: halfway between the integer entries.
  const double mid = model.estimate(cube(2), cube(2), 8.0 * 0.75, 2, 2);  // s = 6, s_a = s_b = 1.5
  EXPECT_NEAR(mid,
              0.25 * (model.table().lookup(6, 1, 1) + model.table().lookup(6, 2, 1) +
                      model.table().lookup(6, 1, 2) + model.table().lookup(6, 2, 2)),
              1e-15);
}

TEST(AdbModel, DifferentSizesMapOntoTheRulesCells) {
  const AdbModel model(2, 0.5);
  // B eight times smaller (cell side ratio 1/2) inside A, both full (pc = 8).
  // Paper's rule, A's (coarser) cells: s = Vol(B) / c_A = 1; s_a = 8 * 1/8 = 1; s_b = 8 scaled down by the
  // face-area ratio 1/4 = 2, capped at s = 1.
  EXPECT_DOUBLE_EQ(model.estimate<kAdbPaperRule>(cube(2), cube(1), 1.0, 8, 8), model.table().lookup(1, 1, 1));
  // Default rule, B's (finer) cells: s = Vol(B) / c_B = 8; s_b = 8; s_a = 8 * 1/8 scaled up by 4 = 4.
  EXPECT_DOUBLE_EQ(model.estimate<kAdbSizedRule>(cube(2), cube(1), 1.0, 8, 8), model.table().lookup(8, 4, 8));
  // A single cell of A's surface, B 100 times smaller inside it: the estimate falls like the size ratio
  // under the default rule (s_a = pc_a / 100 = 0.01), like its square under the paper's (s_b = 8e-4).
  const double sized = model.estimate<kAdbSizedRule>(cube(100), cube(1), 1.0, 1, 8);
  EXPECT_NEAR(sized, 0.01 * model.table().lookup(8, 1, 8), 1e-15);
  const double paper = model.estimate<kAdbPaperRule>(cube(100), cube(1), 1.0, 1, 8);
  EXPECT_LT(paper, sized / 10);
  // Symmetric in the roles of A and B.
  for (int pa : {1, 3, 8})
    for (int pb : {1, 5, 8}) {
      EXPECT_DOUBLE_EQ(model.estimate<kAdbSizedRule>(cube(1), cube(2), 1.0, pa, pb),
                       model.estimate<kAdbSizedRule>(cube(2), cube(1), 1.0, pb, pa));
      EXPECT_DOUBLE_EQ(model.estimate<kAdbPaperRule>(cube(1), cube(2), 1.0, pa, pb),
                       model.estimate<kAdbPaperRule>(cube(2), cube(1), 1.0, pb, pa));
    }
}

// The overlap's cell count s is rounded up (less 1e-9 of slack), into [1, g^3]: the estimate then reads the
// table's layer s, interpolating between the entries around the expected counts.
TEST(AdbModel, TheOverlapsCellCountRoundsUp) {
  const AdbModel model(2, 0.5);
  const auto& table = model.table();
  for (const double overlap : {0.3, 1.5, 2.0, 2.0 + 1e-12, 2.0 + 1e-6, 2.0 - 1e-6, 5.0 - 1e-10, 7.999}) {
    // Equal full cubes of volume 8 (cells of volume 1): s_real = overlap, s_a = s_b = overlap, capped at s.
    const int s = std::clamp(static_cast<int>(std::ceil(overlap - 1e-9)), 1, 8);
    const double x = std::min(overlap, double(s));
    const int lo = static_cast<int>(x), hi = std::min(lo + 1, s);
    const double f = x - lo;
    const double expected = (1 - f) * ((1 - f) * table.lookup(s, lo, lo) + f * table.lookup(s, lo, hi)) +
                            f * ((1 - f) * table.lookup(s, hi, lo) + f * table.lookup(s, hi, hi));
    EXPECT_DOUBLE_EQ(model.estimate(cube(2), cube(2), overlap, 8, 8), expected) << "overlap " << overlap;
  }
}

TEST(AdbModel, AnEmptyCountIsZeroOnlyUnderThePapersRule) {
  const AdbModel model(2, 0.5);
  EXPECT_EQ(model.estimate<kAdbPaperRule>(cube(2), cube(2), 8.0, 0, 8), 0.0);
  EXPECT_DOUBLE_EQ(model.estimate<kAdbSizedRule>(cube(2), cube(2), 8.0, 0, 8), model.table().lookup(8, 1, 8));
  EXPECT_GT(model.estimate<kAdbSizedRule>(cube(2), cube(0.01), 1e-6, 0, 0), 0.0);
  // No overlap is still 0: the volumes are apart.
  EXPECT_EQ(model.estimate<kAdbSizedRule>(cube(2), cube(2), 0.0, 8, 8), 0.0);
}

TEST(AdbModel, NeverOutsideTheUnitIntervalOnExtremeBoxes) {
  const AdbModel model(2, 0.5);
  const Box flat{Vec3::Zero(), Vec3(1, 1, 0)};
  for (const Box& a : {cube(0), cube(1e-300), flat, cube(1), cube(1e100)})
    for (double ov : {0.0, 1e-300, 0.5, 1.0, 1e300})
      for (int pa : {0, 1, 8})
        for (int pb : {0, 1, 8}) {
          const double q = model.estimate<kAdbSizedRule>(a, cube(1), ov, pa, pb);
          EXPECT_TRUE(q >= 0 && q <= 1) << a.max.x() << " " << ov << " " << pa << " " << pb << " -> " << q;
          const double r = model.estimate<kAdbPaperRule>(a, cube(1), ov, pa, pb);
          EXPECT_TRUE(r >= 0 && r <= 1) << a.max.x() << " " << ov << " " << pa << " " << pb << " -> " << r;
        }
}

// Two unit squares in axis planes, crossing: their AABB trees have flat boxes (thickness 0), whose overlap
// volume is 0. The exact answer is "collision"; ADB must not answer it with the probability 0.
TEST(AdbTraversal, FlatBoxesThatCrossGetAPositiveProbability) {
  Mesh in_z{{Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)}, {{0, 1, 2}, {0, 2, 3}}, "in_z"};
  Mesh in_x{{Vec3(0, -1, -1), Vec3(0, 1, -1), Vec3(0, 1, 1), Vec3(0, -1, 1)}, {{0, 1, 2}, {0, 2, 3}}, "in_x"};
  const auto a = annotate_adb(Bvh<Aabb>::build(in_z), 2, 0.25);
  const auto b = annotate_adb(Bvh<Aabb>::build(in_x), 2, 0.25);
  ASSERT_TRUE(query_exact(a.bvh, b.bvh, RigidTransform::identity()).collides);
  AdbOptions options;
  options.p_min = 0.99;
  const Result r = query_adb(a, b, RigidTransform::identity(), options);
  EXPECT_GT(r.probability, 0.0);
  EXPECT_FALSE(r.exact);
}

// Boxes that only touch meet in a face of volume 0; the polygons in that face touch, which exact counts as a
// collision. ADB must not read such a pair as certainly apart: before, it dropped the root pair (overlap 0)
// and answered "no" with the probability 0. Two cubes face to face (also turned about the face's normal) and
// edge to edge, on AABB and OBB trees.
template <class BV>
void expect_touching_cubes_not_apart() {
  const auto tree = annotate_adb(Bvh<BV>::build(generators::make_box(1, 1, 1)), 2, 0.25);
  RigidTransform turned = RigidTransform::translate(Vec3(1, 0, 0));
  turned.rotation = Eigen::AngleAxisd(0.4, Vec3::UnitX()).toRotationMatrix();
  for (const RigidTransform& pose : {RigidTransform::translate(Vec3(1, 0, 0)), turned}) {
    ASSERT_TRUE(query_exact(tree.bvh, tree.bvh, pose).collides);
    const Result r = query_adb(tree, tree, pose, AdbOptions{});
    // The faces' triangles lie in one plane: their flat boxes overlap whole, so the estimate finds them.
    EXPECT_TRUE(r.collides) << BV::name() << ", p " << r.probability;
    EXPECT_FALSE(r.exact);
  }
  const RigidTransform edge = RigidTransform::translate(Vec3(1, 1, 0));
  ASSERT_TRUE(query_exact(tree.bvh, tree.bvh, edge).collides);
  const Result r = query_adb(tree, tree, edge, AdbOptions{});
  EXPECT_GT(r.probability, 0.0) << BV::name();  // an edge has no area: "no" stays possible, never certain
  EXPECT_FALSE(r.exact);
}

TEST(AdbTraversal, BoxesThatOnlyTouchAreNotReadAsApart) {
  expect_touching_cubes_not_apart<Aabb>();
  expect_touching_cubes_not_apart<Obb>();
}

// A small closed box straddling a large slanted triangle (the size pair's case: the jeep's triangles against
// the dragon). The triangle's OBB is a thin slab, its axis-aligned box a cube that holds the small box a
// thousand times over. On OBB trees the default density counts cells in each node's own frame, so a node
// the OBB test found inside the slab is likely to touch the triangle; read in the axis-aligned boxes, every
// pair looked unlikely and the collision was missed.
TEST(AdbTraversal, ASmallBoxInsideASlantedTrianglesObbIsFoundOnObbTrees) {
  const Mesh slanted{{Vec3(10, 0, 0), Vec3(0, 10, 0), Vec3(0, 0, 10)}, {{0, 1, 2}}, "slanted"};
  Mesh small = testing::make_torus(0.05, 0.02, 12, 8);
  const auto a = annotate_adb(Bvh<Obb>::build(slanted), 2, kDefaultAdbTau);
  const auto b = annotate_adb(Bvh<Obb>::build(small), 2, kDefaultAdbTau);
  const Vec3 on_plane = Vec3::Constant(10.0 / 3);
  for (const double turn : {0.0, 0.5, 1.3}) {
    RigidTransform pose;
    pose.rotation = Eigen::AngleAxisd(turn, Vec3(1, -1, 0.5).normalized()).toRotationMatrix();
    pose.translation = on_plane;
    ASSERT_TRUE(query_exact(a.bvh, b.bvh, pose).collides) << turn;
    const Result r = query_adb(a, b, pose, AdbOptions{});  // p_min 0.9
    EXPECT_TRUE(r.collides) << "turn " << turn << ": probability " << r.probability;
    EXPECT_GT(r.probability, 0.9) << turn;
    // Moved off the plane by twice its size along the normal: the OBBs are apart, an exact no.
    pose.translation = on_plane + Vec3::Constant(0.1);
    const Result apart = query_adb(a, b, pose, AdbOptions{});
    EXPECT_FALSE(apart.collides);
    EXPECT_TRUE(apart.exact);
  }
}

// On OBB trees the estimate reads the placement the OBB test computed (Obb::overlap with a PlacedBoxes):
// the root's estimate, what a query stopped after its first test reports, is the model's on the two root
// boxes placed from their own frames and the pose.
TEST(AdbTraversal, OnObbTreesTheEstimateReadsTheRootBoxesAsThePairLies) {
  const auto a = annotate_adb(Bvh<Obb>::build(testing::make_torus(0.7, 0.25, 40, 20)), 2, kDefaultAdbTau);
  const auto b = annotate_adb(Bvh<Obb>::build(testing::make_random_soup(400, 0.1, 5)), 2, kDefaultAdbTau);
  const auto estimate = AdbDensity::estimator(a.density, b.density);
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> offset(-0.6, 0.6), angle(0, 3);
  int compared = 0;
  for (int k = 0; k < 20; ++k) {
    RigidTransform pose;
    pose.rotation =
        Eigen::AngleAxisd(angle(rng), Vec3(offset(rng), 1, offset(rng)).normalized()).toRotationMatrix();
    pose.translation = Vec3(offset(rng), offset(rng), offset(rng));
    const PairGeometry g =
        node_frame_geometry(a.bvh.volume(0).oriented_box(), b.bvh.volume(0).oriented_box(), pose);
    AdbOptions options;
    options.p_min = 1;  // nothing decides: the first test's estimate is what the stopped query reports
    options.budget.max_bv_tests = 1;
    const Result r = query_adb(a, b, pose, options);
    if (!r.budget_exhausted) continue;  // the root volumes apart: an exact no
    EXPECT_NEAR(r.probability, estimate(0, g.a, 0, g.b, g.overlap), 1e-12) << "pose " << k;
    EXPECT_GT(r.probability, 0.0) << "pose " << k;
    ++compared;
  }
  EXPECT_GT(compared, 10);
}

}  // namespace
}  // namespace bvhlab
