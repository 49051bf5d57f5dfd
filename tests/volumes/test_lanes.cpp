// Four volumes a test, for every layout checked against its volume's own test in double: spheres
// (volumes/sphere4.hpp), oriented boxes (obb4.hpp) and the k-DOPs of every direction set (kdop4.hpp). The
// vector path answers as the scalar reference, lane by lane, and both are conservative against the double
// test (itself checked against exact triangle tests by the conformance suite): a lane reported apart is
// apart there, also for pairs bisected to where the double test's answer flips, 1e6 from the origin with
// the lanes stored relative to nearby origins. (Boxes are checked in exact arithmetic: test_aabb4.cpp.)
#include "support/generated_meshes.hpp"
#include "support/random_draws.hpp"
#include "volumes/aabb4.hpp"
#include "volumes/dop24.hpp"
#include "volumes/kdop4.hpp"
#include "volumes/obb4.hpp"
#include "volumes/sphere4.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <random>
#include <vector>

namespace bvhlab {
namespace {

/// A volume fitted to a few random points near `center`, in a cloud stretched differently along x, y and z
/// (so that an OBB's fit has a frame to find).
template <class BV>
BV random_volume(std::mt19937_64& rng, const Vec3& center, double size) {
  std::uniform_real_distribution<double> unit(-1, 1), extent(0.05, 1);
  const Vec3 stretch = testing::draw_vec3(extent, rng);
  std::vector<Vec3> points;
  for (int k = 0; k < 8; ++k)
    points.push_back(center + size * testing::draw_vec3(unit, rng).cwiseProduct(stretch));
  return BV::fit(points);
}

template <class Lanes>
class LaneTest : public ::testing::Test {};
using Layouts = ::testing::Types<Sphere4, Obb4, KDop4<dop_sets::Dop6>, KDop4<dop_sets::Dop14>,
                                 KDop4<dop_sets::Dop18>, KDop4<dop_sets::Zachmann24>, KDop4<dop_sets::Dop26>>;
TYPED_TEST_SUITE(LaneTest, Layouts);

TYPED_TEST(LaneTest, VectorPathAnswersAsTheScalarReferenceAndTheDoubleTest) {
  using BV = typename TypeParam::Volume;
  std::mt19937_64 rng(53);
  int overlapping = 0, total = 0;
  for (int round = 0; round < 1500; ++round) {
    std::array<BV, 4> as, bs;
    TypeParam a, b;
    for (int k = 0; k < 4; ++k) {
      as[k] = random_volume<BV>(rng, Vec3::Zero(), 0.5), bs[k] = random_volume<BV>(rng, Vec3::Zero(), 0.5);
      if ((round + k) % 9 != 0) a.set(k, as[k]);  // some lanes stay empty
      if ((round + 2 * k) % 11 != 0) b.set(k, bs[k]);
    }
    const RigidTransform pose = testing::random_pose(rng, 0.6);
    const auto context = TypeParam::make_context(pose);
    const unsigned mask = TypeParam::overlap(a, b, context);
    ASSERT_EQ(mask, TypeParam::overlap_scalar(a, b, context)) << "round " << round;
    const auto exact = BV::make_context(pose);
    for (int k = 0; k < 4; ++k) {
      const bool said = (mask >> k) & 1u;
      if (a.empty(k) || b.empty(k)) {
        ASSERT_FALSE(said) << "an empty lane overlapped, round " << round;
        continue;
      }
      ASSERT_TRUE(said || !BV::overlap(as[k], bs[k], exact)) << "lane " << k << " of round " << round;
      overlapping += said;
      ++total;
    }
  }
  EXPECT_GT(overlapping, total / 10);  // both answers occur
  EXPECT_LT(overlapping, total * 9 / 10);
}

// B's volume centred on A's, then moved along x until the double test's answer flips (bisected), A and B
// at the origin or 1e6 from it and their lanes stored relative to origins near them: just inside, the lanes
// must say overlap (a slack of zero fails here); a thousandth outside, mostly apart (the slack is not huge).
TYPED_TEST(LaneTest, PairsAtTheDoubleTestsEdgeStayOverlappingFarFromTheOrigin) {
  using BV = typename TypeParam::Volume;
  std::mt19937_64 rng(59);
  std::uniform_real_distribution<double> unit(-1, 1);
  int apart_outside = 0;
  for (int round = 0; round < 300; ++round) {
    const Vec3 far = Vec3::Constant(round % 2 ? 1e6 : 0);
    const BV a = random_volume<BV>(rng, far, 0.4), b = random_volume<BV>(rng, far, 0.4);
    const Vec3 origin_a = far + testing::draw_vec3(unit, rng), origin_b = far + testing::draw_vec3(unit, rng);
    TypeParam la, lb;
    la.set(0, a, origin_a), lb.set(0, b, origin_b);
    RigidTransform pose = testing::random_pose(rng, 0);
    pose.translation = a.bounding_box().center() - pose.rotation * b.bounding_box().center();
    const auto overlaps = [&](const RigidTransform& p) { return BV::overlap(a, b, BV::make_context(p)); };
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

// The wide walk takes the overlapping pair of nearest centres first (traversal/wide_exact.hpp): four small
// volumes of B placed around A's at distances 0.4 to 2.5 in shuffled lanes, after a random pose, come out of
// center_distances in the order of their true distances, for every layout.
template <class Lanes>
class LaneOrder : public ::testing::Test {};
using AllLayouts =
    ::testing::Types<Aabb4, Sphere4, Obb4, KDop4<dop_sets::Dop6>, KDop4<dop_sets::Dop14>,
                     KDop4<dop_sets::Dop18>, KDop4<dop_sets::Zachmann24>, KDop4<dop_sets::Dop26>>;
TYPED_TEST_SUITE(LaneOrder, AllLayouts);

TYPED_TEST(LaneOrder, CenterDistancesOrderThePlacedVolumesByDistance) {
  using BV = typename TypeParam::Volume;
  std::mt19937_64 rng(67);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int round = 0; round < 200; ++round) {
    const Vec3 far = Vec3::Constant(round % 2 ? 1e5 : 0);
    const Vec3 origin_a = far + testing::draw_vec3(unit, rng), origin_b = far + testing::draw_vec3(unit, rng);
    const RigidTransform pose = testing::random_pose(rng, 1.0);
    const BV a = random_volume<BV>(rng, far, 0.05);
    std::array<double, 4> distance = {0.4, 1.0, 1.7, 2.5};
    std::shuffle(distance.begin(), distance.end(), rng);
    TypeParam la, lb;
    for (int k = 0; k < 4; ++k) {
      la.set(k, a, origin_a);
      // B's volume k where the pose puts it at distance[k] from A's centre, in a random direction.
      const Vec3 there = far + distance[k] * testing::draw_vec3(unit, rng).normalized();
      lb.set(k, random_volume<BV>(rng, pose.rotation.transpose() * (there - pose.translation), 0.05),
             origin_b);
    }
    const auto context = TypeParam::make_context(pose, origin_a, origin_b);
    const std::array<float, 4> key = TypeParam::center_distances(la, TypeParam::place(lb, context));
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (distance[i] < distance[j]) ASSERT_LT(key[i], key[j]) << "round " << round;
  }
}

TEST(KDop4, LanesContainTheirDops) {
  using Dop = Dop24;
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> unit(-1, 1);
  const auto& normals = Dop::tables().normals;
  for (int round = 0; round < 500; ++round) {
    const Vec3 far = Vec3::Constant(round % 3 == 0 ? 0 : round % 3 == 1 ? 1e5 : -3e6);
    const Dop dop = random_volume<Dop>(rng, far, round % 2 ? 0.3 : 1e-4);
    const Vec3 origin = far + testing::draw_vec3(unit, rng);
    KDop4<dop_sets::Zachmann24> lanes;
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

TEST(Sphere4, LanesContainTheirSpheres) {
  std::mt19937_64 rng(73);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int round = 0; round < 1000; ++round) {
    const Vec3 far = Vec3::Constant(round % 3 == 0 ? 0 : round % 3 == 1 ? 1e5 : -3e6);
    const Sphere sphere = random_volume<Sphere>(rng, far, round % 2 ? 0.3 : 1e-4);
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
