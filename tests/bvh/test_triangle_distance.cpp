// Property tests: triangle_distance against CGAL's exact distance (Epeck) on random and adversarial families,
// plus hand-written cases with known answers. Every family uses a fixed seed.
//
// Tolerance. The distance must lie within kRelative * max(exact, size) of CGAL's, size being the longest edge
// of the pair: relative 1e-9 of the distance wherever the distance is not tiny next to the triangles, and
// 1e-9 of the triangles' size where it is (a gap of 1e-15 between unit triangles is below what their
// rounded vertices resolve; no double computation can promise its relative digits). The returned points are
// stored in world coordinates, where each component is rounded to half an ulp of its magnitude: their checks
// add 4 eps * (largest coordinate), which matters only for small pairs far from the origin.
#include "bench/core/generators.hpp"
#include "bvh/triangle_distance.hpp"
#include "bvh/triangle_intersection.hpp"
#include "support/exact_triangles.hpp"
#include "support/random_draws.hpp"
#include "support/triangle_families.hpp"

#include <CGAL/squared_distance_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using namespace testing;  // support/triangle_families.hpp, support/exact_triangles.hpp
using generators::random_unit;
using generators::uniform;
using generators::uniform_point;

constexpr double kRelative = 1e-9;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// ---- exact ground truth ----------------------------------------------------------------------------------

// Degenerate triangles included: CGAL treats them as the segments or points they are (it agreed with the
// distances between their pieces on 40,000 degenerate grid pairs).
double exact_distance(const K::Triangle_3& p, const K::Triangle_3& q) {
  return std::sqrt(to_double(CGAL::squared_distance(p, q), 1e-15));
}

// Whether x lies within `tolerance` of t (decided exactly), and its distance from t to 1e-6, for the report.
// CGAL's Point_3/Triangle_3 distance meets exact zeros in its branch tests for a point at a vertex or on an
// edge, where nearest points mostly are, and then redoes everything in rationals (~40 us); asked piece by
// piece (vertices, edges, the plane over the face) the same answer nearly always stays in interval
// arithmetic.
struct Membership {
  bool inside = false;
  double distance = std::numeric_limits<double>::infinity();
};
Membership within(const Vec3& x, const K::Triangle_3& t, double tolerance) {
  const ExactPoint e = exact_point(x);
  const K::FT limit = K::FT(tolerance) * K::FT(tolerance);
  const double negligible = 1e-6 * tolerance;
  Membership m;
  const auto close_enough = [&](const K::FT& squared) {  // true once a piece is far nearer than the tolerance
    double d = std::sqrt(CGAL::to_interval(squared).second);
    if (d > negligible) d = std::sqrt(to_double(squared, 1e-6));  // a loose interval (a sliver's plane)
    m.distance = std::min(m.distance, d);
    m.inside = m.inside || squared <= limit;
    return m.distance <= negligible;
  };
  for (int k = 0; k < 3; ++k)
    if (close_enough(CGAL::squared_distance(e, t.vertex(k)))) return m;
  for (int k = 0; k < 3; ++k)
    if (close_enough(CGAL::squared_distance(e, K::Segment_3(t.vertex(k), t.vertex(k + 1))))) return m;
  // Over the face (a degenerate triangle has none): the foot of x on the plane is inside every edge.
  const K::Vector_3 n = CGAL::cross_product(t.vertex(1) - t.vertex(0), t.vertex(2) - t.vertex(0));
  if (n == CGAL::NULL_VECTOR) return m;
  for (int k = 0; k < 3; ++k)
    if (CGAL::cross_product(t.vertex(k + 1) - t.vertex(k), e - t.vertex(k)) * n < 0) return m;
  const K::FT height = (e - t.vertex(0)) * n;
  close_enough(height * height / n.squared_length());
  return m;
}

// ---- pairs and their transformations -----------------------------------------------------------------

Mat3 random_rotation(Rng& rng) {
  std::normal_distribution<double> normal;
  return testing::draw_quaternion(normal, rng).normalized().toRotationMatrix();
}

// ---- the checks ----------------------------------------------------------------------------------------

