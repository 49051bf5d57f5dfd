// Proximity queries (traversal/distance.hpp) against a brute force over every triangle pair: the typed tests
// (distance_query_tests.hpp) on the box-like volumes, the brute force itself, and bad input.
#include "distance_query_tests.hpp"

namespace bvhlab::distance_tests {
namespace {

using BoxLikeVolumes = ::testing::Types<Aabb, Obb, Sphere>;
INSTANTIATE_TYPED_TEST_SUITE_P(BoxLike, DistanceQuery, BoxLikeVolumes);

// The reference skips triangle pairs whose enclosing balls are farther apart than its best distance so far:
// it must still answer as the plain minimum over every pair, near and far from the origin.
TEST(BruteForceReference, SkipsOnlyPairsThatCannotHoldTheNearest) {
  const Mesh a = testing::make_torus(0.7, 0.25, 8, 4);
  const Mesh b = testing::make_random_soup(40, 0.15, 5);
  const auto every_pair = [](const Mesh& m, const Mesh& n, const RigidTransform& pose) {
    double best = kInf;
    for (std::uint32_t i = 0; i < m.triangles.size(); ++i)
      for (std::uint32_t j = 0; j < n.triangles.size(); ++j) {
        const TrianglePoints t = n.triangle(j);
        best = std::min(
            best, triangle_distance(m.triangle(i), {pose.apply(t[0]), pose.apply(t[1]), pose.apply(t[2])})
                      .distance);
      }
    return best;
  };
  const Vec3 far(1e6, -1e6, 1e6);
  Mesh a_far = a, b_far = b;
  for (Vec3& v : a_far.vertices) v += far;
  for (Vec3& v : b_far.vertices) v += far;
  std::mt19937_64 rng(23);
  int apart = 0;
  for (int k = 0; k < 16; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 0.5 + 0.25 * k);
    const double expected = every_pair(a, b, pose);
    ASSERT_EQ(brute_force_distance(a, b, pose), expected) << "pose " << k;
    RigidTransform far_pose = pose;
    far_pose.translation = pose.translation + far - pose.rotation * far;
    ASSERT_EQ(brute_force_distance(a_far, b_far, far_pose), every_pair(a_far, b_far, far_pose))
        << "pose " << k;
    apart += expected > 0;
  }
  EXPECT_GT(apart, 4);
  EXPECT_LT(apart, 16);
}

TEST(DistanceQueryInput, ACoherentStateServesOnePairOfTrees) {
  const Mesh m = testing::make_torus(0.7, 0.25, 12, 6);
  const auto tree = Bvh<Aabb>::build(m);
  const auto other = Bvh<Aabb>::build(m);
  const RigidTransform pose = translated(RigidTransform{}, Vec3(3, 0, 0));
  CoherentState state;
  (void)query_distance_coherent(tree, tree, pose, state);
  EXPECT_THROW(query_distance_coherent(tree, other, pose, state), std::invalid_argument);
  EXPECT_THROW(query_within_coherent(other, tree, pose, 0.5, state), std::invalid_argument);
}

TEST(DistanceQueryInput, RefusesNonsenseBeforeWork) {
  const Mesh m = testing::make_torus(0.7, 0.25, 12, 6);
  const auto tree = Bvh<Aabb>::build(m);
  const RigidTransform pose = translated(RigidTransform{}, Vec3(3, 0, 0));
  for (double eps : {-1.0, std::nan(""), kInf})
    EXPECT_THROW(query_within(tree, tree, pose, eps), std::invalid_argument) << eps;
  EXPECT_THROW(query_distance_anytime(tree, tree, pose, Budget{}), std::invalid_argument);
  EXPECT_THROW(query_distance_anytime(tree, tree, pose, Budget{0, std::nan("")}), std::invalid_argument);
  EXPECT_THROW(query_distance_anytime(tree, tree, pose, Budget{0, -5}), std::invalid_argument);
  RigidTransform sheared = pose;
  sheared.rotation(0, 1) = 0.3;
  EXPECT_THROW(query_distance(tree, tree, sheared), std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab::distance_tests
