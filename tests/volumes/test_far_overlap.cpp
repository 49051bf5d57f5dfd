// Overlap tests stay conservative when B lies far from its own origin and the pose brings it back next to
// A: the image R c_b + t then rounds relative to |c_b| and |t|, not to its own small size.
#include "support/random_draws.hpp"
#include "support/volume_lists.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <random>
#include <vector>

namespace bvhlab {
namespace {

/// Two boxes that share a point: A = [-1, 1]^3 near its origin, B a unit box near 1e6 in its own frame,
/// and a pose that puts B's corner y (B's lowest in A's x) inside A's face x = 1, at most 1e-10 deep
/// (checked in long double). The re-boxed B then touches A's face only there: the sharpest case for boxes.
/// The other volumes, fitted to the same corners, contain the boxes and must overlap too.
struct TouchingBoxes {
  std::vector<Vec3> a_corners, b_corners;
  RigidTransform pose;
};

std::vector<Vec3> corners(const Vec3& lo, const Vec3& hi) {
  std::vector<Vec3> out;
  for (int k = 0; k < 8; ++k)
    out.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  return out;
}

std::optional<TouchingBoxes> draw_touching_boxes(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0, 1);
  TouchingBoxes t;
  t.pose.rotation =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
  // Corners exactly representable as floats, so every volume stores these very boxes.
  Vec3 b_lo;
  for (int k = 0; k < 3; ++k) b_lo[k] = double(float((k == 1 ? -1e6 : 1e6) + unit(rng)));
  const Vec3 b_hi = b_lo + Vec3::Ones();
  Vec3 y;
  for (int j = 0; j < 3; ++j) y[j] = t.pose.rotation(0, j) > 0 ? b_lo[j] : b_hi[j];
  const Vec3 x(1 - 1e-10 * unit(rng), 0.3, -0.2);
  t.pose.translation = x - t.pose.rotation * y;
  for (int i = 0; i < 3; ++i) {
    long double v = t.pose.translation[i];
    for (int j = 0; j < 3; ++j) v += static_cast<long double>(t.pose.rotation(i, j)) * y[j];
    if (v < -1 || v > 1) return std::nullopt;  // rounding put the corner outside: not a touching case
  }
  t.a_corners = corners(-Vec3::Ones(), Vec3::Ones());
  t.b_corners = corners(b_lo, b_hi);
  return t;
}

template <class BV>
class FarOverlap : public ::testing::Test {};
TYPED_TEST_SUITE(FarOverlap, testing::ShippedBoundingVolumes);

TYPED_TEST(FarOverlap, KeepsAPointSharedFarFromBsOrigin) {
  std::mt19937_64 rng(21);
  int cases = 0;
  for (int k = 0; k < 20000; ++k) {
    const auto t = draw_touching_boxes(rng);
    if (!t) continue;
    ++cases;
    const TypeParam a = TypeParam::fit(t->a_corners), b = TypeParam::fit(t->b_corners);
    ASSERT_TRUE(TypeParam::overlap(a, b, TypeParam::make_context(t->pose))) << "case " << k;
  }
  EXPECT_GT(cases, 10000);
}

TEST(FarOverlapRestrictedBox, KeepsAPointSharedFarFromBsOrigin) {
  std::mt19937_64 rng(22);
  int cases = 0;
  for (int k = 0; k < 20000; ++k) {
    const auto t = draw_touching_boxes(rng);
    if (!t) continue;
    ++cases;
    const auto wa =
        RestrictedBox::start(Aabb::fit(t->a_corners), RestrictedBox::make_frame(RigidTransform{}));
    const auto wb = RestrictedBox::start(Aabb::fit(t->b_corners), RestrictedBox::make_frame(t->pose));
    ASSERT_TRUE(RestrictedBox::overlap(wa, wb)) << "case " << k;
  }
  EXPECT_GT(cases, 10000);
}

}  // namespace
}  // namespace bvhlab