struct FamilyStats {
  std::size_t pairs = 0, intersecting = 0, failures = 0;
  double max_absolute = 0;    // |distance - exact|
  double max_relative = 0;    // the same over exact, where exact > 0
  double max_resolved = 0;    // the same where exact >= 1e-6 size: distances the vertices resolve
  double max_scaled = 0;      // the same over max(exact, size): what the tolerance bounds by kRelative
  double max_point = 0;       // the points' worst miss (gap vs distance, off P, off Q) over max(exact, size)
  std::size_t certified = 0;  // pairs triangles_farther_than certifies farther than half their distance
  std::string first_failure;
};

void fail(FamilyStats& stats, const std::string& what, const Pair& pair, double exact, double computed) {
  if (stats.failures++ > 0) return;
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, " exact=%.17g computed=%.17g", exact, computed);
  stats.first_failure = what + numbers + " P=" + describe(pair.p) + " Q=" + describe(pair.q);
}

// The pair moved rigidly about P's first vertex (rotation and a shift of up to ten sizes).
Pair moved(const Pair& pair, double size, Rng& rng) {
  const Mat3 rotation = random_rotation(rng);
  const Vec3 centre = pair.p[0], shift = uniform_point(rng, -10, 10) * size;
  const auto move = [&](const TrianglePoints& t) {
    TrianglePoints out;
    for (int k = 0; k < 3; ++k) out[k] = rotation * (t[k] - centre) + centre + shift;
    return out;
  };
  return {move(pair.p), move(pair.q)};
}

// The pair scaled by a power of two (exactly) to coordinates below 1, as CGAL is given it: its interval
// filters would otherwise overflow or underflow on the 2^-900..2^1000 family and fall back to rationals.
struct Normalised {
  int exponent = 0;  // world = normalised * 2^exponent
  TrianglePoints p, q;

  explicit Normalised(const Pair& pair) {
    const double largest =
        largest_coordinate({pair.p[0], pair.p[1], pair.p[2], pair.q[0], pair.q[1], pair.q[2]});
    if (largest > 0) exponent = std::ilogb(largest) + 1;
    p = scaled(pair.p, std::ldexp(1.0, -exponent));
    q = scaled(pair.q, std::ldexp(1.0, -exponent));
  }
  [[nodiscard]] Vec3 local(const Vec3& x) const { return x * std::ldexp(1.0, -exponent); }
  [[nodiscard]] double local(double length) const { return std::ldexp(length, -exponent); }
  [[nodiscard]] double world(double length) const { return std::ldexp(length, exponent); }
};

