// The rectangle swept sphere (volumes/rss.hpp): fit and merge hold their points; the rectangle distance
// agrees with CGAL's exact distance between the rectangles (each as two triangles) on random and adversarial
// families; overlap() and distance_lower_bound() are conservative against that exact distance, rounding
// included, also far from the origin, and the bound is close to it; and trees of RSSs answer distance and
// intersection queries as a brute force over every triangle pair does. The RSS does not ship yet
// (volumes/shipped.hpp), so the typed suites do not run over it: this file checks what they would.
#include "bvh/bvh.hpp"
#include "bvh/triangle_distance.hpp"
#include "support/brute_force_distance.hpp"
#include "support/generated_meshes.hpp"
#include "support/random_clouds.hpp"
#include "traversal/distance.hpp"
#include "traversal/exact.hpp"
#include "volumes/obb.hpp"
#include "volumes/rss.hpp"
#include "volumes/sphere.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/squared_distance_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace bvhlab {
namespace {

using testing::brute_force_distance;
using testing::draw_vec3;
using testing::log_uniform;
using testing::random_direction;
using testing::random_rotation;
using testing::uniform;
using Rng = std::mt19937_64;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Full counts in optimised builds; a tenth where assertions are on (Debug: CGAL checks everything).
#ifdef NDEBUG
constexpr int kScale = 1;
#else
constexpr int kScale = 10;
#endif

static_assert(BoundingVolume<Rss> && DistanceVolume<Rss>);
static_assert(!FramedVolume<Rss>, "an RSS is no box: the ADB density keeps its axis-aligned grid");
static_assert(std::is_trivially_copyable_v<Rss> && std::is_standard_layout_v<Rss> && sizeof(Rss) == 40);

// ---------------------------------------------------------------------------------------------------------
// Random draws.

bool chance(Rng& rng, double p) {
  return uniform(rng, 0, 1) < p;
}
/// A random direction times a length uniform in [lo, hi].
Vec3 random_offset(Rng& rng, double lo, double hi) {
  const double length = uniform(rng, lo, hi);
  return length * random_direction(rng);
}
/// s frame.col(0) + t frame.col(1) with s, t uniform in [lo, hi]: a point of the frame's xy plane.
Vec3 in_plane(Rng& rng, const Mat3& frame, double lo, double hi) {
  const double s = uniform(rng, lo, hi);
  const double t = uniform(rng, lo, hi);
  return s * frame.col(0) + t * frame.col(1);
}
/// (1, a, b) with a, b log-uniform in [10^lo, 1].
Vec3 stretch(Rng& rng, double lo) {
  const double a = log_uniform(rng, lo, 0);
  const double b = log_uniform(rng, lo, 0);
  return {1, a, b};
}
double random_sign(Rng& rng) {
  return rng() % 2 ? 1.0 : -1.0;
}
/// Each coordinate +-1e6 (times 1 to 1.1): far from the origin, where absolute rounding is about 1e-10.
Vec3 far_point(Rng& rng) {
  Vec3 far;
  for (int k = 0; k < 3; ++k) {
    const double sign = random_sign(rng);
    far[k] = sign * 1e6 * uniform(rng, 1, 1.1);
  }
  return far;
}

enum class Shape { Cloud, Flat, Collinear, Single, Repeated, Grid };
constexpr std::array<Shape, 6> kShapes = {Shape::Cloud,  Shape::Flat,     Shape::Collinear,
                                          Shape::Single, Shape::Repeated, Shape::Grid};
const char* shape_name(Shape s) {
  switch (s) {
    case Shape::Cloud:
      return "cloud";
    case Shape::Flat:
      return "flat";
    case Shape::Collinear:
      return "collinear";
    case Shape::Single:
      return "single point";
    case Shape::Repeated:
      return "repeated point";
    case Shape::Grid:
      return "grid";
  }
  return "?";
}

/// Points of extent about `scale` around `center`, in a random orientation: a stretched cloud, a flat one, a
/// line, one point, one point many times, or the 27 points of a box's grid (symmetric: PCA is poor there).
std::vector<Vec3> draw_points(Rng& rng, Shape shape, const Vec3& center, double scale) {
  std::normal_distribution<double> normal;
  const Mat3 frame = random_rotation(rng);
  std::vector<Vec3> local;
  const int count = 2 + int(rng() % 40);
  switch (shape) {
    case Shape::Cloud: {
      const Vec3 spread = stretch(rng, -2);
      for (int i = 0; i < count; ++i) local.push_back(draw_vec3(normal, rng).cwiseProduct(spread));
      break;
    }
    case Shape::Flat: {
      const Vec3 spread(1, log_uniform(rng, -2, 0), 0);
      for (int i = 0; i < count; ++i) local.push_back(draw_vec3(normal, rng).cwiseProduct(spread));
      break;
    }
    case Shape::Collinear:
      for (int i = 0; i < count; ++i) local.emplace_back(normal(rng), 0, 0);
      break;
    case Shape::Single:
      local.emplace_back(0, 0, 0);
      break;
    case Shape::Repeated:
      local.assign(count, draw_vec3(normal, rng) * 0.1);
      break;
    case Shape::Grid: {
      const Vec3 half = stretch(rng, -1);
      for (int i = -1; i <= 1; ++i)
        for (int j = -1; j <= 1; ++j)
          for (int k = -1; k <= 1; ++k) local.push_back(half.cwiseProduct(Vec3(i, j, k)));
      break;
    }
  }
  std::vector<Vec3> points;
  for (const Vec3& p : local) points.push_back(center + scale * (frame * p));
  return points;
}

/// A point set of a random shape and scale (1e-3 to 1e3), near the origin or (one in four) around 1e6.
std::vector<Vec3> random_points(Rng& rng) {
  const Shape shape = kShapes[rng() % kShapes.size()];
  const double scale = log_uniform(rng, -3, 3);
  const Vec3 center = chance(rng, 0.25) ? far_point(rng) : Vec3(scale * random_offset(rng, 0, 3));
  return draw_points(rng, shape, center, scale);
}

/// The points of an RSS: rectangle points moved by up to the radius (shrunk by `inside`) in any direction,
/// including the 26 directions to the corners, edges and faces of its box, where the volume is rounded.
std::vector<Vec3> sample_volume(Rng& rng, const Rss& v, int random_count, double inside) {
  const rss::Rectangle r = v.rectangle();
  const Vec3 normal = r.axis0.cross(r.axis1);
  const double radius = double(v.radius) * inside;
  std::vector<Vec3> out;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const Vec3 direction = dx * r.axis0 + dy * r.axis1 + dz * normal;
            const Vec3 on_rectangle = r.center + i * r.half0 * r.axis0 + j * r.half1 * r.axis1;
            out.push_back(direction.isZero() ? on_rectangle
                                             : Vec3(on_rectangle + radius * direction.normalized()));
          }
  for (int k = 0; k < random_count; ++k) {
    const double s = uniform(rng, -1, 1);
    const double t = uniform(rng, -1, 1);
    const double depth = std::cbrt(uniform(rng, 0, 1));
    const Vec3 on_rectangle = r.center + s * r.half0 * r.axis0 + t * r.half1 * r.axis1;
    out.push_back(on_rectangle + radius * depth * random_direction(rng));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------
// Exact ground truth: CGAL's distance between the rectangles, each as the two triangles its corners span.

using K = CGAL::Exact_predicates_exact_constructions_kernel;

std::array<Vec3, 4> corners_of(const rss::Rectangle& r) {
  const Vec3 u = r.half0 * r.axis0, v = r.half1 * r.axis1;
  return {r.center - u - v, r.center + u - v, r.center + u + v, r.center - u + v};
}

std::array<K::Triangle_3, 2> exact_triangles(const std::array<Vec3, 4>& c) {
  const auto point = [](const Vec3& x) { return K::Point_3(x.x(), x.y(), x.z()); };
  return {K::Triangle_3(point(c[0]), point(c[1]), point(c[2])),
          K::Triangle_3(point(c[0]), point(c[2]), point(c[3]))};
}

/// The exact distance between the quadrilaterals with these corners (to 1e-15 relative). CGAL treats a
/// degenerate triangle as the segment or point it is.
double exact_distance(const std::array<Vec3, 4>& a, const std::array<Vec3, 4>& b) {
  const auto ta = exact_triangles(a), tb = exact_triangles(b);
  K::FT best = -1;
  for (const auto& p : ta)
    for (const auto& q : tb) {
      const K::FT d = CGAL::squared_distance(p, q);
      if (best < 0 || d < best) best = d;
      if (best == 0) return 0;
    }
  K::FT::set_relative_precision_of_to_double(1e-15);
  return std::sqrt(CGAL::to_double(best));
}

double exact_distance(const rss::Rectangle& a, const rss::Rectangle& b) {
  return exact_distance(corners_of(a), corners_of(b));
}

/// B's rectangle moved by the pose, into A's frame.
rss::Rectangle placed(const rss::Rectangle& r, const RigidTransform& pose) {
  return {pose.apply(r.center), pose.rotation * r.axis0, pose.rotation * r.axis1, r.half0, r.half1};
}

double largest_coordinate(const rss::Rectangle& a, const rss::Rectangle& b) {
  double m = 0;
  for (const auto* r : {&a, &b})
    for (const Vec3& c : corners_of(*r)) m = std::max(m, c.cwiseAbs().maxCoeff());
  return m;
}

// ---------------------------------------------------------------------------------------------------------
// Fit.

// The largest distance from a point to the fitted rectangle: the radius fit() needed before rounding.
double needed_radius(const Rss& v, const std::vector<Vec3>& points) {
  const rss::Rectangle r = v.rectangle();
  double needed = 0;
  for (const Vec3& p : points)
    needed = std::max(needed, rss::rectangle_distance(r, {p, Vec3::UnitX(), Vec3::UnitY(), 0, 0}));
  return needed;
}

TEST(RssFit, HoldsEveryPointOfEveryShapeScaleAndPlace) {
  Rng rng(1);
  int cases = 0;
  for (Shape shape : kShapes)
    for (double scale : {1e-12, 1e-6, 1e-3, 1.0, 1e3, 1e6, 1e9})
      for (int place = 0; place < 3; ++place)
        for (int k = 0; k < 40; ++k) {
          // At the origin, a few sizes away, or around 1e6.
          const Vec3 center = place == 0   ? Vec3::Zero()
                              : place == 1 ? Vec3(scale * random_offset(rng, 0, 5))
                                           : far_point(rng);
          const std::vector<Vec3> points = draw_points(rng, shape, center, scale);
          const Rss v = Rss::fit(points);
          ++cases;
          ASSERT_FALSE(v.empty());
          ASSERT_TRUE(v.valid());
          const Box box = v.bounding_box();
          for (const Vec3& p : points) {
            ASSERT_TRUE(v.contains(p)) << shape_name(shape) << ", scale " << scale << ", place " << place;
            ASSERT_TRUE(box.contains(p)) << shape_name(shape) << ", scale " << scale << ", place " << place;
          }
          // Not vacuous: the radius is what the farthest point needs, plus the rounding the header allows
          // (2^-21 of the half-diagonal, 2^-24 of |c| and some ulps), and flat or thinner sets get no more
          // than that.
          const double half_diagonal = std::hypot(double(v.half[0]), double(v.half[1]));
          const double rounding =
              0x1p-20 * half_diagonal + 0x1p-23 * (v.rectangle().center.norm() + center.norm()) + 1e-40;
          EXPECT_LE(v.radius, needed_radius(v, points) * (1 + 1e-6) + rounding)
              << shape_name(shape) << ", scale " << scale << ", place " << place;
          if (shape != Shape::Cloud && shape != Shape::Grid) {
            EXPECT_LE(v.radius, 1e-9 * scale + rounding) << shape_name(shape) << ", scale " << scale;
          }
          if (shape == Shape::Collinear || shape == Shape::Single || shape == Shape::Repeated) {
            EXPECT_LE(std::min(v.half[0], v.half[1]), 1e-9 * scale + rounding) << shape_name(shape);
          }
        }
  EXPECT_EQ(cases, 6 * 7 * 3 * 40);
}

TEST(RssFit, EmptyAndNonFinite) {
  EXPECT_TRUE(Rss::fit({}).empty());
  EXPECT_EQ(Rss::fit({}).volume(), 0);
  EXPECT_FALSE(Rss::fit({}).contains(Vec3::Zero()));
  const std::vector<Vec3> bad = {Vec3::Zero(), Vec3(std::nan(""), 0, 0)};
  EXPECT_THROW(Rss::fit(bad), std::invalid_argument);
  const Rss v = Rss::fit(std::vector<Vec3>{Vec3(1, 2, 3)});
  EXPECT_EQ(Rss::merge(v, Rss{}).center, v.center);
  EXPECT_EQ(Rss::merge(Rss{}, v).radius, v.radius);
}

// The volume is Steiner's formula for the RSS stored, checked against counting random points of its bounding
// box that contains() accepts; every sampled point of the volume lies in the bounding box. And the volume
// is no more than the OBB's fitted to the same points times the rounded corners' worst case (a cube-like
// set: (8 + 4 pi + 4/3 pi) / 8, about 3.1), and for flat sets about the OBB's.
TEST(RssFit, VolumeAndBoundingBoxAreConsistent) {
  Rng rng(2);
  std::vector<double> ratios;
  for (int k = 0; k < 300; ++k) {
    const Shape shape = k % 2 ? Shape::Cloud : Shape::Grid;
    const std::vector<Vec3> points = draw_points(rng, shape, Vec3(uniform(rng, -2, 2), 0, 0), 1);
    const Rss v = Rss::fit(points);
    const Box box = v.bounding_box();
    for (const Vec3& x : sample_volume(rng, v, 50, 1 - 1e-9)) ASSERT_TRUE(box.contains(x)) << "case " << k;
    int inside = 0;
    constexpr int kSamples = 20000;
    for (int s = 0; s < kSamples; ++s) {
      Vec3 x;
      for (int c = 0; c < 3; ++c) x[c] = uniform(rng, box.min[c], box.max[c]);
      inside += v.contains(x);
    }
    const double estimate = box.volume() * inside / kSamples;
    const double sigma = box.volume() * std::sqrt(0.25 / kSamples);
    ASSERT_NEAR(v.volume(), estimate, 5 * sigma) << "case " << k;
    ratios.push_back(v.volume() / std::max(Obb::fit(points).volume(), 1e-300));
  }
  std::sort(ratios.begin(), ratios.end());
  EXPECT_LE(ratios.back(), 4.0);
  std::printf("[ measured ] RSS volume / OBB volume on clouds and grids: median %.2f, largest %.2f\n",
              ratios[ratios.size() / 2], ratios.back());
}

// ---------------------------------------------------------------------------------------------------------
// Merge.

TEST(RssMerge, HoldsBothInputs) {
  Rng rng(3);
  int checked = 0, self_merges = 0;
  for (int k = 0; k < 1500; ++k) {
    std::vector<Vec3> pa = random_points(rng), pb = random_points(rng);
    if (chance(rng, 0.2)) pb = draw_points(rng, Shape::Single, pa.front(), 1);  // nested or touching inputs
    const Rss a = Rss::fit(pa), b = Rss::fit(pb);
    const Rss merged = Rss::merge(a, b);
    ASSERT_TRUE(merged.valid());
    for (const Rss* input : {&a, &b})
      for (const Vec3& x : sample_volume(rng, *input, 20, 1 - 1e-9)) {
        if (!input->contains(x)) continue;  // a rounded sample just outside: not the input's
        ++checked;
        ASSERT_TRUE(merged.contains(x)) << "case " << k;
      }
    for (const auto* points : {&pa, &pb})
      for (const Vec3& p : *points) ASSERT_TRUE(merged.contains(p)) << "case " << k;
    // Merging a volume with itself gives about itself, each corner carrying the radius: where the rounding a
    // merge adds (about 2^-21 of the half-diagonal and 2^-24 |c|) is small next to the radius, and not for a
    // square, whose corners leave the frame's in-plane axes to chance.
    const Rss twice = Rss::merge(a, a);
    for (const Vec3& x : sample_volume(rng, a, 5, 1 - 1e-9)) {
      if (a.contains(x)) {
        ASSERT_TRUE(twice.contains(x)) << "case " << k;
      }
    }
    const double added =
        0x1p-20 * std::hypot(double(a.half[0]), double(a.half[1])) + 0x1p-23 * a.rectangle().center.norm();
    const bool square = std::abs(a.half[0] - a.half[1]) < 1e-3 * (a.half[0] + a.half[1]);
    if (!square && added < 1e-4 * a.radius) {
      EXPECT_LE(twice.volume(), 1.001 * a.volume()) << "case " << k;
      ++self_merges;
    }
  }
  EXPECT_GT(checked, 1500 * 2 * 200);
  EXPECT_GT(self_merges, 200);
  std::printf(
      "[ measured ] %d sample points of the inputs held; %d merges of a volume with itself compared\n",
      checked, self_merges);
}

// ---------------------------------------------------------------------------------------------------------
// Rectangle distance against CGAL.

rss::Rectangle rectangle(const Vec3& center, const Mat3& frame, double half0, double half1) {
  return {center, frame.col(0), frame.col(1), half0, half1};
}
/// Half-lengths of about `size`, one in ten 0 (a segment), one in twenty both 0 (a point).
std::array<double, 2> halves(Rng& rng, double size) {
  std::array<double, 2> h = {size * log_uniform(rng, -2, 0), size * log_uniform(rng, -2, 0)};
  if (chance(rng, 0.1)) h[rng() % 2] = 0;
  if (chance(rng, 0.05)) h = {0, 0};
  return h;
}
/// A point of the rectangle: on its face, an edge or a corner.
Vec3 point_of(Rng& rng, const rss::Rectangle& r) {
  double s = uniform(rng, -1, 1), t = uniform(rng, -1, 1);
  const int where = int(rng() % 4);
  if (where == 1) s = rng() % 2 ? 1 : -1;
  if (where == 2) t = rng() % 2 ? 1 : -1;
  if (where == 3) s = rng() % 2 ? 1 : -1, t = rng() % 2 ? 1 : -1;
  return r.center + s * r.half0 * r.axis0 + t * r.half1 * r.axis1;
}
/// A rotation by `angle` about a random axis.
Mat3 tilt(Rng& rng, double angle) {
  return Eigen::AngleAxisd(angle, random_direction(rng)).toRotationMatrix();
}

struct RectanglePair {
  rss::Rectangle a, b;
  std::optional<double> known;  // the distance by construction, where the family gives it
};
using RectangleFamily = std::function<RectanglePair(Rng&)>;

RectanglePair general(Rng& rng) {
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const Mat3 frame = random_rotation(rng), b_frame = random_rotation(rng);
  const Vec3 offset = random_offset(rng, 0, 2.5);
  return {rectangle(Vec3::Zero(), frame, ha[0], ha[1]), rectangle(offset, b_frame, hb[0], hb[1]), {}};
}
/// B's axes are A's (or swapped, or reversed), at a random height over A's plane (one in three: in it).
RectanglePair parallel(Rng& rng) {
  const Mat3 frame = random_rotation(rng);
  Mat3 b_frame = frame;
  if (chance(rng, 0.5)) b_frame.col(0).swap(b_frame.col(1));
  if (chance(rng, 0.5)) b_frame.col(0) = -b_frame.col(0);
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const double height = chance(rng, 0.33) ? 0.0 : uniform(rng, -1, 1);
  const Vec3 offset = in_plane(rng, frame, -2.5, 2.5) + height * frame.col(2);
  return {rectangle(Vec3::Zero(), frame, ha[0], ha[1]), rectangle(offset, b_frame, hb[0], hb[1]), {}};
}
/// Both in one plane, B turned in it by a random angle (one in four: a multiple of a right angle).
RectanglePair coplanar(Rng& rng) {
  const Mat3 frame = random_rotation(rng);
  const double angle = chance(rng, 0.25) ? std::numbers::pi / 2 * double(rng() % 4) : uniform(rng, 0, 7);
  const Mat3 b_frame = frame * Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix();
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const Vec3 offset = in_plane(rng, frame, -2.5, 2.5);
  return {rectangle(Vec3::Zero(), frame, ha[0], ha[1]), rectangle(offset, b_frame, hb[0], hb[1]), {}};
}
/// B is A's frame tilted by 1e-13 to 1e-2 radians, close to A's plane: nearly parallel faces and edges.
RectanglePair nearly_parallel(Rng& rng) {
  const Mat3 frame = random_rotation(rng);
  const Mat3 b_frame = tilt(rng, log_uniform(rng, -13, -2)) * frame;
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const double height = chance(rng, 0.5) ? 0.0 : log_uniform(rng, -12, -1);
  const Vec3 offset = in_plane(rng, frame, -2, 2) + height * frame.col(2);
  return {rectangle(Vec3::Zero(), frame, ha[0], ha[1]), rectangle(offset, b_frame, hb[0], hb[1]), {}};
}
/// B passes through a point of A (a face, edge or corner point): distance 0.
RectanglePair crossing(Rng& rng) {
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const Mat3 frame = random_rotation(rng), b_frame = random_rotation(rng);
  const rss::Rectangle a = rectangle(Vec3::Zero(), frame, ha[0], ha[1]);
  rss::Rectangle b = rectangle(Vec3::Zero(), b_frame, hb[0], hb[1]);
  const Vec3 on_b = point_of(rng, b);
  b.center = point_of(rng, a) - on_b;
  return {a, b, 0.0};
}
/// B's lowest corner (along A's normal) at height D over a point of A's face, the rest of B higher still:
/// distance D (0 included: touching).
RectanglePair corner_over_face(Rng& rng) {
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const Mat3 frame = random_rotation(rng), b_frame = random_rotation(rng);
  const rss::Rectangle a = rectangle(Vec3::Zero(), frame, ha[0], ha[1]);
  rss::Rectangle b = rectangle(Vec3::Zero(), b_frame, hb[0], hb[1]);
  const Vec3 normal = frame.col(2);
  const auto c = corners_of(b);
  const Vec3 lowest = *std::min_element(
      c.begin(), c.end(), [&](const Vec3& x, const Vec3& y) { return x.dot(normal) < y.dot(normal); });
  const double height = chance(rng, 0.3) ? 0.0 : log_uniform(rng, -9, 0);
  const double s = uniform(rng, -1, 1);
  const double t = uniform(rng, -1, 1);
  const Vec3 over = s * ha[0] * frame.col(0) + t * ha[1] * frame.col(1);
  b.center = over + height * normal - lowest;
  return {a, b, height};
}
/// An edge of B crossing an edge of A (touching), or passing it at up to 0.1 in a random direction.
RectanglePair edge_over_edge(Rng& rng) {
  const auto ha = halves(rng, 1), hb = halves(rng, 1);
  const Mat3 frame = random_rotation(rng), b_frame = random_rotation(rng);
  const rss::Rectangle a = rectangle(Vec3::Zero(), frame, ha[0], ha[1]);
  rss::Rectangle b = rectangle(Vec3::Zero(), b_frame, hb[0], hb[1]);
  const double side_a = random_sign(rng), along_a = uniform(rng, -1, 1);
  const double side_b = random_sign(rng), along_b = uniform(rng, -1, 1);
  const Vec3 on_a = a.center + side_a * a.half0 * a.axis0 + along_a * a.half1 * a.axis1;
  const Vec3 on_b = b.center + side_b * b.half1 * b.axis1 + along_b * b.half0 * b.axis0;
  const double miss = chance(rng, 0.5) ? 0.0 : log_uniform(rng, -9, -1);
  b.center = on_a - on_b + miss * random_direction(rng);
  return {a, b, {}};
}
/// Any family's pair, scaled by 1e-6 to 1e6 and moved to coordinates around 1e6.
RectanglePair far_and_scaled(Rng& rng, const RectangleFamily& family) {
  RectanglePair pair = family(rng);
  const double scale = log_uniform(rng, -6, 6);
  const Vec3 offset = far_point(rng);
  for (rss::Rectangle* r : {&pair.a, &pair.b}) {
    r->center = offset + scale * r->center;
    r->half0 *= scale;
    r->half1 *= scale;
  }
  if (pair.known) pair.known = *pair.known * scale;
  return pair;
}

struct FamilyStats {
  int pairs = 0, zero = 0;
  double worst = 0;        // |computed - exact| / size
  double worst_share = 0;  // |computed - exact| / tolerance
  std::string first_failure;
};

/// The computed distance within 1e-12 of the pair's size (its offset and half-lengths) of CGAL's for the
/// rounded corners, plus a few ulps of the coordinates (the corners' own rounding, which far from the origin
/// dominates); also where the family knows the answer, and symmetric.
void check_family(const char* name, std::uint64_t seed, int count, const RectangleFamily& family) {
  Rng rng(seed);
  FamilyStats stats;
  for (int k = 0; k < count / kScale; ++k) {
    const RectanglePair pair = family(rng);
    const double computed = rss::rectangle_distance(pair.a, pair.b);
    const double exact = exact_distance(pair.a, pair.b);
    const double size =
        (pair.a.center - pair.b.center).norm() + pair.a.half0 + pair.a.half1 + pair.b.half0 + pair.b.half1;
    const double tolerance = 1e-12 * size + 16 * kEps * largest_coordinate(pair.a, pair.b);
    ++stats.pairs;
    stats.zero += exact == 0;
    if (size > 0) stats.worst = std::max(stats.worst, std::abs(computed - exact) / size);
    if (tolerance > 0)
      stats.worst_share = std::max(stats.worst_share, std::abs(computed - exact) / tolerance);
    const double swapped = rss::rectangle_distance(pair.b, pair.a);
    const bool wrong = !(std::abs(computed - exact) <= tolerance) ||
                       !(std::abs(swapped - exact) <= tolerance) ||
                       (pair.known && !(std::abs(computed - *pair.known) <= tolerance + 1e-12 * size));
    if (wrong && stats.first_failure.empty()) {
      char text[256];
      std::snprintf(text, sizeof text,
                    "pair %d: computed %.17g, swapped %.17g, exact %.17g, known %.17g, size %g", k, computed,
                    swapped, exact, pair.known.value_or(-1), size);
      stats.first_failure = text;
    }
  }
  std::printf("[ family ] %-22s %5d pairs, %4d touching, worst |error| / size %.1e, / tolerance %.1e\n", name,
              stats.pairs, stats.zero, stats.worst, stats.worst_share);
  EXPECT_TRUE(stats.first_failure.empty()) << name << ": " << stats.first_failure;
}

/// Every family above, by name.
std::vector<std::pair<const char*, RectangleFamily>> rectangle_families() {
  return {{"general", general},
          {"parallel", parallel},
          {"coplanar", coplanar},
          {"nearly parallel", nearly_parallel},
          {"crossing", crossing},
          {"corner over face", corner_over_face},
          {"edge over edge", edge_over_edge}};
}

TEST(RssRectangleDistance, AgreesWithCgal) {
  const auto families = rectangle_families();
  std::uint64_t seed = 100;
  for (const auto& [name, family] : families) {
    check_family(name, ++seed, 1500, family);
    const std::string far = std::string(name) + ", far";
    const RectangleFamily& near = family;  // clang before 16 cannot capture a structured binding
    check_family(far.c_str(), ++seed, 300, [&near](Rng& rng) { return far_and_scaled(rng, near); });
  }
}

// The separation step (rss::rectangle_separation, what the distance bound tries first): on every family
// never above CGAL's distance by more than the distance's own tolerance, and, on pairs apart by more than
// twice their half-lengths, close to it. The share is measured and printed (median 1.0000, smallest 0.99);
// the floor of 0.8 for the median fails a gap along a fixed axis or one not divided by the direction's
// length.
TEST(RssRectangleSeparation, NeverAboveTheDistanceAndCloseWhenApart) {
  const auto families = rectangle_families();
  Rng rng(4242);
  std::vector<double> shares;
  int positive = 0, pairs = 0;
  for (const auto& [name, family] : families) {
    for (int k = 0; k < 600 / kScale; ++k, ++pairs) {
      const RectanglePair pair = chance(rng, 0.2) ? far_and_scaled(rng, family) : family(rng);
      const double separation = rss::rectangle_separation(pair.a, pair.b);
      const double exact = exact_distance(pair.a, pair.b);
      const double size =
          (pair.a.center - pair.b.center).norm() + pair.a.half0 + pair.a.half1 + pair.b.half0 + pair.b.half1;
      const double tolerance = 1e-12 * size + 16 * kEps * largest_coordinate(pair.a, pair.b);
      ASSERT_GE(separation, 0) << name << " pair " << k;
      ASSERT_LE(separation, exact + tolerance) << name << " pair " << k << ": exact " << exact;
      positive += separation > 0;
      const double sizes = pair.a.half0 + pair.a.half1 + pair.b.half0 + pair.b.half1;
      if (exact > 2 * sizes && exact > 0) shares.push_back(separation / exact);
    }
  }
  std::sort(shares.begin(), shares.end());
  ASSERT_GT(shares.size(), 50U);
  const double median = shares[shares.size() / 2];
  EXPECT_GT(median, 0.8);
  std::printf(
      "[ measured ] %d pairs, %d with a gap; apart by more than their sizes (%zu): separation / "
      "distance median %.4f, smallest %.4f\n",
      pairs, positive, shares.size(), median, shares.front());
}

TEST(RssRectangleDistance, HandWrittenCases) {
  const Mat3 id = Mat3::Identity();
  const auto at = [&](const Vec3& c, double h0, double h1) { return rectangle(c, id, h0, h1); };
  // Stacked squares, one over the other: their planes' distance.
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 1), at({0.5, 0.5, 2}, 1, 1)), 2);
  // Side by side in one plane, 1 apart; overlapping in one plane; one inside the other.
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 1), at({3, 0, 0}, 1, 1)), 1);
  EXPECT_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 1), at({1.5, 0.5, 0}, 1, 1)), 0);
  EXPECT_EQ(rss::rectangle_distance(at({0, 0, 0}, 2, 2), at({0.5, 0.5, 0}, 1, 1)), 0);
  // Corner to corner, diagonally: sqrt(2).
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 1), at({3, 3, 0}, 1, 1)), std::sqrt(2.0));
  // A vertical square through the middle of a horizontal one: they cross.
  const Mat3 upright = Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix();
  EXPECT_LE(rss::rectangle_distance(at({0, 0, 0}, 1, 1), rectangle({0, 0, 0}, upright, 0.5, 0.5)), 1e-16);
  // The same lifted by 3 over its own lower edge: 2.5.
  EXPECT_NEAR(rss::rectangle_distance(at({0, 0, 0}, 1, 1), rectangle({0, 0, 3}, upright, 0.5, 0.5)), 2.5,
              1e-15);
  // Points and segments.
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 0, 0), at({3, 4, 0}, 0, 0)), 5);
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 0), at({0, 0, 1}, 0, 1)), 1);
  EXPECT_DOUBLE_EQ(rss::rectangle_distance(at({0, 0, 0}, 1, 1), at({0.2, 0.3, -4}, 0, 0)), 4);
}

