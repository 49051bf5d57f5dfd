// LB: the plane/cube geometry, the plane sampler against integral-geometry values, and the tabulated
// rows re-run from their seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "adb/lb_monte_carlo.hpp"
#include "adb/lb_table.hpp"
#include "adb/lb_table_data.hpp"

namespace bvhlab {
namespace {

CellPlane plane_through(Point3d normal, const Point3d& point) {
  const double length = std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  for (double& c : normal) c /= length;
  return {normal, normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2]};
}

double area_of(const CellPlane& plane) {
  return section_area(clip_plane_to_unit_cube(plane), plane.normal);
}

TEST(CubeSection, KnownAreas) {
  const CubeSection square = clip_plane_to_unit_cube(plane_through({0, 0, 1}, {0.5, 0.5, 0.3}));
  EXPECT_EQ(square.count, 4);
  EXPECT_NEAR(area_of(plane_through({0, 0, 1}, {0.5, 0.5, 0.3})), 1.0, 1e-14);
  EXPECT_NEAR(area_of(plane_through({1, -1, 0}, {0, 0, 0})), std::sqrt(2.0), 1e-14);  // diagonal rectangle
  EXPECT_NEAR(area_of(plane_through({1, 1, 1}, {0.5, 0.5, 0.5})), 3.0 * std::sqrt(3.0) / 4.0, 1e-14);
  EXPECT_EQ(clip_plane_to_unit_cube(plane_through({1, 1, 1}, {0.5, 0.5, 0.5})).count, 6);  // hexagon
  EXPECT_NEAR(area_of(plane_through({1, 1, 1}, {1, 0, 0})), std::sqrt(3.0) / 2.0, 1e-14);  // corner triangle
  EXPECT_NEAR(area_of(plane_through({1, 1, 1}, {0.1, 0, 0})), 0.01 * std::sqrt(3.0) / 2.0, 1e-15);
  EXPECT_NEAR(area_of(plane_through({0, 1, 0}, {0, 1.0 / 3.0, 0})), 1.0, 1e-14);
  const CubeSection miss = clip_plane_to_unit_cube(plane_through({0, 0, 1}, {0, 0, 1.5}));
  EXPECT_LT(miss.count, 3);
  EXPECT_EQ(area_of(plane_through({1, 2, 3}, {2, 2, 2})), 0.0);
}

TEST(CubeSection, VerticesLieInCubeAndOnPlane) {
  std::mt19937_64 rng(7);
  for (int i = 0; i < 20'000; ++i) {
    const CellPlane plane = random_plane_hitting_unit_cube(rng);
    const CubeSection section = clip_plane_to_unit_cube(plane);
    ASSERT_GE(section.count, 3);
    ASSERT_LE(section.count, 6);
    for (int k = 0; k < section.count; ++k) {
      const Point3d& v = section.vertices[static_cast<std::size_t>(k)];
      for (double c : v) ASSERT_TRUE(c >= -1e-12 && c <= 1.0 + 1e-12) << c;
      const double side =
          plane.normal[0] * v[0] + plane.normal[1] * v[1] + plane.normal[2] * v[2] - plane.offset;
      ASSERT_NEAR(side, 0.0, 1e-12);
    }
    ASSERT_LE(section_area(section, plane.normal), std::sqrt(2.0) + 1e-12);
  }
}

TEST(CubeSection, PatchesMeetExactlyWhenTheirLineCrossesTheCell) {
  const CellPlane horizontal = plane_through({0, 0, 1}, {0.5, 0.5, 0.5});
  const CellPlane vertical = plane_through({1, 0, 0}, {0.5, 0.5, 0.5});
  const CellPlane parallel = plane_through({0, 0, 1}, {0.5, 0.5, 0.8});
  const CellPlane corner = plane_through({1, 1, 1}, {0.1, 0, 0});  // small triangle near the origin
  EXPECT_TRUE(patch_meets_plane(clip_plane_to_unit_cube(vertical), horizontal));
  EXPECT_TRUE(patch_meets_plane(clip_plane_to_unit_cube(horizontal), vertical));
  EXPECT_FALSE(patch_meets_plane(clip_plane_to_unit_cube(parallel), horizontal));
  // Planes x + y + z = 0.1 and z = 0.5 meet in a line outside the cube's corner region.
  EXPECT_FALSE(patch_meets_plane(clip_plane_to_unit_cube(horizontal), corner));
  EXPECT_FALSE(patch_meets_plane(clip_plane_to_unit_cube(corner), horizontal));
  EXPECT_FALSE(patch_meets_plane(CubeSection{}, horizontal));
}

// Crofton: for motion-invariant random planes hitting a convex body K, E[area of the section] =
// Vol(K) / (mean width of K) and E[perimeter] = (pi / 4) Area(dK) / (mean width). Unit cube: mean width
// 3/2, so 2/3 and pi. Both are sensitive to the direction weighting (uniform offsets over the cube's own
// extent along a uniform direction give 0.674 and 3.165: about 25 standard errors off).
TEST(PlaneSampler, MatchesIntegralGeometry) {
  std::mt19937_64 rng(11);
  const int n = 400'000;
  double sum_area = 0, sum_area2 = 0, sum_perimeter = 0, sum_perimeter2 = 0;
  for (int i = 0; i < n; ++i) {
    const CellPlane plane = random_plane_hitting_unit_cube(rng);
    const CubeSection section = clip_plane_to_unit_cube(plane);
    const double area = section_area(section, plane.normal);
    double perimeter = 0;
    for (int k = 0; k < section.count; ++k) {
      const Point3d& p = section.vertices[static_cast<std::size_t>(k)];
      const Point3d& q = section.vertices[static_cast<std::size_t>((k + 1) % section.count)];
      perimeter += std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    }
    sum_area += area;
    sum_area2 += area * area;
    sum_perimeter += perimeter;
    sum_perimeter2 += perimeter * perimeter;
  }
  const double mean_area = sum_area / n;
  const double se_area = std::sqrt((sum_area2 / n - mean_area * mean_area) / n);
  const double mean_perimeter = sum_perimeter / n;
  const double se_perimeter = std::sqrt((sum_perimeter2 / n - mean_perimeter * mean_perimeter) / n);
  EXPECT_NEAR(mean_area, 2.0 / 3.0, 4 * se_area) << "se " << se_area;
  EXPECT_NEAR(mean_perimeter, std::numbers::pi, 4 * se_perimeter) << "se " << se_perimeter;
}

TEST(LbTable, NoThresholdGivesPiOverSix) {
  // Patch Q meets a random hitting plane with probability (mean width of Q) / (mean width of the cube)
  // = (perimeter(Q) / 4) / (3 / 2); averaged, E[perimeter] = pi gives LB(0) = pi / 6.
  const LbTableRow& row = kLbTable[0];
  ASSERT_EQ(row.tau, 0.0);
  EXPECT_NEAR(row.lb(), std::numbers::pi / 6.0, 4 * row.standard_error);
}

TEST(LbTable, RowsAreOrderedConsistentAndIncreasing) {
  ASSERT_GE(std::size(kLbTable), 2u);
  for (std::size_t i = 0; i < std::size(kLbTable); ++i) {
    const LbTableRow& row = kLbTable[i];
    const double p = row.lb();
    EXPECT_NEAR(row.standard_error, std::sqrt(p * (1 - p) / static_cast<double>(row.pairs)),
                1e-3 * row.standard_error);
    if (i > 0) {
      EXPECT_GT(row.tau, kLbTable[i - 1].tau);
      // Larger patches reach further across the cell: LB grows with tau, by far more than the noise.
      EXPECT_GT(p - kLbTable[i - 1].lb(), 4 * (row.standard_error + kLbTable[i - 1].standard_error));
    }
  }
}

TEST(LbTable, LbForTauInterpolatesAndRejectsOutOfRange) {
  for (const LbTableRow& row : kLbTable) EXPECT_EQ(lb_for_tau(row.tau), row.lb());
  const LbTableRow& a = kLbTable[2];
  const LbTableRow& b = kLbTable[3];
  EXPECT_NEAR(lb_for_tau(0.5 * (a.tau + b.tau)), 0.5 * (a.lb() + b.lb()), 1e-15);
  EXPECT_THROW(lb_for_tau(-0.01), std::invalid_argument);
  EXPECT_THROW(lb_for_tau(kLbTable[std::size(kLbTable) - 1].tau + 0.01), std::invalid_argument);
  EXPECT_THROW(lb_for_tau(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(LbMonteCarlo, BadInputIsRejected) {
  EXPECT_THROW(run_lb_monte_carlo(-0.1, 10, 1), std::invalid_argument);
  EXPECT_THROW(run_lb_monte_carlo(1.5, 10, 1), std::invalid_argument);
  EXPECT_THROW(run_lb_monte_carlo(std::numeric_limits<double>::quiet_NaN(), 10, 1), std::invalid_argument);
  EXPECT_THROW(run_lb_monte_carlo(0.5, 0, 1), std::invalid_argument);
}

// Every tabulated row, re-run from its seed with its sample count: the generator is deterministic
// (mt19937_64, own uniform mapping, IEEE basic operations only, no FMA contraction), so the hit count
// must match exactly. One ctest entry per row (about 1 to 3 s each in a Release build).
class LbTableRegeneration : public ::testing::TestWithParam<std::size_t> {};

TEST_P(LbTableRegeneration, RegeneratesExactly) {
  const LbTableRow& row = kLbTable[GetParam()];
  const LbMonteCarloResult rerun = run_lb_monte_carlo(row.tau, row.pairs, row.seed);
  EXPECT_EQ(rerun.pairs, row.pairs);
  EXPECT_EQ(rerun.hits, row.hits) << "tau " << row.tau << ": LB " << rerun.probability() << " vs tabulated "
                                  << row.lb();
  EXPECT_NEAR(rerun.standard_error(), row.standard_error, 1e-3 * row.standard_error);
}

INSTANTIATE_TEST_SUITE_P(AllRows, LbTableRegeneration, ::testing::Range<std::size_t>(0, std::size(kLbTable)));

}  // namespace
}  // namespace bvhlab
