// ADB density annotation: clipped areas against closed forms and an independent clipper, the closed-cell
// rule, degenerate input, exact ties, and pc counts against an exact rational reference.
#include "adb/adb_density.hpp"
#include "support/generated_meshes.hpp"
#include "volumes/aabb.hpp"

#include <CGAL/Gmpq.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace bvhlab {
namespace {

using testing::draw_vec3;

using Range = std::pair<std::uint32_t, std::uint32_t>;

Box box_of(const Vec3& lo, const Vec3& hi) {
  return Box{lo, hi};
}

double triangle_area(const TrianglePoints& t) {
  return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
}

/// pc of one node holding all `triangles`, on `box`.
int pc_of(const std::vector<TrianglePoints>& triangles, const Box& box, int g, double tau,
          AnnotateStats* stats = nullptr) {
  const std::vector<Box> boxes{box};
  const std::vector<Range> ranges{{0, static_cast<std::uint32_t>(triangles.size())}};
  AnnotateOptions options;
  options.tau = tau;
  options.threads = 1;
  const CellCounts result = annotate_counts(boxes, ranges, triangles, g, options);
  if (stats) *stats = result.stats;
  return result.counts.at(0);
}

/// Two triangles covering the axis-aligned rectangle spanned by corner + s*u + t*v, s, t in [0, 1].
std::vector<TrianglePoints> rectangle(const Vec3& corner, const Vec3& u, const Vec3& v) {
  return {{corner, corner + u, corner + u + v}, {corner, corner + u + v, corner + v}};
}

// Independent reference: Sutherland-Hodgman against the six planes in plain doubles.
double reference_area_in_box(const TrianglePoints& t, const Box& box) {
  std::vector<Vec3> poly(t.begin(), t.end());
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const double bound = side == 0 ? box.min[axis] : box.max[axis];
      auto inside = [&](const Vec3& p) { return side == 0 ? p[axis] >= bound : p[axis] <= bound; };
      std::vector<Vec3> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Vec3& a = poly[i];
        const Vec3& b = poly[(i + 1) % poly.size()];
        if (inside(a)) out.push_back(a);
        if (inside(a) != inside(b)) out.push_back(a + (b - a) * ((bound - a[axis]) / (b[axis] - a[axis])));
      }
      poly = std::move(out);
      if (poly.empty()) return 0;
    }
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) sum += (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]);
  return 0.5 * sum.norm();
}

TEST(TriangleAreaInBox, AxisAlignedTriangleCutByOnePlaneIntoKnownParts) {
  // x + y <= 2 in the plane z = 0; the plane x = 1 cuts it into 1.5 (x <= 1) and 0.5 (x >= 1).
  const TrianglePoints t{Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 2, 0)};
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(0, -1, -1), Vec3(1, 3, 1))), 1.5, 1e-14);
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(1, -1, -1), Vec3(3, 3, 1))), 0.5, 1e-14);
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(-1, -1, -1), Vec3(3, 3, 1))), 2.0, 1e-14);
}

TEST(TriangleAreaInBox, SlantedTriangleCutByTwoPlanes) {
  // In the plane z = x: the area is the xy-projected area times sqrt(2).
  const TrianglePoints t{Vec3(0, 0, 0), Vec3(1, 0, 1), Vec3(0, 1, 0)};
  const double s2 = std::sqrt(2.0);
  EXPECT_NEAR(triangle_area(t), 0.5 * s2, 1e-15);
  // x, y <= 0.5: the whole square [0, .5]^2 lies under x + y <= 1.
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(0, 0, -1), Vec3(0.5, 0.5, 2))), 0.25 * s2, 1e-14);
  // x >= 0.5, y <= 0.5: the triangle (.5, 0), (1, 0), (.5, .5), projected area 1/8.
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(0.5, 0, -1), Vec3(1, 0.5, 2))), 0.125 * s2, 1e-14);
  // z <= 0.5 means x <= 0.5: projected area of x in [0, .5], y in [0, 1 - x] is 3/8.
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(-1, -1, 0), Vec3(2, 2, 0.5))), 0.375 * s2, 1e-14);
  // z in [0.25, 0.5] and y >= 0.25: x in [.25, .5], y in [.25, 1 - x]: integral of (0.75 - x) dx = 3/32.
  EXPECT_NEAR(triangle_area_in_box(t, box_of(Vec3(-1, 0.25, 0.25), Vec3(2, 2, 0.5))), 3.0 / 32 * s2, 1e-14);
}