// ---------------------------------------------------------------------------------------------------------
// overlap() and distance_lower_bound() against the exact distance of the swept rectangles.

/// Two fitted volumes and the pose mapping B's frame into A's.
struct VolumePair {
  Rss a, b;
  RigidTransform pose;
};

/// The exact distance between the two volumes as the pair lies: the rectangles' less both radii (at least
/// 0). `magnitude` receives the largest coordinate the reference rounded (its corners, B's before the pose
/// and after).
double exact_volume_distance(const VolumePair& v, double* magnitude = nullptr) {
  const rss::Rectangle ra = v.a.rectangle(), rb = v.b.rectangle(), rb_placed = placed(rb, v.pose);
  if (magnitude)
    *magnitude = std::max({largest_coordinate(ra, rb_placed), largest_coordinate(rb, rb),
                           v.pose.translation.cwiseAbs().maxCoeff()});
  // B's corners are moved as points, as the volumes' placement moves them.
  std::array<Vec3, 4> b_corners = corners_of(rb);
  for (Vec3& c : b_corners) c = v.pose.apply(c);
  return exact_distance(corners_of(ra), b_corners) - double(v.a.radius) - double(v.b.radius);
}

/// Volumes fitted to random sets, B's pose random, then moved along a random direction to where the swept
/// volumes just touch (found by bisection on rss::rectangle_distance, itself checked against CGAL above),
/// and from there by `shift` times the pair's size: negative overlaps, positive separates.
std::optional<VolumePair> near_contact(Rng& rng, double shift) {
  const std::vector<Vec3> pa = random_points(rng), pb = random_points(rng);
  VolumePair v{Rss::fit(pa), Rss::fit(pb), {}};
  v.pose.rotation = random_rotation(rng);
  const Vec3 direction = random_direction(rng);
  const Vec3 start = v.a.rectangle().center - v.pose.rotation * v.b.rectangle().center;
  const double size = v.a.bounding_box().extent().norm() + v.b.bounding_box().extent().norm();
  const auto gap = [&](double s) {
    RigidTransform pose = v.pose;
    pose.translation = start + s * direction;
    return rss::rectangle_distance(v.a.rectangle(), placed(v.b.rectangle(), pose)) - double(v.a.radius) -
           double(v.b.radius);
  };
  double lo = 0, hi = 4 * size + 1e-300;
  if (gap(lo) > 0 || gap(hi) <= 0) return std::nullopt;
  for (int step = 0; step < 200 && lo < hi; ++step) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) break;
    (gap(mid) <= 0 ? lo : hi) = mid;
  }
  v.pose.translation = start + (hi + shift * size) * direction;
  return v;
}