// Per pair: the distance against CGAL, distance 0 exactly when triangles_intersect_exact says so, the points
// (their gap against the distance, each in its own triangle by CGAL), symmetry (swapped, vertices permuted)
// and invariance under a rigid motion.
void check_pair(const Pair& pair, Rng& rng, FamilyStats& stats) {
  const Normalised normalised(pair);
  const K::Triangle_3 exact_p = exact_triangle(normalised.p), exact_q = exact_triangle(normalised.q);
  const bool intersecting = triangles_intersect_exact(pair.p, pair.q);
  // CGAL's distance of intersecting triangles is 0 too, but costs ~150 us in rationals to say so.
  const double exact = intersecting ? 0.0 : normalised.world(exact_distance(exact_p, exact_q));
  const TriangleDistance result = triangle_distance(pair.p, pair.q);
  const double size = std::max(longest_edge(pair.p), longest_edge(pair.q));
  const double scale = std::max(exact, size);
  const double tolerance = kRelative * scale;
  const double point_tolerance =
      tolerance + 4 * kEps *
                      largest_coordinate({pair.p[0], pair.p[1], pair.p[2], pair.q[0], pair.q[1], pair.q[2],
                                          result.on_p, result.on_q});
  ++stats.pairs;
  stats.intersecting += intersecting;
  if (!std::isfinite(result.distance) || !result.on_p.allFinite() || !result.on_q.allFinite())
    return fail(stats, "not finite", pair, exact, result.distance);  // CGAL (GMP) would trap on them

  const double error = std::abs(result.distance - exact);
  stats.max_absolute = std::max(stats.max_absolute, error);
  if (exact > 0) stats.max_relative = std::max(stats.max_relative, error / exact);
  if (exact >= 1e-6 * size) stats.max_resolved = std::max(stats.max_resolved, error / exact);
  if (scale > 0) stats.max_scaled = std::max(stats.max_scaled, error / scale);
  if (!(error <= tolerance)) fail(stats, "distance off", pair, exact, result.distance);
  if ((result.distance == 0) != intersecting)
    fail(stats, intersecting ? "intersecting, distance not 0" : "disjoint, distance 0", pair, exact,
         result.distance);

  const double gap_error = std::abs((result.on_p - result.on_q).stableNorm() - result.distance);
  if (!(gap_error <= point_tolerance)) fail(stats, "|on_p - on_q| != distance", pair, exact, result.distance);
  const Membership in_p = within(normalised.local(result.on_p), exact_p, normalised.local(point_tolerance));
  const Membership in_q = within(normalised.local(result.on_q), exact_q, normalised.local(point_tolerance));
  if (!in_p.inside) fail(stats, "on_p not in P", pair, exact, result.distance);
  if (!in_q.inside) fail(stats, "on_q not in Q", pair, exact, result.distance);
  if (intersecting && result.on_p != result.on_q) fail(stats, "intersecting, on_p != on_q", pair, exact, 0);
  const double off = normalised.world(std::max(in_p.distance, in_q.distance));
  if (scale > 0) stats.max_point = std::max(stats.max_point, std::max(gap_error, off) / scale);

  // The skip certificate: where triangles_farther_than says the pair is farther than x, the computed
  // distance is above x (a search that skips the pair loses nothing), also for x just below it.
  for (const double x : {result.distance, std::nextafter(result.distance, 0.0), 0.999 * result.distance,
                         0.5 * result.distance})
    if (triangles_farther_than(pair.p, pair.q, x) && !(result.distance > x))
      fail(stats, "triangles_farther_than(" + std::to_string(x) + ") but the distance is not", pair, exact,
           result.distance);
  stats.certified += triangles_farther_than(pair.p, pair.q, 0.5 * result.distance);

  const TrianglePoints q_first = permuted(pair.q, rng), p_second = permuted(pair.p, rng);
  const double swapped = triangle_distance(q_first, p_second).distance;
  if (intersecting ? swapped != 0 : !(std::abs(swapped - result.distance) <= tolerance))
    fail(stats, "not symmetric: swapped gives " + std::to_string(swapped), pair, exact, result.distance);

  // Moving rounds every vertex by a few ulps of its distance from the centre and of its new position.
  const Pair motion = moved(pair, scale, rng);
  double reach = 0;
  for (const TrianglePoints* t : {&pair.p, &pair.q})
    for (const Vec3& v : *t) reach = std::max(reach, (v - pair.p[0]).stableNorm());
  const double motion_slack = 16 * kEps *
                              (reach + largest_coordinate({motion.p[0], motion.p[1], motion.p[2], motion.q[0],
                                                           motion.q[1], motion.q[2]}));
  const double after_motion = triangle_distance(motion.p, motion.q).distance;
  if (!(std::abs(after_motion - result.distance) <= tolerance + motion_slack))
    fail(stats, "not invariant under a rigid motion: " + std::to_string(after_motion), pair, exact,
         result.distance);
}

FamilyStats run_family(const char* name, std::uint64_t seed, std::size_t count, const Generator& generate) {
  Rng rng(seed);
  FamilyStats stats;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < count / kFamilyScale; ++i) check_pair(generate(rng), rng, stats);
  const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
  std::printf(
      "[family] %-24s pairs=%zu intersecting=%.3f max_abs=%.3g max_rel=%.3g max_rel_resolved=%.3g "
      "max_scaled=%.3g max_point=%.3g certified_half=%.3f failures=%zu (%.0f ms)\n",
      name, stats.pairs, double(stats.intersecting) / double(stats.pairs), stats.max_absolute,
      stats.max_relative, stats.max_resolved, stats.max_scaled, stats.max_point,
      double(stats.certified) / double(stats.pairs), stats.failures, elapsed.count());
  return stats;
}

FamilyStats check_family(const char* name, std::uint64_t seed, std::size_t count, const Generator& generate) {
  const FamilyStats stats = run_family(name, seed, count, generate);
  ::testing::Test::RecordProperty(std::string(name) + "_max_scaled", std::to_string(stats.max_scaled));
  EXPECT_EQ(stats.failures, 0u) << name << ": " << stats.first_failure;
  return stats;
}

