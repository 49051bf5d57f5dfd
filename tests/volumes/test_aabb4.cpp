// Four boxes a test (volumes/aabb4.hpp): the vector path answers as the scalar reference, lane by lane, and
// both are conservative: a lane reported apart is apart in exact arithmetic, also for pairs bisected to
// touching within rounding and far from the origin.
#include "support/generated_meshes.hpp"
#include "support/random_draws.hpp"
#include "volumes/aabb4.hpp"

#include <gtest/gtest.h>

#include <random>

namespace bvhlab {
namespace {

// The gap of B's box placed in A's frame on A's axes, in long double from the lanes' own float boxes and
// the double pose (the lane test rounds R and t to float): > 0 on some axis means the boxes are apart.
bool apart_exactly(const Aabb4& a, const Aabb4& b, int k, const RigidTransform& pose) {
  const long double bc[3] = {b.cx[k], b.cy[k], b.cz[k]}, bh[3] = {b.hx[k], b.hy[k], b.hz[k]};
  const long double ac[3] = {a.cx[k], a.cy[k], a.cz[k]}, ah[3] = {a.hx[k], a.hy[k], a.hz[k]};
  for (int r = 0; r < 3; ++r) {
    long double center = pose.translation(r), half = 0;
    for (int j = 0; j < 3; ++j) {
      center += static_cast<long double>(pose.rotation(r, j)) * bc[j];
      half += std::abs(static_cast<long double>(pose.rotation(r, j))) * bh[j];
    }
    if (std::abs(center - ac[r]) - ah[r] - half > 0) return true;
  }
  return false;
}

Aabb random_box(std::mt19937_64& rng, double offset, double size) {
  std::uniform_real_distribution<double> unit(-1, 1), extent(0.01, 1);
  const Vec3 c = Vec3::Constant(offset) + testing::draw_vec3(unit, rng);
  const Vec3 h = size * testing::draw_vec3(extent, rng);
  return Aabb::from_box({c - h, c + h});
}

// B's box placed on A's (centres together), then moved along A's x axis until the placed boxes just touch
// (bisected in exact arithmetic), then `beyond` further out: a pair at the edge of the test's slack.
RigidTransform touching_pose(const Aabb& a, const Aabb& b, RigidTransform pose, double beyond) {
  Aabb4 la, lb;
  la.set(0, a), lb.set(0, b);
  const Vec3 center_a = (to_vec(a.lo) + to_vec(a.hi)) / 2, center_b = (to_vec(b.lo) + to_vec(b.hi)) / 2;
  pose.translation = center_a - pose.rotation * center_b;
  double inside = pose.translation.x(), outside = inside + 100;
  for (int i = 0; i < 200; ++i) {
    pose.translation.x() = 0.5 * (inside + outside);
    (apart_exactly(la, lb, 0, pose) ? outside : inside) = pose.translation.x();
  }
  pose.translation.x() = inside + beyond;
  return pose;
}

class Aabb4Test : public ::testing::TestWithParam<double> {};  // the boxes' distance from the origin

TEST_P(Aabb4Test, VectorPathAnswersAsTheScalarReference) {
  std::mt19937_64 rng(41);
  int overlapping = 0, total = 0;
  for (int round = 0; round < 2000; ++round) {
    Aabb4 a, b;
    for (int k = 0; k < 4; ++k) a.set(k, random_box(rng, GetParam(), 0.6)), b.set(k, random_box(rng, 0, 0.6));
    if (round % 7 == 0) a.clear(round % 4);
    if (round % 5 == 0) b.clear((round + 1) % 4);
    RigidTransform pose = testing::random_pose(rng, 1.2);  // B's boxes brought near A's
    pose.translation += Vec3::Constant(GetParam());
    const auto context = Aabb4::make_context(pose);
    const unsigned mask = Aabb4::overlap(a, b, context);
    ASSERT_EQ(mask, Aabb4::overlap_scalar(a, b, context)) << "round " << round;
    for (int k = 0; k < 4; ++k) {
      const bool said = (mask >> k) & 1u;
      if (a.empty(k) || b.empty(k)) {
        ASSERT_FALSE(said) << "an empty lane overlapped, round " << round;
        continue;
      }
      ASSERT_TRUE(said || apart_exactly(a, b, k, pose)) << "lane " << k << " of round " << round;
      overlapping += said;
      ++total;
    }
  }
  // Both answers occur. Not at 1e6: the slack grows with the coordinates (there it is several units, and
  // every pair overlaps), which is why wide trees store their lanes relative to their root box's centre.
  EXPECT_GT(overlapping, total / 10);
  if (std::abs(GetParam()) <= 1e3) {
    EXPECT_LT(overlapping, total * 9 / 10);
  }
}

TEST_P(Aabb4Test, TouchingPairsStayOverlapping) {
  std::mt19937_64 rng(43);
  int said_apart_just_outside = 0;
  for (int round = 0; round < 500; ++round) {
    const Aabb a = random_box(rng, GetParam(), 0.5), b = random_box(rng, 0, 0.5);
    const RigidTransform start = testing::random_pose(rng, 0);
    Aabb4 la, lb;
    la.set(0, a), lb.set(0, b);
    // Just inside (touching to rounding): the lane test must say overlap.
    const RigidTransform inside = touching_pose(a, b, start, 0);
    ASSERT_FALSE(apart_exactly(la, lb, 0, inside));
    ASSERT_TRUE(Aabb4::overlap(la, lb, Aabb4::make_context(inside)) & 1u) << "round " << round;
    // A thousandth of the coordinates' scale outside: apart, or the slack is far too wide.
    const RigidTransform outside = touching_pose(a, b, start, 1e-3 * (1 + std::abs(GetParam())));
    said_apart_just_outside += (Aabb4::overlap(la, lb, Aabb4::make_context(outside)) & 1u) == 0;
  }
  EXPECT_GT(said_apart_just_outside, 450);
}

INSTANTIATE_TEST_SUITE_P(Offsets, Aabb4Test, ::testing::Values(0.0, 1e3, -1e6));

TEST(Aabb4, LanesContainTheirBoxes) {
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int round = 0; round < 3000; ++round) {
    const double offset = round % 3 == 0 ? 0 : round % 3 == 1 ? 1e5 : -3e6;
    const Aabb box = random_box(rng, offset, round % 2 ? 0.3 : 1e-4);
    const Vec3 origin =
        round % 5 == 0 ? Vec3::Zero() : Vec3(Vec3::Constant(offset) + testing::draw_vec3(unit, rng));
    Aabb4 lanes;
    const int k = round % 4;
    lanes.set(k, box, origin);
    const double c[3] = {lanes.cx[k], lanes.cy[k], lanes.cz[k]},
                 h[3] = {lanes.hx[k], lanes.hy[k], lanes.hz[k]};
    for (int r = 0; r < 3; ++r) {  // in long double: the lane's box around the stored one, both less origin
      ASSERT_LE((long double)c[r] - h[r], (long double)box.lo[r] - origin[r]) << round;
      ASSERT_GE((long double)c[r] + h[r], (long double)box.hi[r] - origin[r]) << round;
      ASSERT_GE(double(lanes.mag[k]), std::abs(c[r]) + h[r]);
    }
  }
}

}  // namespace
}  // namespace bvhlab