TEST(RssOverlap, ConservativeAndTightAgainstTheExactDistance) {
  Rng rng(7);
  int touching = 0, apart = 0, cases = 0;
  double loosest = 0;  // largest exact distance (over the pair's size) of a pair overlap() says overlaps
  for (int k = 0; k < 3000 / kScale; ++k) {
    static constexpr double kShifts[] = {-1e-3, -1e-9, -1e-13, 0, 1e-13, 1e-9, 1e-6, 1e-3, 0.5};
    const double shift = kShifts[k % std::size(kShifts)];
    const auto v = near_contact(rng, shift);
    if (!v) continue;
    ++cases;
    double magnitude = 0;
    const double exact = exact_volume_distance(*v, &magnitude);
    const auto context = Rss::make_context(v->pose);
    const bool overlap = Rss::overlap(v->a, v->b, context);
    const double bound = Rss::distance_lower_bound(v->a, v->b, context);
    // Conservative: where the volumes share a point (CGAL says so, for the rectangles as rounded), true.
    if (exact <= 0) {
      ++touching;
      ASSERT_TRUE(overlap) << "case " << k << ", shift " << shift << ": exact distance " << exact;
    } else {
      ++apart;
    }
    // The bound never exceeds the exact distance (the reference's corners round by a few ulps of the
    // coordinates), and it is 0 exactly where overlap() is true.
    ASSERT_LE(bound, std::max(0.0, exact) + 8 * kEps * magnitude) << "case " << k << ", shift " << shift;
    if (overlap) {
      ASSERT_EQ(bound, 0) << "case " << k;
    }
    if (bound > 0) {
      ASSERT_FALSE(overlap) << "case " << k;
    }
    // Not vacuous: overlap() answers true only within its slack (a few hundred ulps of the magnitudes).
    const double size = v->a.bounding_box().extent().norm() + v->b.bounding_box().extent().norm();
    if (overlap) {
      ASSERT_LE(exact, 1e-12 * size + 1e3 * kEps * magnitude) << "case " << k << ", shift " << shift;
      loosest = std::max(loosest, exact / size);
    }
  }
  EXPECT_GT(cases, 2500 / kScale);
  EXPECT_GT(touching, cases / 4);
  EXPECT_GT(apart, cases / 3);
  std::printf(
      "[ measured ] %d poses near contact: %d touching, %d apart; overlap() true at most %.1e sizes apart\n",
      cases, touching, apart, loosest);
}

