// Four oriented boxes a test (volumes/obb4.hpp): the vector path answers as the scalar reference, lane by
// lane, and both are conservative against Obb's own test in double (itself checked against exact triangle
// tests by the conformance suite): a lane reported apart is apart there, also for pairs bisected to where the
// double test's answer flips, 1e6 from the origin with the lanes stored relative to nearby origins.
#include "support/random_draws.hpp"
#include "volumes/obb4.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace bvhlab {
namespace {

Obb random_obb(std::mt19937_64& rng, const Vec3& near, double size) {
  std::uniform_real_distribution<double> unit(-1, 1), extent(0.01, 1);
  std::vector<Vec3> points;
  const Vec3 stretch = testing::draw_vec3(extent, rng);  // an elongated cloud, so the fit has a frame
  for (int k = 0; k < 8; ++k)
    points.push_back(near + size * testing::draw_vec3(unit, rng).cwiseProduct(stretch));
  return Obb::fit(points);
}

RigidTransform random_obb_pose(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(-reach, reach);
  RigidTransform pose;
  pose.rotation = testing::draw_quaternion(normal, rng).normalized().toRotationMatrix();
  pose.translation = testing::draw_vec3(unit, rng);
  return pose;
}

TEST(Obb4, VectorPathAnswersAsTheScalarReferenceAndTheDoubleTest) {
  std::mt19937_64 rng(67);
  int overlapping = 0, total = 0;
  for (int round = 0; round < 2000; ++round) {
    std::array<Obb, 4> as, bs;
    Obb4 a, b;
    for (int k = 0; k < 4; ++k) {
      as[k] = random_obb(rng, Vec3::Zero(), 0.4), bs[k] = random_obb(rng, Vec3::Zero(), 0.4);
      if ((round + k) % 9 != 0) a.set(k, as[k]);  // some lanes stay empty
      if ((round + 2 * k) % 11 != 0) b.set(k, bs[k]);
    }
    const RigidTransform pose = random_obb_pose(rng, 0.5);
    const auto context = Obb4::make_context(pose);
    const unsigned mask = Obb4::overlap(a, b, context);
    ASSERT_EQ(mask, Obb4::overlap_scalar(a, b, context)) << "round " << round;
    const auto exact = Obb::make_context(pose);
    for (int k = 0; k < 4; ++k) {
      const bool said = (mask >> k) & 1u;
      if (a.empty(k) || b.empty(k)) {
        ASSERT_FALSE(said) << "an empty lane overlapped, round " << round;
        continue;
      }
      ASSERT_TRUE(said || !Obb::overlap(as[k], bs[k], exact)) << "lane " << k << " of round " << round;
      overlapping += said;
      ++total;
    }
  }
  EXPECT_GT(overlapping, total / 10);  // both answers occur
  EXPECT_LT(overlapping, total * 9 / 10);
}

TEST(Obb4, PairsAtTheDoubleTestsEdgeStayOverlappingFarFromTheOrigin) {
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> unit(-1, 1);
  int apart_outside = 0;
  for (int round = 0; round < 500; ++round) {
    const Vec3 far = Vec3::Constant(round % 2 ? 1e6 : 0);
    const Obb a = random_obb(rng, far, 0.3), b = random_obb(rng, far, 0.3);
    const Vec3 origin_a = far + testing::draw_vec3(unit, rng), origin_b = far + testing::draw_vec3(unit, rng);
    Obb4 la, lb;
    la.set(0, a, origin_a), lb.set(0, b, origin_b);
    RigidTransform pose = random_obb_pose(rng, 0);
    pose.translation = to_vec(a.center) - pose.rotation * to_vec(b.center);  // B's centre on A's
    const auto overlaps = [&](const RigidTransform& p) { return Obb::overlap(a, b, Obb::make_context(p)); };
    double inside = pose.translation.x(), outside = inside + 10;
    for (int i = 0; i < 200; ++i) {
      pose.translation.x() = 0.5 * (inside + outside);
      (overlaps(pose) ? inside : outside) = pose.translation.x();
    }
    pose.translation.x() = inside;
    ASSERT_TRUE(Obb4::overlap(la, lb, Obb4::make_context(pose, origin_a, origin_b)) & 1u)
        << "round " << round;
    pose.translation.x() = inside + 1e-3;
    apart_outside += (Obb4::overlap(la, lb, Obb4::make_context(pose, origin_a, origin_b)) & 1u) == 0;
  }
  EXPECT_GT(apart_outside, 480);
}

}  // namespace
}  // namespace bvhlab