TEST(TriangleAreaInBox, RandomTrianglesMatchAnIndependentClipper) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int i = 0; i < 500; ++i) {
    const TrianglePoints t{draw_vec3(unit, rng), draw_vec3(unit, rng), draw_vec3(unit, rng)};
    Vec3 a = draw_vec3(unit, rng);
    Vec3 b = draw_vec3(unit, rng);
    const Box box = box_of(a.cwiseMin(b), a.cwiseMax(b));
    const double expected = reference_area_in_box(t, box);
    EXPECT_NEAR(triangle_area_in_box(t, box), expected, 1e-12 * (1 + triangle_area(t))) << "case " << i;
  }
}

TEST(TriangleAreaInBox, CellAreasOfAGridSumToTheTriangleArea) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> inner(-0.9, 0.9);
  for (int g = 1; g <= 4; ++g)
    for (int i = 0; i < 40; ++i) {
      const TrianglePoints t{draw_vec3(inner, rng), draw_vec3(inner, rng), draw_vec3(inner, rng)};
      double sum = 0;
      for (int x = 0; x < g; ++x)
        for (int y = 0; y < g; ++y)
          for (int z = 0; z < g; ++z) {
            const Vec3 lo = Vec3(-1, -1, -1) + 2.0 / g * Vec3(x, y, z);
            sum += triangle_area_in_box(t, box_of(lo, lo + Vec3::Constant(2.0 / g)));
          }
      EXPECT_NEAR(sum, triangle_area(t), 1e-13 * triangle_area(t) + 1e-15) << "g " << g << " case " << i;
    }
}

TEST(TriangleAreaInBox, TriangleInsideOneCellKeepsItsArea) {
  const TrianglePoints t{Vec3(0.1, 0.2, 0.3), Vec3(0.4, 0.1, 0.2), Vec3(0.3, 0.45, 0.1)};
  EXPECT_DOUBLE_EQ(triangle_area_in_box(t, box_of(Vec3(0, 0, 0), Vec3(0.5, 0.5, 0.5))), triangle_area(t));
}

TEST(TriangleAreaInBox, DegenerateTrianglesAndMissedBoxesHaveZeroArea) {
  const Box box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 1));
  EXPECT_EQ(triangle_area_in_box({Vec3(0.1, 0.1, 0.1), Vec3(0.5, 0.5, 0.5), Vec3(0.9, 0.9, 0.9)}, box), 0.0);
  EXPECT_EQ(triangle_area_in_box({Vec3(0.2, 0.3, 0.4), Vec3(0.2, 0.3, 0.4), Vec3(0.2, 0.3, 0.4)}, box), 0.0);
  EXPECT_EQ(triangle_area_in_box({Vec3(0.2, 0.3, 0.4), Vec3(0.2, 0.3, 0.4), Vec3(0.7, 0.1, 0.4)}, box), 0.0);
  EXPECT_EQ(triangle_area_in_box({Vec3(2, 2, 2), Vec3(3, 2, 2), Vec3(2, 3, 2)}, box), 0.0);
  EXPECT_EQ(triangle_area_in_box({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}, Box{}), 0.0);
  // Touching the box in an edge only.
  EXPECT_EQ(triangle_area_in_box({Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(2, 0.5, 0.5)}, box), 0.0);
}

TEST(TriangleAreaInBox, TriangleOnACellFaceCountsForBothClosedCells) {
  // In the plane x = 0.5, the face shared by the cells x in [0, .5] and x in [.5, 1].
  const TrianglePoints t{Vec3(0.5, 0.1, 0.1), Vec3(0.5, 0.9, 0.1), Vec3(0.5, 0.1, 0.9)};
  const double full = triangle_area(t);
  EXPECT_DOUBLE_EQ(triangle_area_in_box(t, box_of(Vec3(0, 0, 0), Vec3(0.5, 1, 1))), full);
  EXPECT_DOUBLE_EQ(triangle_area_in_box(t, box_of(Vec3(0.5, 0, 0), Vec3(1, 1, 1))), full);
  // Cut by the plane z = 0.5 as well: split between the lower and the upper cells, on both sides of x.
  for (const double x0 : {0.0, 0.5}) {
    const double lower = triangle_area_in_box(t, box_of(Vec3(x0, 0, 0), Vec3(x0 + 0.5, 1, 0.5)));
    const double upper = triangle_area_in_box(t, box_of(Vec3(x0, 0, 0.5), Vec3(x0 + 0.5, 1, 1)));
    EXPECT_NEAR(lower + upper, full, 1e-15);
    EXPECT_NEAR(upper, 0.5 * 0.4 * 0.4, 1e-15);  // the corner triangle above z = 0.5 has legs 0.4
  }
}