/// Two boxes that share a point, as tests/volumes/test_far_overlap.cpp draws them: A = [-1, 1]^3, B a unit
/// box around 1e6 in its own frame, and a pose that puts B's corner at most 1e-10 inside A's face x = 1. The
/// RSSs fitted to the boxes' corners contain the boxes, so they must overlap: the placement's rounding
/// there grows with |c_b| and |t| (about 1e6), not with the boxes.
TEST(RssOverlap, KeepsAPointSharedFarFromBsOrigin) {
  Rng rng(21);
  int cases = 0;
  for (int k = 0; k < 5000; ++k) {
    RigidTransform pose;
    pose.rotation = random_rotation(rng);
    Vec3 b_lo;
    for (int c = 0; c < 3; ++c) b_lo[c] = double(float((c == 1 ? -1e6 : 1e6) + uniform(rng, 0, 1)));
    const Vec3 b_hi = b_lo + Vec3::Ones();
    Vec3 y;
    for (int j = 0; j < 3; ++j) y[j] = pose.rotation(0, j) > 0 ? b_lo[j] : b_hi[j];
    const Vec3 x(1 - 1e-10 * uniform(rng, 0, 1), 0.3, -0.2);
    pose.translation = x - pose.rotation * y;
    bool inside = true;
    for (int i = 0; i < 3; ++i) {
      long double v = pose.translation[i];
      for (int j = 0; j < 3; ++j) v += static_cast<long double>(pose.rotation(i, j)) * y[j];
      inside = inside && v >= -1 && v <= 1;
    }
    if (!inside) continue;  // rounding put the corner outside: not a touching case
    std::vector<Vec3> a_corners, b_corners;
    for (int c = 0; c < 8; ++c) {
      a_corners.emplace_back(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1);
      b_corners.emplace_back(c & 1 ? b_hi.x() : b_lo.x(), c & 2 ? b_hi.y() : b_lo.y(),
                             c & 4 ? b_hi.z() : b_lo.z());
    }
    const Rss a = Rss::fit(a_corners), b = Rss::fit(b_corners);
    ++cases;
    const auto context = Rss::make_context(pose);
    ASSERT_TRUE(Rss::overlap(a, b, context)) << "case " << k;
    ASSERT_EQ(Rss::distance_lower_bound(a, b, context), 0) << "case " << k;
  }
  EXPECT_GT(cases, 2500);
}

