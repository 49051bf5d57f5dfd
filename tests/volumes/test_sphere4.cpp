// Four spheres a test (volumes/sphere4.hpp): the vector path answers as the scalar reference, lane by lane,
// and both are conservative against Sphere's own test in double: a lane reported apart is apart there,
// also for pairs bisected to where the double test's answer flips, 1e6 from the origin with the lanes
// stored relative to nearby origins.
#include "support/random_draws.hpp"
#include "volumes/sphere4.hpp"

#include <gtest/gtest.h>

#include <random>

namespace bvhlab {
namespace {

Sphere random_sphere(std::mt19937_64& rng, const Vec3& near, double size) {
  std::uniform_real_distribution<double> unit(-1, 1), extent(0.01, 1);
  const std::array<Vec3, 2> points{near + testing::draw_vec3(unit, rng),
                                   near + testing::draw_vec3(unit, rng) * size * extent(rng)};
  return Sphere::fit(points);
}

RigidTransform random_sphere_pose(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(-reach, reach);
  RigidTransform pose;
  pose.rotation = testing::draw_quaternion(normal, rng).normalized().toRotationMatrix();
  pose.translation = testing::draw_vec3(unit, rng);
  return pose;
}

TEST(Sphere4, VectorPathAnswersAsTheScalarReferenceAndTheDoubleTest) {
  std::mt19937_64 rng(67);
  int overlapping = 0, total = 0;
  for (int round = 0; round < 2000; ++round) {
    std::array<Sphere, 4> as, bs;
    Sphere4 a, b;
    for (int k = 0; k < 4; ++k) {
      as[k] = random_sphere(rng, Vec3::Zero(), 0.4), bs[k] = random_sphere(rng, Vec3::Zero(), 0.4);
      if ((round + k) % 9 != 0) a.set(k, as[k]);  // some lanes stay empty
      if ((round + 2 * k) % 11 != 0) b.set(k, bs[k]);
    }
    const RigidTransform pose = random_sphere_pose(rng, 1.2);
    const auto context = Sphere4::make_context(pose);
    const unsigned mask = Sphere4::overlap(a, b, context);
    ASSERT_EQ(mask, Sphere4::overlap_scalar(a, b, context)) << "round " << round;
    const auto exact = Sphere::make_context(pose);
    for (int k = 0; k < 4; ++k) {
      const bool said = (mask >> k) & 1u;
      if (a.empty(k) || b.empty(k)) {
        ASSERT_FALSE(said) << "an empty lane overlapped, round " << round;
        continue;
      }
      ASSERT_TRUE(said || !Sphere::overlap(as[k], bs[k], exact)) << "lane " << k << " of round " << round;
      overlapping += said;
      ++total;
    }
  }
  EXPECT_GT(overlapping, total / 10);  // both answers occur
  EXPECT_LT(overlapping, total * 9 / 10);
}

TEST(Sphere4, PairsAtTheDoubleTestsEdgeStayOverlappingFarFromTheOrigin) {
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> unit(-1, 1);
  int apart_outside = 0;
  for (int round = 0; round < 500; ++round) {
    const Vec3 far = Vec3::Constant(round % 2 ? 1e6 : 0);
    const Sphere a = random_sphere(rng, far, 0.3), b = random_sphere(rng, far, 0.3);
    const Vec3 origin_a = far + testing::draw_vec3(unit, rng), origin_b = far + testing::draw_vec3(unit, rng);
    Sphere4 la, lb;
    la.set(0, a, origin_a), lb.set(0, b, origin_b);
    RigidTransform pose = random_sphere_pose(rng, 0);
    pose.translation = to_vec(a.center) - pose.rotation * to_vec(b.center);  // B's centre on A's
    const auto overlaps = [&](const RigidTransform& p) {
      return Sphere::overlap(a, b, Sphere::make_context(p));
    };
    double inside = pose.translation.x(), outside = inside + 10;
    for (int i = 0; i < 200; ++i) {
      pose.translation.x() = 0.5 * (inside + outside);
      (overlaps(pose) ? inside : outside) = pose.translation.x();
    }
    pose.translation.x() = inside;
    ASSERT_TRUE(Sphere4::overlap(la, lb, Sphere4::make_context(pose, origin_a, origin_b)) & 1u)
        << "round " << round;
    pose.translation.x() = inside + 1e-3;
    apart_outside += (Sphere4::overlap(la, lb, Sphere4::make_context(pose, origin_a, origin_b)) & 1u) == 0;
  }
  EXPECT_GT(apart_outside, 480);
}

TEST(Sphere4, LanesContainTheirSpheres) {
  std::mt19937_64 rng(73);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int round = 0; round < 1000; ++round) {
    const Vec3 far = Vec3::Constant(round % 3 == 0 ? 0 : round % 3 == 1 ? 1e5 : -3e6);
    const Sphere sphere = random_sphere(rng, far, round % 2 ? 0.3 : 1e-4);
    const Vec3 origin = far + testing::draw_vec3(unit, rng);
    Sphere4 lanes;
    const int k = round % 4;
    lanes.set(k, sphere, origin);
    // The lane's sphere holds the stored one: |c_lane - (c - origin)| + r <= r_lane, in long double.
    long double moved = 0;
    const float c[3] = {lanes.cx[k], lanes.cy[k], lanes.cz[k]};
    for (int r = 0; r < 3; ++r) {
      const long double d = (long double)c[r] - ((long double)sphere.center[r] - origin[r]);
      moved += d * d;
    }
    ASSERT_LE(std::sqrt(moved) + sphere.radius, (long double)lanes.radius[k]) << round;
  }
}

}  // namespace
}  // namespace bvhlab