TEST(PossibleCollisionCells, UnitSquareInTheLowerLayerFillsFourCells) {
  // Square at z = 0.25 in the node box [0, 1]^3 with g = 2: each of the four lower cells holds 0.25, the
  // cell's mean face area is 0.25. Its diagonal runs through the corner shared by four cells.
  const auto square = rectangle(Vec3(0, 0, 0.25), Vec3(1, 0, 0), Vec3(0, 1, 0));
  const Box box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 1));
  for (const double tau : {0.25, 0.5, 0.75}) EXPECT_EQ(pc_of(square, box, 2, tau), 4) << tau;
  // tau = 1: area == threshold exactly; the exact decision counts ties.
  AnnotateStats stats;
  EXPECT_EQ(pc_of(square, box, 2, 1.0, &stats), 4);
  EXPECT_GT(stats.exact_cells, 0u);
  EXPECT_EQ(pc_of(square, box, 2, std::nextafter(1.0, 2.0)), 0);
  // g = 4: z = 0.25 is now the plane between the first two layers, so the square counts in both: 2 x 16
  // cells of area 1/16, mean face area 1/16.
  EXPECT_EQ(pc_of(square, box, 4, 1.0), 32);
  EXPECT_EQ(pc_of(square, box, 4, 1.0 + 1e-12), 0);
  // g = 3 (cell planes at 1/3, 2/3): one layer, 9 cells of area 1/9 against a mean face area of 1/9.
  EXPECT_EQ(pc_of(square, box, 3, 0.99), 9);
}

TEST(PossibleCollisionCells, IrrationalAreaWithinAnUlpOfTheThresholdIsDecidedExactly) {
  // A rectangle in the plane z = x puts 0.25 sqrt(2) into each of two cells of mean face area 0.25. The
  // double nearest sqrt(2) lies above sqrt(2), its predecessor below: thresholds one ulp apart, on either
  // side of an irrational area, which only the exact comparison separates.
  const auto slanted = rectangle(Vec3(0, 0, 0), Vec3(0.5, 0, 0.5), Vec3(0, 1, 0));
  const Box box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 1));
  const double sqrt2_above = std::sqrt(2.0);
  ASSERT_GT(sqrt2_above * sqrt2_above, 2.0);  // 1.4142135623730951 squared rounds up: it is above sqrt(2)
  AnnotateStats stats;
  EXPECT_EQ(pc_of(slanted, box, 2, sqrt2_above, &stats), 0);
  EXPECT_GT(stats.exact_cells, 0u);
  EXPECT_EQ(pc_of(slanted, box, 2, std::nextafter(sqrt2_above, 0.0), &stats), 2);
  EXPECT_GT(stats.exact_cells, 0u);
}

TEST(PossibleCollisionCells, SquareOnTheSharedFaceCountsInBothLayers) {
  const Box box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 1));
  EXPECT_EQ(pc_of(rectangle(Vec3(0, 0, 0.5), Vec3(1, 0, 0), Vec3(0, 1, 0)), box, 2, 0.5), 8);
  // Half a square, ending on the edge y = 0.5 shared by four cells: both z layers, one y row.
  EXPECT_EQ(pc_of(rectangle(Vec3(0, 0, 0.5), Vec3(1, 0, 0), Vec3(0, 0.5, 0)), box, 2, 0.5), 4);
  // A sliver along the cell edge x = y = 0.5 (zero area) counts nowhere.
  const std::vector<TrianglePoints> sliver{{Vec3(0.5, 0.5, 0.1), Vec3(0.5, 0.5, 0.9), Vec3(0.5, 0.5, 0.5)}};
  EXPECT_EQ(pc_of(sliver, box, 2, 0.01), 0);
  EXPECT_EQ(pc_of(sliver, box, 2, 0.0), 0);  // not even at tau = 0: zero area never counts
}