// Useful, not only valid: on separated pairs the bound is the exact distance of the swept volumes less the
// slack, so its share of that distance is about 1; against the distance of the points the volumes were fitted
// to it is what the volumes' tightness allows (printed; the OBB's median there is 0.94,
// tests/volumes/test_distance_bound.cpp).
TEST(RssDistanceBound, CloseToTheExactDistanceOfSeparatedVolumes) {
  Rng rng(77);
  std::vector<double> to_volumes, to_points;
  for (int k = 0; k < 600 / kScale; ++k) {
    // Clouds of sizes 1e-3 to 1e3 near their frames' origins, apart by 3 to 30 times the sum of their sizes.
    const double scale_a = log_uniform(rng, -3, 3), scale_b = scale_a * log_uniform(rng, -1, 1);
    const std::vector<Vec3> pa = draw_points(rng, Shape::Cloud, scale_a * random_offset(rng, 0, 3), scale_a);
    const std::vector<Vec3> pb = draw_points(rng, Shape::Cloud, scale_b * random_offset(rng, 0, 3), scale_b);
    VolumePair v{Rss::fit(pa), Rss::fit(pb), {}};
    v.pose.rotation = random_rotation(rng);
    const double diameters = v.a.bounding_box().extent().norm() + v.b.bounding_box().extent().norm();
    v.pose.translation = v.a.rectangle().center - v.pose.rotation * v.b.rectangle().center +
                         diameters * random_offset(rng, 3, 30);
    const double exact = exact_volume_distance(v);
    const double bound = Rss::distance_lower_bound(v.a, v.b, Rss::make_context(v.pose));
    ASSERT_GT(exact, 0) << "case " << k;
    ASSERT_LE(bound, exact * (1 + 1e-12)) << "case " << k;
    to_volumes.push_back(bound / exact);
    double points = kInf;
    for (const Vec3& p : pa)
      for (const Vec3& q : pb) points = std::min(points, (p - v.pose.apply(q)).norm());
    to_points.push_back(bound / points);
  }
  std::sort(to_volumes.begin(), to_volumes.end());
  std::sort(to_points.begin(), to_points.end());
  const double median = to_volumes[to_volumes.size() / 2];
  EXPECT_GT(median, 0.9);
  EXPECT_GT(to_volumes.front(), 1 - 1e-9);  // the slack is a few hundred ulps of the magnitudes
  EXPECT_GT(to_points[to_points.size() / 2], 0.9);
  std::printf(
      "[ measured ] bound / exact volume distance: median %.12f, smallest %.12f; bound / point distance: "
      "median %.3f, smallest %.3f\n",
      median, to_volumes.front(), to_points[to_points.size() / 2], to_points.front());
}