// ---- generators: the families shared with test_triangle_intersection.cpp (support/triangle_families.hpp),
// plus separated pairs, parallel faces, nearly parallel edges and slivers. Random draws in a fixed order
// (braces, one per statement): g++ and clang evaluate function arguments in different orders.

// Pairs per family. CGAL's exact distance leaves interval arithmetic for rationals on near contacts, parallel
// features and slivers (ties in its own edge-pair loop), ~150 us a pair: those families, and the scales
// (which repeat general position), get fewer, so that the whole test stays near 3 s.
constexpr std::size_t kPairs = 1'000, kCostlyPairs = 600;

// A general pair with Q moved 1e-8..10 in a random direction: mostly disjoint, at every distance.
Pair separated_pair(Rng& rng) {
  const Pair base = general_pair(rng);
  const Vec3 direction = random_unit(rng);
  return {base.p, translated(base.q, direction * log_uniform(rng, -8, 1))};
}

// A random direction times 1e-12..1e-2, for `sharing` (the direction drawn first).
Vec3 small_offset(Rng& rng) {
  const Vec3 direction = random_unit(rng);
  return direction * log_uniform(rng, -12, -2);
}

// Q in the cone opposite P's corner p[0], at P's edge midpoint, or along P's edge (whole or half): exact
// contact, which coplanar_touching moves half the time by a small lattice step (overlap or a coplanar gap).
Tri2 touching_q(Rng& rng, const Tri2& p) {
  const Eigen::Vector2d mid = (p[0] + p[1]) / 2.0;
  const auto beyond = [&]() -> Eigen::Vector2d {
    const double along = double(integer(rng, -2, 2)), away = double(integer(rng, 1, 3));
    return mid + along * (p[1] - p[0]) / 2.0 - away * (p[2] - mid);
  };
  const auto opposite = [&]() -> Eigen::Vector2d {
    const double back1 = double(integer(rng, 0, 3)), back2 = double(integer(rng, 1, 3));
    return p[0] - back1 * (p[1] - p[0]) - back2 * (p[2] - p[0]);
  };
  switch (integer(rng, 0, 3)) {
    case 0:
      return {p[0], opposite(), opposite()};
    case 1:
      return {mid, beyond(), beyond()};
    case 2:
      return {p[0], p[1], beyond()};
    default:
      return {p[0], mid, beyond()};
  }
}

// Q in P's plane (vertices at barycentrics -0.5..1.2) lifted by `offset(rng)` per vertex along the normal.
Pair in_plane_of_p(Rng& rng, const std::function<double(Rng&)>& offset) {
  const TrianglePoints p = general_pair(rng).p;
  const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  TrianglePoints q;
  for (Vec3& v : q) {
    const double s = uniform(rng, -0.5, 1.2), t = uniform(rng, -0.5, 1.2), lift = offset(rng);
    v = p[0] + s * (p[1] - p[0]) + t * (p[2] - p[0]) + lift * n;
  }
  return {p, q};
}

// Two edges at an angle of 1e-12..1, one 1e-12..1 above the other, each its triangle's nearest feature (the
// third vertices lie beyond): the ill-conditioned common perpendicular. Q's edge slides along its line, so
// the projections cross or not; a random pose.
Pair near_parallel_edges(Rng& rng) {
  const double angle = log_uniform(rng, -12, 0), gap = log_uniform(rng, -12, 0);
  const Vec3 along(std::cos(angle), std::sin(angle), 0), up(0, 0, gap);
  const double slide = uniform(rng, -1.5, 1.5);
  const TrianglePoints p = {Vec3(-uniform(rng, 0.1, 1), 0, 0), Vec3(uniform(rng, 0.1, 1), 0, 0),
                            Vec3{uniform(rng, -1, 1), uniform(rng, -1, 1), -uniform(rng, 0.1, 1)}};
  const TrianglePoints q = {up + (slide - uniform(rng, 0.1, 1)) * along,
                            up + (slide + uniform(rng, 0.1, 1)) * along,
                            up + Vec3{uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, 0.1, 1)}};
  const Mat3 rotation = random_rotation(rng);
  const Vec3 shift = uniform_point(rng, -2, 2);
  const auto pose = [&](const TrianglePoints& t) {
    return TrianglePoints{rotation * t[0] + shift, rotation * t[1] + shift, rotation * t[2] + shift};
  };
  return {permuted(pose(p), rng), permuted(pose(q), rng)};
}