TEST(PossibleCollisionCells, FlatNodeBoxCountsEveryLayer) {
  // One triangle in z = 0: the box is flat, a = b = 0.5, c = 0, mean face area 1/12. Cell areas: 1/4 for the
  // corner cell, 1/8 for its two neighbours, 0 for the opposite one; each counts in both (identical) layers.
  const std::vector<TrianglePoints> t{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}};
  const Box box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 0));
  EXPECT_EQ(pc_of(t, box, 2, 0.0), 6);  // tau = 0: every cell with some area; the empty one still not
  EXPECT_EQ(pc_of(t, box, 2, 0.5), 6);
  EXPECT_EQ(pc_of(t, box, 2, 1.5), 6);  // 1/8 == 1.5 / 12: a tie, counted
  EXPECT_EQ(pc_of(t, box, 2, 1.6), 2);
  EXPECT_EQ(pc_of(t, box, 2, 3.0), 2);  // 1/4 == 3 / 12
  EXPECT_EQ(pc_of(t, box, 2, 3.01), 0);
}

TEST(PossibleCollisionCells, AFrameCountsItsTriangleAsTheSameShapeAxisAligned) {
  // FlatNodeBoxCountsEveryLayer's triangle, turned and moved: counted in its own frame (the OBB's box, as
  // thin as a rounding margin, hence flattened) it gives the counts of the axis-aligned original; the
  // thresholds are kept away from its ties (1/8 and 1/4 of a cell, mean face area 1/12).
  const Mat3 turn = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 shift(5, -2, 3);
  std::vector<TrianglePoints> turned{{shift, turn * Vec3(1, 0, 0) + shift, turn * Vec3(0, 1, 0) + shift}};
  const std::vector<OrientedBox> frames{{turn, turn * Vec3(0.5, 0.5, 0) + shift, Vec3(0.5, 0.5, 1e-9)}};
  const std::vector<Range> ranges{{0, 1}};
  const std::vector<TrianglePoints> flat{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}};
  const Box flat_box = box_of(Vec3(0, 0, 0), Vec3(1, 1, 0));
  for (const double tau : {0.5, 1.4, 1.6, 2.9, 3.1}) {
    AnnotateOptions options;
    options.tau = tau;
    const int in_frame = annotate_counts_in_frames(frames, ranges, turned, 2, options).counts.at(0);
    EXPECT_EQ(in_frame, pc_of(flat, flat_box, 2, tau)) << "tau " << tau;
  }
  // On its axis-aligned bounding box the turned triangle is a slanted cut through a solid box: other counts.
  Box around;
  for (const Vec3& v : turned[0]) around.extend(v);
  EXPECT_NE(pc_of(turned, around, 2, 1.6), pc_of(flat, flat_box, 2, 1.6));
}

TEST(PossibleCollisionCells, DegenerateTrianglesNeverCount) {
  const std::vector<TrianglePoints> t{{Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(0.5, 0.5, 0.5)},
                                      {Vec3(0.2, 0.2, 0.2), Vec3(0.2, 0.2, 0.2), Vec3(0.2, 0.2, 0.2)}};
  AnnotateStats stats;
  EXPECT_EQ(pc_of(t, box_of(Vec3(0, 0, 0), Vec3(1, 1, 1)), 2, 1e-6, &stats), 0);
  EXPECT_EQ(stats.degenerate_triangles, 2u);
}

// ---- whole trees
// --------------------------------------------------------------------------------------------

Mesh snapped(Mesh mesh, double step) {
  // Coordinates on a coarse grid: leaf boxes then pass exactly through vertices and edge midpoints, the
  // degenerate clipping positions real float meshes produce.
  for (auto& v : mesh.vertices) v = (v / step).array().round().matrix() * step;
  return mesh;
}

std::vector<Box> node_boxes(const Bvh<Aabb>& bvh) {
  std::vector<Box> boxes;
  for (const Aabb& v : bvh.volumes()) boxes.push_back(v.bounding_box());
  return boxes;
}

