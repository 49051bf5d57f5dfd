// The distance query on wide trees (traversal/wide_distance.hpp), on oriented boxes (the layout with a
// four-lane distance bound): the brute force's distance over every triangle pair, the same distance as the
// binary query bit for bit, its points on the named triangles, 1e6 from the origin too, and the refusals.
#include "support/brute_force_distance.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/wide_distance.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

namespace bvhlab {
namespace {

using testing::brute_force_distance;

struct WideObbTrees {
  Bvh<Obb> a, b;
  WideBvh<Obb4> wide_a, wide_b;
  WideObbTrees(const Mesh& mesh_a, const Mesh& mesh_b, const BuildOptions& options = {})
      : a(Bvh<Obb>::build(mesh_a, options)),
        b(Bvh<Obb>::build(mesh_b, options)),
        wide_a(WideBvh<Obb4>::build(a)),
        wide_b(WideBvh<Obb4>::build(b)) {}
  [[nodiscard]] DistanceResult query(const RigidTransform& pose) const {
    return query_distance_wide(a, wide_a, b, wide_b, pose);
  }
};

double off_triangle(const Vec3& p, const TrianglePoints& t) {
  return triangle_distance({p, p, p}, t).distance;
}

static_assert(HasWideDistance<Obb> && !HasWideDistance<Aabb> && !HasWideDistance<Rss>);

TEST(WideDistance, FindsTheBruteForceDistanceAndTheBinaryQuerysOne) {
  const Mesh a = testing::make_torus(0.7, 0.25, 16, 8);
  const Mesh b = testing::make_random_soup(150, 0.15, 3);
  // One triangle a leaf and up to four.
  for (const std::uint32_t leaf_triangles : {1u, 4u}) {
    BuildOptions options;
    options.max_leaf_triangles = leaf_triangles;
    const WideObbTrees trees(a, b, options);
    std::mt19937_64 rng(38);
    int touching = 0, apart = 0;
    for (int k = 0; k < 40; ++k) {
      const RigidTransform pose = testing::random_pose(rng, 0.5 + 0.15 * k);
      const DistanceResult r = trees.query(pose);
      ASSERT_EQ(r.distance, brute_force_distance(a, b, pose)) << "pose " << k;
      ASSERT_EQ(r.distance, query_distance(trees.a, trees.b, pose).distance) << "pose " << k;
      ASSERT_TRUE(r.exact);
      ASSERT_EQ(r.lower_bound, r.distance);
      ASSERT_TRUE(r.triangles.has_value());
      const TrianglePoints tb = b.triangle(r.triangles->b);
      EXPECT_LT(off_triangle(r.on_a, a.triangle(r.triangles->a)), 1e-12);
      EXPECT_LT(off_triangle(r.on_b, {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])}), 1e-12);
      EXPECT_NEAR((r.on_a - r.on_b).norm(), r.distance, 1e-12);
      (r.distance == 0 ? touching : apart) += 1;
    }
    EXPECT_GT(touching, 3);
    EXPECT_GT(apart, 10);
  }
}

TEST(WideDistance, PrunesMostPairsWhenApart) {
  const Mesh a = testing::make_torus(0.7, 0.25, 24, 12);
  const Mesh b = testing::make_random_soup(300, 0.1, 5);
  const WideObbTrees trees(a, b);
  const RigidTransform pose{Mat3::Identity(), Vec3(3, 0.2, 0)};
  const DistanceResult r = trees.query(pose);
  ASSERT_EQ(r.distance, brute_force_distance(a, b, pose));
  EXPECT_LT(r.counters.triangle_tests, a.triangles.size() * b.triangles.size() / 100);
}

TEST(WideDistance, KeepsItsPrecisionFarFromTheOrigin) {
  const Vec3 far(1e6, -1e6, 1e6);
  Mesh a = testing::make_torus(0.7, 0.25, 12, 6), b = testing::make_random_soup(100, 0.15, 3);
  for (Vec3& v : a.vertices) v += far;
  for (Vec3& v : b.vertices) v += far;
  const WideObbTrees trees(a, b);
  std::mt19937_64 rng(4);
  for (int k = 0; k < 6; ++k) {
    RigidTransform pose = testing::random_pose(rng, 0.1);
    pose.translation += Vec3(1.5 + 0.2 * k, 0, 0);
    pose.translation += far - pose.rotation * far;  // conjugated: B's frame lies at `far` too
    ASSERT_EQ(trees.query(pose).distance, brute_force_distance(a, b, pose)) << "pose " << k;
  }
}

TEST(WideDistance, RefusesWideTreesOfOtherOrRefittedTreesAndNonRigidPoses) {
  const Mesh a = testing::make_torus(0.7, 0.25, 12, 6), b = testing::make_random_soup(60, 0.15, 3);
  WideObbTrees trees(a, b);
  const WideObbTrees others(b, a);
  EXPECT_THROW((void)query_distance_wide(trees.a, others.wide_a, trees.b, trees.wide_b, RigidTransform{}),
               std::invalid_argument);
  RigidTransform sheared;
  sheared.rotation(0, 1) = 0.5;
  EXPECT_THROW((void)trees.query(sheared), std::invalid_argument);
  try {
    (void)query_distance_wide(trees.a, trees.wide_a, trees.b, others.wide_b, RigidTransform{});
    FAIL() << "a wide tree of another binary tree was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "wide distance query: wide tree B was not built from binary tree B");
  }
}

}  // namespace
}  // namespace bvhlab