// The procedure of tests/volumes/test_distance_bound.cpp (UsefulForSeparatedClouds), with its clouds and
// poses (support/random_clouds.hpp): clouds of 1 to 30 points (stretched, one in ten flat), centre
// distance 3.5 to 10 times the sum of their diameters, point distance at least 3 times it; the bound's share
// of the point distance, for the RSS beside the OBB and the sphere on 3,000 pairs (the README's numbers). Not
// the same pairs with g++: this test draws each centre's and the pose's length before its direction, that one
// in the order the compiler evaluates its operands (g++ the direction first, clang as here).
TEST(RssDistanceBound, UsefulForSeparatedCloudsBesideTheOtherVolumes) {
  Rng rng(77);
  std::vector<double> rss_ratios, obb_ratios, sphere_ratios;
  while (rss_ratios.size() < 3000) {
    const double scale_a = log_uniform(rng, -3, 3), scale_b = scale_a * log_uniform(rng, -1, 1);
    const double offset_a = log_uniform(rng, -1, 2);
    const std::vector<Vec3> a =
        testing::random_cloud(rng, scale_a * offset_a * random_direction(rng), scale_a);
    const double offset_b = log_uniform(rng, -1, 2);
    const std::vector<Vec3> b =
        testing::random_cloud(rng, scale_b * offset_b * random_direction(rng), scale_b);
    const double diameters = testing::diameter_of(a) + testing::diameter_of(b);
    if (diameters == 0) continue;
    RigidTransform pose;
    pose.rotation = testing::random_pose_rotation(rng);
    const double apart = diameters * (3.5 + 6.5 * uniform(rng, 0, 1));
    pose.translation =
        testing::mean_of(a) + apart * random_direction(rng) - pose.rotation * testing::mean_of(b);
    const double distance = testing::point_distance(a, b, pose);
    if (distance < 3 * diameters) continue;
    const double bound = Rss::distance_lower_bound(Rss::fit(a), Rss::fit(b), Rss::make_context(pose));
    ASSERT_LE(bound, distance * (1 + 1e-12)) << "case " << rss_ratios.size();
    ASSERT_GE(bound, 0.4 * distance) << "case " << rss_ratios.size();
    rss_ratios.push_back(bound / distance);
    obb_ratios.push_back(Obb::distance_lower_bound(Obb::fit(a), Obb::fit(b), Obb::make_context(pose)) /
                         distance);
    sphere_ratios.push_back(
        Sphere::distance_lower_bound(Sphere::fit(a), Sphere::fit(b), Sphere::make_context(pose)) / distance);
  }
  for (auto* ratios : {&rss_ratios, &obb_ratios, &sphere_ratios}) std::sort(ratios->begin(), ratios->end());
  const auto median = [](const std::vector<double>& r) { return r[r.size() / 2]; };
  // The RSS's bound is the distance between its volumes, not the gap on a few axes: tighter than the OBB's.
  EXPECT_GT(median(rss_ratios), 0.9);
  EXPECT_GE(median(rss_ratios), median(obb_ratios));
  std::printf(
      "[ measured ] bound / point distance over 3000 separated pairs, median (smallest): rss %.3f (%.3f), "
      "obb %.3f (%.3f), sphere %.3f (%.3f)\n",
      median(rss_ratios), rss_ratios.front(), median(obb_ratios), obb_ratios.front(), median(sphere_ratios),
      sphere_ratios.front());
}