// P a sliver (a cap: third vertex 1e-12..1e-3 off the long edge, or a needle: one edge that short) and Q's
// lowest vertex 1e-9..1 over a random point of it, the rest of Q higher up: the vertex-face case where the
// plane of P is ill-conditioned across the sliver but well defined along it. A random pose.
Pair sliver_faces(Rng& rng) {
  const double thin = log_uniform(rng, -12, -3), angle = uniform(rng, 0, std::numbers::pi);
  const Vec3 third = coin(rng) ? Vec3(uniform(rng, -0.5, 1.5), thin, 0)
                               : Vec3(thin * std::cos(angle), thin * std::sin(angle), 0);
  const TrianglePoints p = {Vec3(0, 0, 0), Vec3(1, 0, 0), third};
  const double a = uniform(rng, 0, 1), b = uniform(rng, 0, 1 - a);
  const Vec3 x = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]) + Vec3(0, 0, log_uniform(rng, -9, 0));
  const TrianglePoints q = {x, x + Vec3{uniform(rng, -1, 1), uniform(rng, -1, 1), 1.0},
                            x + Vec3{uniform(rng, -1, 1), uniform(rng, -1, 1), 1.0}};
  const Mat3 rotation = random_rotation(rng);
  const Vec3 shift = uniform_point(rng, -2, 2);
  const auto pose = [&](const TrianglePoints& t) {
    return TrianglePoints{rotation * t[0] + shift, rotation * t[1] + shift, rotation * t[2] + shift};
  };
  return {permuted(pose(p), rng), permuted(pose(q), rng)};
}

// ---- families ------------------------------------------------------------------------------------------

TEST(TriangleDistanceFamilies, GeneralPosition) {
  check_family("general_position", 1, kPairs, general_pair);
  // Not vacuous: the certificate holds for a good share of separated pairs (0.2 of them measured).
  const FamilyStats separated = check_family("separated", 2, kPairs, separated_pair);
  EXPECT_GT(separated.certified, separated.pairs / 10);
}

TEST(TriangleDistanceFamilies, Coplanar) {
  check_family("coplanar_overlapping", 3, kPairs, [](Rng& rng) {
    const LatticePlane plane = LatticePlane::random(rng);
    const Tri2 p = random_tri2(rng, 20), q = shifted2(random_tri2(rng, 20), lattice2(rng, 30));
    return Pair{plane.map(p), plane.map(q)};
  });
  check_family("coplanar_touching", 4, kPairs, [](Rng& rng) { return coplanar_touching(rng, touching_q); });
}

TEST(TriangleDistanceFamilies, Sharing) {
  check_family("shared_edge", 5, kPairs, [](Rng& rng) { return sharing(rng, 2, small_offset); });
  check_family("shared_vertex", 6, kPairs, [](Rng& rng) { return sharing(rng, 1, small_offset); });
}

TEST(TriangleDistanceFamilies, VertexOnOrNearFace) {
  check_family("vertex_on_face", 7, kPairs, [](Rng& rng) { return vertex_on_face(rng, false); });
  check_family("vertex_near_face", 8, kCostlyPairs, vertex_near_face);
}

TEST(TriangleDistanceFamilies, NearParallel) {
  // Q within 1e-15..1e-12 of P's plane, on either side per vertex (the intersection tests' family).
  check_family("near_parallel", 9, kCostlyPairs, [](Rng& rng) {
    return in_plane_of_p(rng, [](Rng& r) { return (coin(r) ? 1.0 : -1.0) * log_uniform(r, -15, -12); });
  });
  // Parallel faces 1e-9..1 apart: the nearest pair is a vertex over the other face or two edges.
  check_family("parallel_faces", 10, kCostlyPairs, [](Rng& rng) {
    const double gap = (coin(rng) ? 1.0 : -1.0) * log_uniform(rng, -9, 0);
    return in_plane_of_p(rng, [gap](Rng&) { return gap; });
  });
  check_family("near_parallel_edges", 11, kCostlyPairs, near_parallel_edges);
  check_family("sliver_faces", 21, kCostlyPairs, sliver_faces);
}

