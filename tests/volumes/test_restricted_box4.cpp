// The restricted boxtree's wide layout (volumes/restricted_box4.hpp): four boxes packed on a grid over the
// box around them. Unpacked (vector path and scalar reference alike, bit for bit), every lane contains the
// box it was packed from in exact arithmetic, also far from the origin and for boxes thin enough that a step
// rounds away; it is at most a few steps looser; unused lanes stay empty. The test itself is Aabb4's
// (conservative by test_aabb4.cpp); the wide walk on rbox trees is checked against CGAL in
// tests/traversal/test_wide_exact.cpp.
#include "support/random_draws.hpp"
#include "volumes/restricted_box4.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace bvhlab {
namespace {

Box random_box(std::mt19937_64& rng, const Vec3& center, double size) {
  std::uniform_real_distribution<double> unit(-1, 1), extent(0, 1);
  const Vec3 c = center + size * testing::draw_vec3(unit, rng);
  const Vec3 h = size * testing::draw_vec3(extent, rng);
  return {c - h, c + h};
}

// Lane k of `lanes` (relative to `origin`) holds `box`, compared in long double.
bool contains(const Aabb4& lanes, int k, const Box& box, const Vec3& origin) {
  const long double c[3] = {lanes.cx[k], lanes.cy[k], lanes.cz[k]};
  const long double h[3] = {lanes.hx[k], lanes.hy[k], lanes.hz[k]};
  for (int r = 0; r < 3; ++r) {
    const long double low = static_cast<long double>(box.min[r]) - origin[r];
    const long double high = static_cast<long double>(box.max[r]) - origin[r];
    if (c[r] - h[r] > low || c[r] + h[r] < high) return false;
  }
  return true;
}

void expect_packs(const std::vector<Box>& boxes, const Vec3& origin, const std::string& what) {
  const RestrictedBox4 packed = RestrictedBox4::pack(boxes, origin);
  const Aabb4 vector = RestrictedBox4::unpack(packed), scalar = RestrictedBox4::unpack_scalar(packed);
  Box around;
  for (const Box& b : boxes) around.extend(b);
  for (int k = 0; k < 4; ++k) {
    for (const auto& [v, s] : {std::pair{vector.cx, scalar.cx},
                               {vector.cy, scalar.cy},
                               {vector.cz, scalar.cz},
                               {vector.hx, scalar.hx},
                               {vector.hy, scalar.hy},
                               {vector.hz, scalar.hz}})
      ASSERT_EQ(v[k], s[k]) << what << ", lane " << k;
    if (k >= int(boxes.size())) {
      EXPECT_TRUE(packed.empty(k) && vector.empty(k)) << what << ", lane " << k;
      continue;
    }
    ASSERT_TRUE(contains(vector, k, boxes[k], origin)) << what << ", lane " << k;
    // At most one step looser at each end, and the pad: the grid is the box around the four, in 255 steps;
    // the pad is 16 float roundings of the largest coordinate about the origin, and taking the origin off
    // in double moves each end out by a few double roundings of the coordinates.
    const float h[3] = {vector.hx[k], vector.hy[k], vector.hz[k]};
    const double reach =
        std::max((around.min - origin).cwiseAbs().maxCoeff(), (around.max - origin).cwiseAbs().maxCoeff());
    const double shift =
        1e-14 * (around.min.cwiseAbs().sum() + around.max.cwiseAbs().sum() + origin.cwiseAbs().sum());
    for (int r = 0; r < 3; ++r) {
      const double extent = around.max[r] - around.min[r];
      const double loose = double(h[r]) - 0.5 * (boxes[k].max[r] - boxes[k].min[r]);
      EXPECT_LE(loose, 1.01 * extent / 255 + 2e-6 * reach + shift + 1e-30)
          << what << ", lane " << k << ", axis " << r;
    }
    EXPECT_GE(vector.mag[k],
              std::max({std::abs(vector.cx[k]), std::abs(vector.cy[k]), std::abs(vector.cz[k])}) +
                  std::max({h[0], h[1], h[2]}))
        << what;
  }
}

TEST(RestrictedBox4, UnpackedLanesContainTheirBoxesAndVectorEqualsScalar) {
  std::mt19937_64 rng(71);
  for (int round = 0; round < 3000; ++round) {
    const double scale = std::pow(10.0, round % 7 - 3);  // 1e-3 to 1e3
    const Vec3 center = (round % 5 == 0 ? 1e6 : 1.0) * Vec3(0.3, -0.7, 0.2);
    const Vec3 origin = round % 3 == 0 ? Vec3(Vec3::Zero()) : Vec3(center + scale * Vec3(0.1, 0.2, -0.3));
    std::vector<Box> boxes;
    for (int k = 0; k < 1 + round % 4; ++k) boxes.push_back(random_box(rng, center, scale));
    expect_packs(boxes, origin, "round " + std::to_string(round));
  }
}

// A point, a flat box, and boxes a millionth of their distance from the origin wide: the step is far below
// the ends' float spacing, and the pad is what keeps them inside.
TEST(RestrictedBox4, DegenerateAndThinBoxesFarFromTheOrigin) {
  const Vec3 p(1e6, -2e6, 3e5);
  expect_packs({Box{p, p}}, Vec3::Zero(), "a point");
  expect_packs({Box{p, p + Vec3(1, 0, 0)}, Box{p, p}}, Vec3::Zero(), "a segment and a point");
  expect_packs({Box{p, p + Vec3(1e-6, 1e-6, 0)}, Box{p + Vec3(0, 1e-6, 0), p + Vec3(2e-6, 3e-6, 1e-9)}},
               Vec3::Zero(), "thin boxes");
  expect_packs({Box{p, p + Vec3(1e-6, 1e-6, 0)}}, p, "a thin box about its own origin");
}

TEST(RestrictedBox4, RefusesNoBoxTooManyAndNonFiniteOnes) {
  const Box unit{Vec3::Zero(), Vec3::Ones()};
  EXPECT_THROW(RestrictedBox4::pack({}, Vec3::Zero()), std::invalid_argument);
  const std::vector<Box> five(5, unit);
  EXPECT_THROW(RestrictedBox4::pack(five, Vec3::Zero()), std::invalid_argument);
  Box bad = unit;
  bad.max.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(RestrictedBox4::pack(std::vector<Box>{unit, bad}, Vec3::Zero()), std::invalid_argument);
  EXPECT_THROW(RestrictedBox4::pack(std::vector<Box>{Box{}}, Vec3::Zero()), std::invalid_argument);
}

// Lanes packed from overlapping boxes report the overlap; boxes well apart are reported apart.
TEST(RestrictedBox4, OverlapFollowsTheBoxes) {
  const std::vector<Box> a = {{Vec3(0, 0, 0), Vec3(1, 1, 1)}, {Vec3(3, 0, 0), Vec3(4, 1, 1)}};
  const std::vector<Box> b = {{Vec3(0.5, 0.5, 0.5), Vec3(2, 2, 2)}};
  const RestrictedBox4 lanes_a = RestrictedBox4::pack(a), lanes_b = RestrictedBox4::pack(b);
  const RestrictedBox4 one_b = RestrictedBox4::pack(std::vector<Box>(4, b[0]));
  const auto context = RestrictedBox4::make_context(RigidTransform::identity());
  EXPECT_EQ(RestrictedBox4::overlap(lanes_a, one_b, context), 1u);  // lane 0 only; lanes 2, 3 are empty
  EXPECT_EQ(RestrictedBox4::overlap(lanes_a, lanes_b, context), 1u);
  const auto moved = RestrictedBox4::make_context(RigidTransform::translate({2.5, 0, 0}));
  EXPECT_EQ(RestrictedBox4::overlap(lanes_a, one_b, moved), 2u);
}

}  // namespace
}  // namespace bvhlab