// The same two volumes near the origin and at coordinates around 1e6 (fitted there, then moved back exactly:
// centres minus integer offsets are exact in float) give the same bound within 1e-6 of a distance about 1:
// the slack grows with the magnitudes, but only by a few hundred ulps of them.
TEST(RssDistanceBound, SameAtCoordinatesAround1e6) {
  Rng rng(1000000);
  std::uniform_int_distribution<int> jitter(-1000, 1000);
  const auto far_offset = [&] {
    Vec3 o;
    for (int k = 0; k < 3; ++k) {
      const double sign = random_sign(rng);
      o[k] = sign * (1e6 + jitter(rng));
    }
    return o;
  };
  double worst = 0;
  int compared = 0, positive = 0;
  for (int k = 0; k < 1000; ++k) {
    const std::vector<Vec3> pa = draw_points(rng, Shape::Cloud, Vec3::Zero(), uniform(rng, 0.02, 0.1));
    const std::vector<Vec3> pb = draw_points(rng, Shape::Cloud, Vec3::Zero(), uniform(rng, 0.02, 0.1));
    const Mat3 rotation = random_rotation(rng);
    const RigidTransform pose{rotation, random_offset(rng, 1, 1.5)};
    const Vec3 offset_a = far_offset(), offset_b = far_offset();
    std::vector<Vec3> far_a, far_b;
    for (const Vec3& p : pa) far_a.push_back(p + offset_a);
    for (const Vec3& q : pb) far_b.push_back(q + offset_b);
    RigidTransform far_pose = pose;
    far_pose.translation = pose.translation + offset_a - pose.rotation * offset_b;
    const Rss a_far = Rss::fit(far_a), b_far = Rss::fit(far_b);
    Rss a = a_far, b = b_far;
    for (int c = 0; c < 3; ++c) {
      a.center[c] = rounded_to_float(double(a_far.center[c]) - offset_a[c]);
      b.center[c] = rounded_to_float(double(b_far.center[c]) - offset_b[c]);
      ASSERT_EQ(double(a.center[c]), double(a_far.center[c]) - offset_a[c]) << "moving back is not exact";
      ASSERT_EQ(double(b.center[c]), double(b_far.center[c]) - offset_b[c]) << "moving back is not exact";
    }
    const double near_bound = Rss::distance_lower_bound(a, b, Rss::make_context(pose));
    const double far_bound = Rss::distance_lower_bound(a_far, b_far, Rss::make_context(far_pose));
    const double exact = exact_volume_distance({a, b, pose});
    // Both bound the same distance (the far volumes' rectangles differ by about 1e-10 after the pose).
    ASSERT_LE(near_bound, std::max(0.0, exact)) << "case " << k;
    ASSERT_LE(far_bound, std::max(0.0, exact) + 1e-9) << "case " << k;
    if (exact < 0.5) continue;  // compared where the distance is about 1
    ++compared;
    positive += near_bound > 0;
    const double relative = std::abs(far_bound - near_bound) / exact;
    ASSERT_LE(relative, 1e-6) << "case " << k << ": at the origin " << near_bound << ", at 1e6 " << far_bound;
    worst = std::max(worst, relative);
  }
  EXPECT_GT(compared, 700);
  EXPECT_EQ(positive, compared);  // not vacuous: the bounds compared are positive
  std::printf("[ measured ] largest relative change of the bound at coordinates 1e6: %.2e\n", worst);
}