TEST(TriangleDistanceFamilies, Degenerate) {
  check_family("degenerate_vs_triangle", 12, kPairs, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 4), grid_triangle(rng, 4)};
  });
  check_family("near_degenerate", 13, kCostlyPairs, near_degenerate);
  check_family("degenerate_on_face", 14, kPairs, [](Rng& rng) { return vertex_on_face(rng, true); });
  check_family("degenerate_vs_degenerate", 15, kPairs, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 2), degenerate_triangle(rng, 2)};
  });
}

TEST(TriangleDistanceFamilies, AxisAligned) {
  check_family("axis_aligned", 16, kPairs, [](Rng& rng) {
    return Pair{axis_aligned_triangle(rng), axis_aligned_triangle(rng)};
  });
}

TEST(TriangleDistanceFamilies, Scales) {
  for_each_scale_family(separated_pair, 17, [](const char* name, std::uint64_t seed, const Generator& make) {
    check_family(name, seed, kCostlyPairs, make);
  });
}

// ---- hand-written cases ----------------------------------------------------------------------------------

const Vec3 kO(0, 0, 0), kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

double relative_error(double computed, double expected) {
  return std::abs(computed - expected) / expected;
}

TEST(TriangleDistanceCases, KnownDistances) {
  const TrianglePoints p = {kO, kX, kY};
  EXPECT_DOUBLE_EQ(triangle_distance(p, translated(p, Vec3(0.1, 0.1, 2))).distance, 2.0);  // parallel faces
  const TriangleDistance above = triangle_distance(p, {Vec3(0.25, 0.25, 0.5), Vec3(0, 0, 3), Vec3(1, 1, 3)});
  EXPECT_DOUBLE_EQ(above.distance, 0.5);  // a vertex over the face
  EXPECT_TRUE(above.on_p.isApprox(Vec3(0.25, 0.25, 0))) << above.on_p.transpose();
  // Skew edges: P's edge along x at z = 0, Q's edge along y at z = 1, crossing over (0.5, 0, 0).
  const TriangleDistance skew = triangle_distance({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 0, -1)},
                                                  {Vec3(0.5, -1, 1), Vec3(0.5, 1, 1), Vec3(0.5, 0, 2)});
  EXPECT_DOUBLE_EQ(skew.distance, 1.0);
  EXPECT_TRUE(skew.on_p.isApprox(Vec3(0.5, 0, 0))) << skew.on_p.transpose();
  EXPECT_TRUE(skew.on_q.isApprox(Vec3(0.5, 0, 1))) << skew.on_q.transpose();
  // Degenerate: points and segments.
  EXPECT_DOUBLE_EQ(triangle_distance({kX, kX, kX}, {kY, kY, kY}).distance, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(
      triangle_distance({kO, Vec3(2, 0, 0), kX}, {Vec3(1, 1, 1), Vec3(1, 1, 1), Vec3(1, 3, 1)}).distance,
      std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(triangle_distance(p, {Vec3(0.2, 0.2, 3), Vec3(0.2, 0.2, 3), Vec3(0.2, 0.2, 3)}).distance,
                   3.0);
  // Collinear edges, apart along their line.
  EXPECT_DOUBLE_EQ(
      triangle_distance({kO, kX, Vec3(0, 1, 0)}, {Vec3(3, 0, 0), Vec3(4, 0, 0), Vec3(4, -1, 0)}).distance,
      2.0);
}

TEST(TriangleDistanceCases, TouchingIsZeroWithACommonPoint) {
  const TrianglePoints p = {kO, kX, kY};
  const auto expect_common = [&](const TrianglePoints& q, const char* what) {
    const TriangleDistance d = triangle_distance(p, q);
    EXPECT_EQ(d.distance, 0.0) << what;
    EXPECT_EQ(d.on_p, d.on_q) << what;
    EXPECT_TRUE(within(d.on_p, exact_triangle(p), 1e-15).inside) << what;
    EXPECT_TRUE(within(d.on_p, exact_triangle(q), 1e-15).inside) << what;
  };
  expect_common({kO, Vec3(-1, 0, 0), kZ}, "shared vertex");
  expect_common({kO, kX, kZ}, "shared edge");
  expect_common({Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(3, 3, 0)}, "piercing");
  expect_common({Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(2, 2, 0)}, "edge through the hypotenuse");
  expect_common({Vec3(0.1, 0.1, 0), Vec3(0.3, 0.1, 0), Vec3(0.1, 0.3, 0)}, "coplanar, nested");
  expect_common({Vec3(0.5, -0.5, 0), Vec3(0.5, 2, 0), Vec3(3, 0, 0)}, "coplanar, edges crossing");
  expect_common({Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 0)}, "point on the face");
}

