// Exact traversal against CGAL's exact predicates, on generated meshes.
#include "bench/core/ground_truth.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace bvhlab {
namespace {

TEST(ExactTraversal, FirstContactMatchesCgalOnRandomPoses) {
  const Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  const Mesh b = testing::make_random_soup(600, 0.08, 11);
  const auto tree_a = Bvh<Aabb>::build(a);
  const auto tree_b = Bvh<Aabb>::build(b);
  const CgalGroundTruth truth(a, b);
  std::mt19937_64 rng(5);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result r = query_exact(tree_a, tree_b, pose);
    ASSERT_EQ(r.collides, truth.collides(pose)) << "pose " << k;
    if (r.collides) {
      ++colliding;
      ASSERT_TRUE(r.witness.has_value());
      const auto ta = a.triangle(r.witness->a), tb = b.triangle(r.witness->b);
      ASSERT_TRUE(triangles_intersect_exact(ta, {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])}));
    }
  }
  // The pose mix must exercise both answers, or the comparison proves little.
  EXPECT_GT(colliding, 30);
  EXPECT_LT(colliding, 270);
}

TEST(ExactTraversal, AllContactsEqualCgalEnumeration) {
  const Mesh a = testing::make_torus(0.7, 0.25, 24, 12);
  const Mesh b = testing::make_torus(0.6, 0.2, 20, 10);
  BuildOptions three_per_leaf;
  three_per_leaf.max_leaf_triangles = 3;
  const auto tree_a = Bvh<Aabb>::build(a, three_per_leaf);
  const auto tree_b = Bvh<Aabb>::build(b);
  const CgalGroundTruth truth(a, b);
  std::mt19937_64 rng(9);
  std::size_t total = 0;
  for (int k = 0; k < 40; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 0.8);
    Result r = query_exact(tree_a, tree_b, pose, ContactMode::All);
    std::sort(r.contacts.begin(), r.contacts.end());
    const auto expected = truth.all_contacts(pose);
    ASSERT_EQ(r.contacts, expected) << "pose " << k;
    EXPECT_EQ(r.collides, !expected.empty());
    total += expected.size();
  }
  EXPECT_GT(total, 100u);
}

TEST(ExactTraversal, DisjointAndIdenticalPlacements) {
  const Mesh a = testing::make_torus(0.7, 0.25, 16, 8);
  const auto tree = Bvh<Aabb>::build(a);
  EXPECT_FALSE(query_exact(tree, tree, RigidTransform::translate(Vec3(5, 0, 0))).collides);
  const Result same = query_exact(tree, tree, RigidTransform::identity());
  EXPECT_TRUE(same.collides);
  EXPECT_TRUE(same.exact);
  EXPECT_EQ(same.probability, 1.0);
}

TEST(ExactTraversal, DeepChainTreeDoesNotOverflow) {
  // Triangles strung along a line with identical centroids produce no useful split; the explicit stack
  // and the builder's fallback must cope without recursion.
  Mesh m;
  for (int i = 0; i < 20000; ++i) {
    const auto b = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.emplace_back(i * 1e-3, 0, 0);
    m.vertices.emplace_back(i * 1e-3 + 1e-3, 0, 0);
    m.vertices.emplace_back(i * 1e-3, 1e-3, 0);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  const auto tree = Bvh<Aabb>::build(m);
  EXPECT_LT(tree.stats().depth, 64u);
  EXPECT_TRUE(query_exact(tree, tree, RigidTransform::translate(Vec3(5e-4, 0, 0))).collides);
}

}  // namespace
}  // namespace bvhlab

#include "volumes/restricted_box.hpp"

namespace bvhlab {
namespace {

TEST(ExactTraversal, RestrictedBoxtreeMatchesCgalAndStaysCompact) {
  const Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  const Mesh b = testing::make_random_soup(600, 0.08, 13);
  const auto rbox_a = Bvh<RestrictedBox>::build(a);
  const auto rbox_b = Bvh<RestrictedBox>::build(b);
  const CgalGroundTruth truth(a, b);
  std::mt19937_64 rng(29);
  int colliding = 0;
  for (int k = 0; k < 300; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const bool expected = truth.collides(pose);
    ASSERT_EQ(query_exact(rbox_a, rbox_b, pose).collides, expected) << "pose " << k;
    colliding += expected;
  }
  EXPECT_GT(colliding, 30);
  // 12 bytes of volume a node against the AABB's 24.
  EXPECT_LT(rbox_a.stats().bytes_per_node, Bvh<Aabb>::build(a).stats().bytes_per_node);
  // Every decoded child box lies inside its parent's and contains its triangles.
  const auto boxes = rbox_a.node_boxes();
  const auto ranges = node_triangle_ranges(rbox_a.nodes());
  for (std::uint32_t i = 0; i < rbox_a.nodes().size(); ++i) {
    for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t)
      for (const auto& v : rbox_a.triangles()[t]) ASSERT_TRUE(boxes[i].contains(v)) << "node " << i;
    if (!rbox_a.node(i).is_leaf())
      for (std::uint32_t c : {rbox_a.node(i).left(), rbox_a.node(i).right()}) {
        ASSERT_TRUE(boxes[i].contains(boxes[c].min));
        ASSERT_TRUE(boxes[i].contains(boxes[c].max));
      }
  }
}

}  // namespace
}  // namespace bvhlab