TEST(Annotate, CountsAreAtMostGCubedAndMonotoneInTau) {
  const Mesh mesh = testing::make_torus(1.0, 0.35, 24, 12);
  const auto bvh = Bvh<Aabb>::build(mesh);
  std::vector<std::uint8_t> previous;
  // The density takes tau where the LB table has values; the counting alone (annotate_counts) takes any.
  EXPECT_THROW(annotate_adb(bvh, 3, 1.5), std::invalid_argument);
  for (const double tau : {1.0, 0.75, 0.5, 0.25, 0.1, 0.0}) {  // 0: the LB table's first row
    AnnotateOptions options;
    options.tau = tau;
    const auto tree3 = annotate_adb(bvh, 3, options);
    ASSERT_EQ(tree3.density.possible_collision_cells.size(), bvh.nodes().size());
    EXPECT_EQ(tree3.density.params.tau, tau);
    const auto& counts = tree3.density.possible_collision_cells;
    for (const auto c : counts) ASSERT_LE(c, 27);
    if (!previous.empty()) {
      for (std::size_t i = 0; i < counts.size(); ++i) ASSERT_GE(counts[i], previous[i]) << "node " << i;
    }
    previous = counts;
  }
  // Not a vacuous chain: the smallest tau finds more cells than the largest.
  EXPECT_GT(std::count_if(previous.begin(), previous.end(), [](auto c) { return c > 0; }), 0);
}

TEST(Annotate, ThreadCountDoesNotChangeTheCounts) {
  const Mesh mesh = snapped(testing::make_random_soup(600, 0.2, 5), 1.0 / 64);
  const auto bvh = Bvh<Aabb>::build(mesh);
  AnnotateOptions one, two;
  one.threads = 1;
  two.threads = 2;
  AnnotateStats stats;
  const auto a = annotate_adb(bvh, 2, one, &stats);
  const auto b = annotate_adb(bvh, 2, two);
  EXPECT_EQ(a.density.possible_collision_cells, b.density.possible_collision_cells);
  EXPECT_EQ(stats.nodes, bvh.nodes().size());
  EXPECT_GT(stats.fast_path_triangles, 0u);
  EXPECT_GT(stats.clipped_triangles, 0u);
  EXPECT_GT(stats.clip_calls, 0u);
}

// Reference pc by exact rational clipping of every triangle against every closed cell (flat axes dropped:
// every triangle of a flat node lies in its plane), summed as doubles; near-ties are skipped.
using Exact = CGAL::Simple_cartesian<CGAL::Gmpq>;

double exact_area(const TrianglePoints& t, const Exact::Iso_cuboid_3& cell) {
  auto p = [](const Vec3& v) { return Exact::Point_3(v.x(), v.y(), v.z()); };
  const auto result = CGAL::intersection(Exact::Triangle_3(p(t[0]), p(t[1]), p(t[2])), cell);
  if (!result) return 0;
  std::vector<Exact::Point_3> pts;
  if (const auto* tri = boost::get<Exact::Triangle_3>(&*result))
    pts = {tri->vertex(0), tri->vertex(1), tri->vertex(2)};
  if (const auto* poly = boost::get<std::vector<Exact::Point_3>>(&*result)) pts = *poly;
  if (pts.size() < 3) return 0;
  Exact::Vector_3 sum(0, 0, 0);
  for (std::size_t i = 1; i + 1 < pts.size(); ++i)
    sum = sum + CGAL::cross_product(pts[i] - pts[0], pts[i + 1] - pts[0]);
  return 0.5 * std::sqrt(CGAL::to_double(sum.squared_length()));
}

TEST(Annotate, MatchesAnExactRationalReference) {
  for (const double step : {1.0 / 16, 0.0}) {
    Mesh mesh = testing::make_random_soup(60, 0.4, 3);
    if (step > 0) mesh = snapped(mesh, step);
    const auto bvh = Bvh<Aabb>::build(mesh);
    const double tau = 0.5;
    AnnotateOptions options;
    options.tau = tau;
    const auto tree = annotate_adb(bvh, 2, options);
    const auto boxes = node_boxes(bvh);
    const auto ranges = node_triangle_ranges(bvh.nodes());
    int compared = 0;
    for (std::size_t n = 0; n < boxes.size(); ++n) {
      const Box& box = boxes[n];
      const Vec3 side = box.extent() / 2;
      const double threshold = tau * (side.x() * side.y() + side.y() * side.z() + side.z() * side.x()) / 3;
      int expected = 0;
      bool near_tie = false;
      for (int c = 0; c < 8; ++c) {
        Vec3 lo, hi;
        for (int a = 0; a < 3; ++a) {
          const bool upper = (c >> a) & 1;
          lo[a] = side[a] > 0 ? (upper ? box.min[a] + side[a] : box.min[a]) : -1e3;
          hi[a] = side[a] > 0 ? (upper ? box.max[a] : box.min[a] + side[a]) : 1e3;
        }
        const Exact::Iso_cuboid_3 cell(Exact::Point_3(lo.x(), lo.y(), lo.z()),
                                       Exact::Point_3(hi.x(), hi.y(), hi.z()));
        double area = 0;
        for (std::uint32_t t = ranges[n].first; t < ranges[n].second; ++t)
          area += exact_area(bvh.triangles()[t], cell);
        near_tie = near_tie || std::abs(area - threshold) <= 1e-9 * threshold;
        if (area > 0 && area >= threshold) ++expected;
      }
      if (near_tie) continue;
      ++compared;
      ASSERT_EQ(tree.density.possible_collision_cells[n], expected) << "node " << n << " step " << step;
    }
    EXPECT_GT(compared, static_cast<int>(boxes.size()) / 2);
  }
}