TEST(TriangleDistanceCases, TinyGapsArePositive) {
  const TrianglePoints p = {kO, kX, kY};
  const double parallel = triangle_distance(p, translated(p, Vec3(0, 0, 1e-300))).distance;
  EXPECT_GT(parallel, 0.0);
  EXPECT_LT(relative_error(parallel, 1e-300), 1e-9);
  const double vertex =
      triangle_distance(p, {Vec3(0.25, 0.25, 1e-300), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}).distance;
  EXPECT_LT(relative_error(vertex, 1e-300), 1e-9);
  const double gap = std::nextafter(1.0, 2.0) - 1.0;  // one ulp beyond the hypotenuse
  EXPECT_GT(triangle_distance(p, {Vec3(0.5 + gap, 0.5, -1), Vec3(0.5 + gap, 0.5, 1), Vec3(2, 2, 0)}).distance,
            0.0);
}

// Triangles of size ~1 at ~1e6 from the origin, 1e-3 apart: parallel faces and two edges crossing at a gap.
// Computed about the origin, every coordinate would carry 1e-10 of rounding, 1e-7 of the distance.
TEST(TriangleDistanceCases, FarFromOriginKeepsRelativePrecision) {
  Rng rng(31);
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    const Mat3 rotation = random_rotation(rng);
    const Vec3 centre = Vec3::Constant(1e6) + uniform_point(rng, -1e5, 1e5);
    const auto place = [&](const TrianglePoints& t) {
      return TrianglePoints{rotation * t[0] + centre, rotation * t[1] + centre, rotation * t[2] + centre};
    };
    // Faces: Q parallel to P, 1e-3 above it. Edges: P's edge along x and Q's along y, 1e-3 apart, every other
    // point of each triangle farther away.
    const std::array<Pair, 2> pairs = {
        Pair{place({kO, kX, kY}), place({Vec3(0.1, 0.1, 1e-3), Vec3(1, 0.2, 1e-3), Vec3(0.2, 1, 1e-3)})},
        Pair{place({kO, kX, Vec3(0.5, -1, -1)}),
             place({Vec3(0.5, -0.5, 1e-3), Vec3(0.5, 0.5, 1e-3), Vec3(0.5, 0, 1)})}};
    for (const Pair& pair : pairs) {
      const double exact = exact_distance(exact_triangle(pair.p), exact_triangle(pair.q));
      ASSERT_LT(relative_error(exact, 1e-3), 1e-6);  // the construction, rounded at 1e6
      const double error = relative_error(triangle_distance(pair.p, pair.q).distance, exact);
      worst = std::max(worst, error);
      EXPECT_LT(error, 1e-9) << describe(pair.p) << describe(pair.q);
    }
  }
  std::printf("[far] worst relative error %.3g\n", worst);
}

TEST(TriangleDistanceCases, NonFiniteInputIsRejected) {
  const TrianglePoints p = {kO, kX, kY};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)triangle_distance(p, {kO, Vec3(nan, 0, 0), kZ}), std::invalid_argument);
  EXPECT_THROW((void)triangle_distance({Vec3(inf, 0, 0), kX, kY}, p), std::invalid_argument);
  EXPECT_THROW((void)triangle_distance(p, {kO, kX, Vec3(0, 0, -inf)}), std::invalid_argument);
  try {
    (void)triangle_distance(p, {kO, kX, Vec3(0, nan, 0)});
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Q vertex 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bvhlab