// The bound and overlap() agree about every pose, also along bisections to the pose where overlap() flips.
TEST(RssDistanceBound, ZeroExactlyWhereOverlapIsTrue) {
  Rng rng(3838);
  int flips = 0, overlapping = 0, positive = 0;
  for (int k = 0; k < 500; ++k) {
    VolumePair v{
        Rss::fit(random_points(rng)), Rss::fit(random_points(rng)), {random_rotation(rng), Vec3::Zero()}};
    const Vec3 direction = random_direction(rng);
    const Vec3 start = v.a.rectangle().center - v.pose.rotation * v.b.rectangle().center;
    const double far = 4 * (v.a.bounding_box().extent().norm() + v.b.bounding_box().extent().norm()) +
                       1e-6 * start.norm() + 1e-300;
    const auto at = [&](double s) {
      RigidTransform pose = v.pose;
      pose.translation = start + s * direction;
      return Rss::make_context(pose);
    };
    if (!Rss::overlap(v.a, v.b, at(0)) || Rss::overlap(v.a, v.b, at(far))) continue;
    double lo = 0, hi = far;
    for (int step = 0; step < 200; ++step) {
      const double mid = 0.5 * (lo + hi);
      if (mid == lo || mid == hi) break;
      const auto context = at(mid);
      const bool overlap = Rss::overlap(v.a, v.b, context);
      const double bound = Rss::distance_lower_bound(v.a, v.b, context);
      if (overlap) {
        ASSERT_EQ(bound, 0) << "case " << k;
      }
      if (bound > 0) {
        ASSERT_FALSE(overlap) << "case " << k;
      }
      overlapping += overlap;
      positive += bound > 0;
      (overlap ? lo : hi) = mid;
    }
    ASSERT_EQ(Rss::distance_lower_bound(v.a, v.b, at(lo)), 0) << "case " << k;
    ++flips;
  }
  EXPECT_GT(flips, 400);
  EXPECT_GT(overlapping, flips * 10);
  EXPECT_GT(positive, flips * 10);
}

// ---------------------------------------------------------------------------------------------------------
// Trees of RSSs: distance and intersection queries against a brute force over every triangle pair.

class RssTree : public ::testing::Test {
 protected:
  Mesh a = testing::make_torus(0.7, 0.25, 12, 6);
  Mesh b = testing::make_random_soup(100, 0.15, 3);
  /// Poses from deep overlap to a few object sizes apart.
  static std::vector<RigidTransform> poses() {
    std::mt19937_64 rng(17);
    std::vector<RigidTransform> out;
    for (int k = 0; k < 24; ++k) out.push_back(testing::random_pose(rng, 0.5 + 0.25 * k));
    return out;
  }
  static void expect_brute_force_answers(const Mesh& a, const Mesh& b,
                                         const std::vector<RigidTransform>& poses, int* touching,
                                         int* apart) {
    const auto tree_a = Bvh<Rss>::build(a), tree_b = Bvh<Rss>::build(b);
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const RigidTransform& pose = poses[k];
      const DistanceResult r = query_distance(tree_a, tree_b, pose);
      const double expected = brute_force_distance(a, b, pose);
      ASSERT_EQ(r.distance, expected) << "pose " << k;
      ASSERT_TRUE(r.exact);
      ASSERT_EQ(r.lower_bound, r.distance);
      // Distance 0 exactly when the exact intersection query finds a contact.
      ASSERT_EQ(r.distance == 0, query_exact(tree_a, tree_b, pose).collides) << "pose " << k;
      (r.distance == 0 ? *touching : *apart) += 1;
    }
  }
};

TEST_F(RssTree, DistanceAndIntersectionAsTheBruteForce) {
  int touching = 0, apart = 0;
  expect_brute_force_answers(a, b, poses(), &touching, &apart);
  EXPECT_GT(touching, 3);
  EXPECT_GT(apart, 8);
}

TEST_F(RssTree, DistanceAndIntersectionAsTheBruteForceFarFromTheOrigin) {
  // Both objects moved 1e6 away, the poses conjugated to match.
  const Vec3 far(1e6, -1e6, 1e6);
  Mesh a_far = a, b_far = b;
  for (Vec3& v : a_far.vertices) v += far;
  for (Vec3& v : b_far.vertices) v += far;
  std::vector<RigidTransform> far_poses;
  for (RigidTransform pose : poses()) {
    pose.translation = pose.translation + far - pose.rotation * far;
    far_poses.push_back(pose);
  }
  int touching = 0, apart = 0;
  expect_brute_force_answers(a_far, b_far, far_poses, &touching, &apart);
  EXPECT_GT(touching, 3);
  EXPECT_GT(apart, 8);
}

TEST_F(RssTree, PrunesMostPairsWhenApart) {
  // Far apart, the bound must spare nearly all of the |A| x |B| triangle pairs a brute force tests.
  const auto tree_a = Bvh<Rss>::build(a), tree_b = Bvh<Rss>::build(b);
  const RigidTransform pose = RigidTransform::translate(Vec3(3, 0.5, 0));
  const DistanceResult r = query_distance(tree_a, tree_b, pose);
  EXPECT_EQ(r.distance, brute_force_distance(a, b, pose));
  EXPECT_LT(r.counters.triangle_tests, a.triangles.size() * b.triangles.size() / 20);
  // And each node holds the triangles below it (in tree order, a node's triangles are one run).
  const std::function<std::pair<std::uint32_t, std::uint32_t>(std::uint32_t)> run = [&](std::uint32_t i) {
    const TreeNode& n = tree_a.node(i);
    if (n.is_leaf()) return std::pair{n.first, n.first + n.count};
    return std::pair{run(n.left()).first, run(n.right()).second};
  };
  for (std::uint32_t i = 0; i < tree_a.nodes().size(); ++i) {
    const auto [first, last] = run(i);
    for (std::uint32_t t = first; t < last; ++t)
      for (const Vec3& v : tree_a.triangles()[t]) ASSERT_TRUE(tree_a.volume(i).contains(v)) << "node " << i;
  }
}

}  // namespace
}  // namespace bvhlab
