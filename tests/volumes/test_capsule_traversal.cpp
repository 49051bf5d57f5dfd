// The test-only capsule through the real pipeline: Bvh<Capsule> built by the library builder and queried by
// the library's exact traversal must give the same first-contact answers as Bvh<Aabb>.
#include "bvh/triangle_intersection.hpp"
#include "support/generated_meshes.hpp"
#include "support/test_volumes.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

namespace bvhlab {
namespace {

TEST(CapsuleTree, ExactFirstContactAgreesWithAabbTree) {
  const Mesh a = testing::make_torus(0.7, 0.25, 24, 12);
  const Mesh b = testing::make_random_soup(300, 0.1, 7);
  const auto capsule_a = Bvh<testing::Capsule>::build(a), capsule_b = Bvh<testing::Capsule>::build(b);
  const auto aabb_a = Bvh<Aabb>::build(a), aabb_b = Bvh<Aabb>::build(b);
  std::mt19937_64 rng(59);
  int colliding = 0;
  for (int k = 0; k < 200; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    const Result with_capsules = query_exact(capsule_a, capsule_b, pose);
    const Result with_boxes = query_exact(aabb_a, aabb_b, pose);
    ASSERT_EQ(with_capsules.collides, with_boxes.collides) << "pose " << k;
    if (!with_capsules.collides) continue;
    ++colliding;
    ASSERT_TRUE(with_capsules.witness.has_value());
    const auto ta = a.triangle(with_capsules.witness->a), tb = b.triangle(with_capsules.witness->b);
    EXPECT_TRUE(triangles_intersect_exact(ta, {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])}));
  }
  // Both answers must occur, or agreement proves little.
  EXPECT_GT(colliding, 20);
  EXPECT_LT(colliding, 180);
}

}  // namespace
}  // namespace bvhlab
