// The exact query on wide trees (traversal/wide_exact.hpp), of boxes, spheres, oriented boxes, k-DOPs and
// restricted boxes, against CGAL's exact predicates and against the binary query it stands in for, on
// generated meshes.
#include "bench/core/ground_truth.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/wide_exact.hpp"
#include "volumes/dop24.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace bvhlab {
namespace {

template <class Lanes>
struct WidePair {
  using BV = typename Lanes::Volume;
  Bvh<BV> a, b;
  WideBvh<Lanes> wide_a, wide_b;
  WidePair(const Mesh& mesh_a, const Mesh& mesh_b, const BuildOptions& options = {})
      : a(Bvh<BV>::build(mesh_a, options)),
        b(Bvh<BV>::build(mesh_b, options)),
        wide_a(WideBvh<Lanes>::build(a)),
        wide_b(WideBvh<Lanes>::build(b)) {}
  Result query(const RigidTransform& pose, ContactMode mode = ContactMode::First) const {
    return query_exact_wide(a, wide_a, b, wide_b, pose, mode);
  }
};

// Every kind of four-lane layout: boxes, spheres, oriented boxes, restricted boxes, and the k-DOPs through
// the 24-DOP (the k-DOPs share one template over their direction tables, which tests/volumes/test_lanes.cpp
// checks one by one; the protocol test runs the wide trees of every direction set).
using LaneTypes = ::testing::Types<Aabb4, Sphere4, Obb4, KDop4<dop_sets::Zachmann24>, RestrictedBox4>;
template <class Lanes>
class WideExact : public ::testing::Test {};
TYPED_TEST_SUITE(WideExact, LaneTypes);

TYPED_TEST(WideExact, FirstContactMatchesCgalOnRandomPoses) {
  const Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  const Mesh b = testing::make_random_soup(600, 0.08, 11);
  const WidePair<TypeParam> trees(a, b);
  const CgalGroundTruth truth(a, b);
  std::mt19937_64 rng(5);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result r = trees.query(pose);
    ASSERT_EQ(r.collides, truth.collides(pose)) << "pose " << k;
    ASSERT_TRUE(r.exact);
    if (!r.collides) continue;
    ++colliding;
    ASSERT_TRUE(r.witness.has_value());
    const auto ta = a.triangle(r.witness->a), tb = b.triangle(r.witness->b);
    ASSERT_TRUE(triangles_intersect_exact(ta, {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])}));
  }
  EXPECT_GT(colliding, 30);
  EXPECT_LT(colliding, 270);
}

TYPED_TEST(WideExact, AllContactsEqualCgalEnumeration) {
  const Mesh a = testing::make_torus(0.7, 0.25, 24, 12);
  const Mesh b = testing::make_torus(0.6, 0.2, 20, 10);
  const CgalGroundTruth truth(a, b);
  // One triangle a leaf (leaf pairs' plane tests four at once) and up to three (one pair at a time).
  for (const std::uint32_t leaf_triangles : {1u, 3u}) {
    BuildOptions options;
    options.max_leaf_triangles = leaf_triangles;
    const WidePair<TypeParam> trees(a, b, options);
    std::mt19937_64 rng(9);
    std::size_t total = 0;
    for (int k = 0; k < 40; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 0.8);
      Result r = trees.query(pose, ContactMode::All);
      std::sort(r.contacts.begin(), r.contacts.end());
      const auto expected = truth.all_contacts(pose);
      ASSERT_EQ(r.contacts, expected) << "pose " << k << ", " << leaf_triangles << " triangles a leaf";
      EXPECT_EQ(r.collides, !expected.empty());
      total += expected.size();
    }
    EXPECT_GT(total, 100u);
  }
}

// The wide walk takes fewer pairs off its stack than the binary one (a step settles four children) for about
// as many box tests.
TYPED_TEST(WideExact, VisitsFewerPairsThanTheBinaryWalk) {
  const Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  const WidePair<TypeParam> trees(a, a);
  std::mt19937_64 rng(17);
  Counters wide, binary;
  for (int k = 0; k < 200; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.0);
    const Result w = trees.query(pose);
    const Result s = query_exact(trees.a, trees.b, pose);
    ASSERT_EQ(w.collides, s.collides) << "pose " << k;
    wide += w.counters;
    binary += s.counters;
  }
  // Measured: 0.62 of the binary walk's pairs, 1.11 of its BV tests (empty lanes included).
  EXPECT_LT(double(wide.nodes_visited), 0.75 * double(binary.nodes_visited));
  EXPECT_LT(double(wide.bv_tests), 1.3 * double(binary.bv_tests));
}

