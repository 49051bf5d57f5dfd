// Four k-DOPs a test (volumes/kdop4.hpp), for every direction set: the vector path answers as the scalar
// reference, lane by lane, and both are conservative against KDop's own test in double (itself checked
// against exact triangle tests by the conformance suite): a lane reported apart is apart in double, also
// for pairs bisected to where the double test's answer flips, and with the lanes stored relative to origins
// 1e6 away.
#include "support/random_draws.hpp"
#include "volumes/dop24.hpp"
#include "volumes/kdop4.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace bvhlab {
namespace {

template <class Lanes>
class KDop4Test : public ::testing::Test {};
using DopLanes = ::testing::Types<KDop4<dop_sets::Dop6>, KDop4<dop_sets::Dop14>, KDop4<dop_sets::Dop18>,
                                  KDop4<dop_sets::Zachmann24>, KDop4<dop_sets::Dop26>>;
TYPED_TEST_SUITE(KDop4Test, DopLanes);

// A DOP around a few random points near `center`.
template <class Dop>
Dop random_dop(std::mt19937_64& rng, const Vec3& center, double size) {
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<Vec3> points;
  for (int k = 0; k < 6; ++k) points.push_back(center + size * testing::draw_vec3(unit, rng));
  return Dop::fit(points);
}

RigidTransform random_dop_pose(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(-reach, reach);
  RigidTransform pose;
  pose.rotation = testing::draw_quaternion(normal, rng).normalized().toRotationMatrix();
  pose.translation = testing::draw_vec3(unit, rng);
  return pose;
}

TYPED_TEST(KDop4Test, VectorPathAnswersAsTheScalarReferenceAndTheDoubleTest) {
  using Dop = typename TypeParam::Volume;
  std::mt19937_64 rng(53);
  int overlapping = 0, total = 0;
  for (int round = 0; round < 1500; ++round) {
    std::array<Dop, 4> as, bs;
    TypeParam a, b;
    for (int k = 0; k < 4; ++k) {
      as[k] = random_dop<Dop>(rng, Vec3::Zero(), 0.5), bs[k] = random_dop<Dop>(rng, Vec3::Zero(), 0.5);
      if ((round + k) % 9 != 0) a.set(k, as[k]);  // some lanes stay empty
      if ((round + 2 * k) % 11 != 0) b.set(k, bs[k]);
    }
    const RigidTransform pose = random_dop_pose(rng, 1.2);
    const auto context = TypeParam::make_context(pose);
    const unsigned mask = TypeParam::overlap(a, b, context);
    ASSERT_EQ(mask, TypeParam::overlap_scalar(a, b, context)) << "round " << round;
    const auto exact = Dop::make_context(pose);
    for (int k = 0; k < 4; ++k) {
      const bool said = (mask >> k) & 1u;
      if (a.empty(k) || b.empty(k)) {
        ASSERT_FALSE(said) << "an empty lane overlapped, round " << round;
        continue;
      }
      ASSERT_TRUE(said || !Dop::overlap(as[k], bs[k], exact)) << "lane " << k << " of round " << round;
      overlapping += said;
      ++total;
    }
  }
  EXPECT_GT(overlapping, total / 10);  // both answers occur
  EXPECT_LT(overlapping, total * 9 / 10);
}

// B moved along x until the double test's answer flips (bisected), A and B 1e6 from the origin and their
// lanes stored relative to origins near them: just inside, the lanes must say overlap; a thousandth of the
// DOPs' size outside, mostly apart.
TYPED_TEST(KDop4Test, PairsAtTheDoubleTestsEdgeStayOverlappingFarFromTheOrigin) {
  using Dop = typename TypeParam::Volume;
  std::mt19937_64 rng(59);
  std::uniform_real_distribution<double> unit(-1, 1);
  int apart_outside = 0;
  for (int round = 0; round < 300; ++round) {
    const Vec3 far = Vec3::Constant(round % 2 ? 1e6 : 0);
    const Dop a = random_dop<Dop>(rng, far, 0.4), b = random_dop<Dop>(rng, far, 0.4);
    const Vec3 origin_a = far + testing::draw_vec3(unit, rng), origin_b = far + testing::draw_vec3(unit, rng);
    TypeParam la, lb;
    la.set(0, a, origin_a), lb.set(0, b, origin_b);
    RigidTransform pose = random_dop_pose(rng, 0);
    pose.translation = a.bounding_box().center() - pose.rotation * b.bounding_box().center();  // B on A
    const auto overlaps = [&](const RigidTransform& p) { return Dop::overlap(a, b, Dop::make_context(p)); };
    ASSERT_TRUE(overlaps(pose));
    double inside = pose.translation.x(), outside = inside + 10;
    for (int i = 0; i < 200; ++i) {
      pose.translation.x() = 0.5 * (inside + outside);
      (overlaps(pose) ? inside : outside) = pose.translation.x();
    }
    pose.translation.x() = inside;
    ASSERT_TRUE(TypeParam::overlap(la, lb, TypeParam::make_context(pose, origin_a, origin_b)) & 1u)
        << "round " << round;
    pose.translation.x() = inside + 1e-3;
    apart_outside +=
        (TypeParam::overlap(la, lb, TypeParam::make_context(pose, origin_a, origin_b)) & 1u) == 0;
  }
  EXPECT_GT(apart_outside, 280);
}

TYPED_TEST(KDop4Test, LanesContainTheirDops) {
  using Dop = typename TypeParam::Volume;
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> unit(-1, 1);
  const auto& normals = Dop::tables().normals;
  for (int round = 0; round < 500; ++round) {
    const Vec3 far = Vec3::Constant(round % 3 == 0 ? 0 : round % 3 == 1 ? 1e5 : -3e6);
    const Dop dop = random_dop<Dop>(rng, far, round % 2 ? 0.3 : 1e-4);
    const Vec3 origin = far + testing::draw_vec3(unit, rng);
    TypeParam lanes;
    const int k = round % 4;
    lanes.set(k, dop, origin);
    for (std::size_t m = 0; m < Dop::kPlanes; ++m) {  // in long double: offset less n . origin
      long double along = 0;
      for (int r = 0; r < 3; ++r) along += (long double)normals[m][r] * origin[r];
      ASSERT_GE((long double)lanes.offsets[m][k], (long double)dop.offsets[m] - along) << round;
      ASSERT_GE(lanes.mag[k], std::abs(lanes.offsets[m][k]));
    }
  }
}

}  // namespace
}  // namespace bvhlab