TEST(Annotate, ReportsProgressUpToTheTotal) {
  const auto bvh = Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 16, 8));
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  AnnotateOptions options;
  options.progress = [&](std::size_t done, std::size_t total) { calls.emplace_back(done, total); };
  AnnotateStats stats;
  annotate_adb(bvh, 2, options, &stats);
  ASSERT_FALSE(calls.empty());
  EXPECT_EQ(calls.back().first, stats.triangle_node_pairs);
  EXPECT_EQ(calls.back().second, stats.triangle_node_pairs);
  for (std::size_t i = 1; i < calls.size(); ++i) EXPECT_LE(calls[i - 1].first, calls[i].first);
}

TEST(Annotate, RejectsBadInputWithAClearMessage) {
  const std::vector<TrianglePoints> t{{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)}};
  const std::vector<Box> boxes{box_of(Vec3(0, 0, 0), Vec3(1, 1, 0))};
  const std::vector<Range> ranges{{0, 1}};
  auto expect_error = [](auto&& call, const std::string& fragment) {
    try {
      call();
      ADD_FAILURE() << "no exception; expected one mentioning '" << fragment << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  AnnotateOptions options;
  expect_error([&] { annotate_counts(boxes, ranges, t, 0, options); }, "grid");
  expect_error([&] { annotate_counts(boxes, ranges, t, 7, options); }, "grid");
  for (const double tau : {-1e-300, -1.0, std::nan("")}) {
    AnnotateOptions bad;
    bad.tau = tau;
    expect_error([&] { annotate_counts(boxes, ranges, t, 2, bad); }, "tau");
  }
  expect_error([&] { annotate_counts(boxes, std::vector<Range>{}, t, 2, options); }, "node ranges");
  expect_error([&] { annotate_counts(boxes, std::vector<Range>{{0, 2}}, t, 2, options); }, "outside");
  expect_error([&] { annotate_counts(std::vector<Box>{Box{}}, ranges, t, 2, options); }, "bounding box");
  const std::vector<TrianglePoints> nan_triangle{{Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0), Vec3(0, 1, 0)}};
  expect_error([&] { annotate_counts(boxes, ranges, nan_triangle, 2, options); }, "non-finite");
  // In frames: a frame that is not finite (a corrupt volume) for a node holding triangles, or a size
  // mismatch.
  const std::vector<OrientedBox> nan_frame{{Mat3::Constant(std::nan("")), Vec3::Zero(), Vec3::Ones()}};
  expect_error([&] { annotate_counts_in_frames(nan_frame, ranges, t, 2, options); }, "non-finite frame");
  expect_error([&] { annotate_counts_in_frames(nan_frame, std::vector<Range>{}, t, 2, options); },
               "node ranges");

  auto bvh = Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 8, 4));
  auto stripped = Bvh<Aabb>::from_parts(bvh.nodes(), bvh.volumes(), bvh.triangle_ids());
  expect_error([&] { annotate_adb(stripped, 2); }, "no polygons");
}

}  // namespace
}  // namespace bvhlab

// A tree without density pays nothing: the compiler checks it for every registered kind of volume.
#include "support/random_draws.hpp"
#include "volumes/dop24.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"
static_assert(std::is_empty_v<bvhlab::NoDensity::Storage>);
static_assert(bvhlab::no_density_is_free<bvhlab::Aabb>);
static_assert(bvhlab::no_density_is_free<bvhlab::Dop24>);
static_assert(bvhlab::no_density_is_free<bvhlab::Obb>);
static_assert(bvhlab::no_density_is_free<bvhlab::RestrictedBox>);