// Far from the origin (1e6 in every coordinate) the lanes are stored relative to the root box's centre, so
// the float test prunes as well as it does at the origin: against the binary walk on the same trees, about
// the same ratio of BV tests as at the origin (in float about the origin the slack alone would be several
// units there, and every box would overlap). Both walks do more work there than at the origin: the binary
// tree's float boxes are rounded outwards by 1/16 at 1e6.
TYPED_TEST(WideExact, FarFromTheOriginKeepsItsPruning) {
  Mesh near_mesh = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh far_mesh = near_mesh;
  const Vec3 far = Vec3::Constant(1e6);
  for (Vec3& v : far_mesh.vertices) v += far;
  const WidePair<TypeParam> near_trees(near_mesh, near_mesh), far_trees(far_mesh, far_mesh);
  std::mt19937_64 rng(23);
  Counters near_work, far_work, near_binary, far_binary;
  for (int k = 0; k < 100; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.0);
    // The same relative placement of the far copies: x -> R (x - far) + far + t.
    RigidTransform far_pose = pose;
    far_pose.translation = pose.translation + far - pose.rotation * far;
    const Result n = near_trees.query(pose), f = far_trees.query(far_pose);
    const Result n_binary = query_exact(near_trees.a, near_trees.b, pose);
    const Result f_binary = query_exact(far_trees.a, far_trees.b, far_pose);
    ASSERT_EQ(f.collides, f_binary.collides) << "pose " << k;
    near_work += n.counters, far_work += f.counters;
    near_binary += n_binary.counters, far_binary += f_binary.counters;
  }
  const double near_ratio = double(near_work.bv_tests) / double(near_binary.bv_tests);
  const double far_ratio = double(far_work.bv_tests) / double(far_binary.bv_tests);
  EXPECT_LT(far_ratio, 1.2 * near_ratio) << near_ratio;
}

TYPED_TEST(WideExact, EmptyAndSingleLeafTrees) {
  const Mesh one = testing::make_random_soup(1, 0.3, 3);
  const WidePair<TypeParam> trees(one, one);
  EXPECT_TRUE(trees.query(RigidTransform::identity()).collides);
  EXPECT_FALSE(trees.query(RigidTransform::translate({2, 0, 0})).collides);
  EXPECT_THROW(WideBvh<TypeParam>::build(Bvh<typename TypeParam::Volume>{}), std::invalid_argument);
}

TYPED_TEST(WideExact, RefusesWideTreesOfOtherOrRefittedTreesAndNonRigidPoses) {
  const Mesh a = testing::make_torus(0.7, 0.25, 12, 8);
  const WidePair<TypeParam> trees(a, a);
  const auto other = Bvh<typename TypeParam::Volume>::build(a);
  const auto expect_message = [](const auto& call, const std::string& part) {
    try {
      call();
      ADD_FAILURE() << "no error; expected one naming " << part;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  const RigidTransform pose = RigidTransform::identity();
  expect_message([&] { query_exact_wide(other, trees.wide_a, trees.b, trees.wide_b, pose); }, "tree A");
  expect_message([&] { query_exact_wide(trees.a, trees.wide_a, other, trees.wide_b, pose); }, "tree B");
  RigidTransform scaled;
  scaled.rotation *= 2;
  expect_message([&] { trees.query(scaled); }, "rotation");
  // A refit moves the binary tree's volumes: the wide tree built before it is refused, not used.
  Mesh moved = a;
  for (Vec3& v : moved.vertices) v *= 1.5;
  auto refitted = Bvh<typename TypeParam::Volume>::build(a);
  const auto wide = WideBvh<TypeParam>::build(refitted);
  refitted.refit(moved);
  expect_message([&] { query_exact_wide(refitted, wide, refitted, wide, pose); }, "refitted");
  const auto rebuilt = WideBvh<TypeParam>::build(refitted);
  EXPECT_TRUE(query_exact_wide(refitted, rebuilt, refitted, rebuilt, pose).collides);
}

}  // namespace
}  // namespace bvhlab
