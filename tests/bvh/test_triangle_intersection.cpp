// Property tests: the fast triangle test against CGAL ground truth on random and adversarial families,
// plus hand-written cases with known answers. Every family uses a fixed seed.
#include "bench/core/generators.hpp"
#include "bvh/triangle_batch.hpp"
#include "bvh/triangle_intersection.hpp"
#include "bvh/triangle_intersection_fast.hpp"
#include "support/triangle_families.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using namespace testing;  // the triangle families: support/triangle_families.hpp

// Full counts in optimised builds; a tenth where assertions are on (Debug: CGAL checks everything).
#ifdef NDEBUG
constexpr std::size_t kScale = 1;
#else
constexpr std::size_t kScale = 10;
#endif

using generators::random_unit;
using generators::uniform;
using generators::uniform_point;

struct FamilyStats {
  std::size_t pairs = 0, intersecting = 0, undecided = 0, disagreements = 0, known = 0, known_wrong = 0;
  std::size_t batch_apart = 0, batch_problems = 0;
  std::string first_problem;
};

// Four pairs of a family at a time through the plane tests of bvh/triangle_batch.hpp: the vector lanes must
// answer as the scalar reference, and a pair they call apart must be disjoint.
struct BatchCheck {
  TrianglePairs4 batch{};
  bool exact[4] = {};
  int filled = 0;

  void add(const Pair& pair, bool intersects, FamilyStats& stats) {
    batch.set(filled, pair.p, pair.q);
    exact[filled++] = intersects;
    if (filled < 4) return;
    filled = 0;
    const unsigned apart = triangle_pairs_apart(batch), reference = triangle_pairs_apart_scalar(batch);
    for (int k = 0; k < 4; ++k) {
      const bool wrong = (apart >> k & 1) && exact[k];
      stats.batch_apart += apart >> k & 1;
      if ((apart != reference || wrong) && stats.batch_problems++ == 0)
        stats.first_problem = "plane tests of four: vector mask " + std::to_string(apart) + ", scalar " +
                              std::to_string(reference) + ", lane " + std::to_string(k) +
                              " apart but intersects: " + std::to_string(wrong);
    }
  }
};

// Per pair: ground truth, the fast test as the traversal calls it, the filter's own verdict, and the fast
// test again on the swapped pair with both vertex orders permuted (symmetry and orientation handling).
FamilyStats run_family(const char* name, std::uint64_t seed, std::size_t count, const Generator& generate) {
  Rng rng(seed);
  FamilyStats stats;
  BatchCheck batch;
  for (std::size_t i = 0; i < count; ++i) {
    const Pair pair = generate(rng);
    const bool exact = triangles_intersect_exact(pair.p, pair.q);
    const bool fast = triangles_intersect(pair.p, pair.q);
    const FilteredVerdict verdict =
        triangles_intersect_filtered(pair.p[0], pair.p[1], pair.p[2], pair.q[0], pair.q[1], pair.q[2]);
    const bool swapped = triangles_intersect_fast(permuted(pair.q, rng), permuted(pair.p, rng));
    const bool filter_wrong =
        verdict != FilteredVerdict::undecided && (verdict == FilteredVerdict::intersecting) != exact;
    ++stats.pairs;
    stats.intersecting += exact;
    batch.add(pair, exact, stats);
    stats.undecided += verdict == FilteredVerdict::undecided;
    if (fast != exact || swapped != exact || filter_wrong) {
      if (stats.disagreements++ == 0)
        stats.first_problem = "exact=" + std::to_string(exact) + " fast=" + std::to_string(fast) +
                              " swapped=" + std::to_string(swapped) + " P=" + describe(pair.p) +
                              " Q=" + describe(pair.q);
    }
    if (pair.known) {
      ++stats.known;
      if (*pair.known != exact && stats.known_wrong++ == 0 && stats.first_problem.empty())
        stats.first_problem =
            "ground truth contradicts construction: P=" + describe(pair.p) + " Q=" + describe(pair.q);
    }
  }
  std::printf(
      "[family] %-24s pairs=%zu intersecting=%.3f undecided=%.4f disagreements=%zu known=%zu "
      "known_wrong=%zu apart_by_planes=%.3f\n",
      name, stats.pairs, double(stats.intersecting) / double(stats.pairs),
      double(stats.undecided) / double(stats.pairs), stats.disagreements, stats.known, stats.known_wrong,
      double(stats.batch_apart) / double(stats.pairs));
  return stats;
}

// Runs a family and checks: zero disagreements, ground truth matches every constructed answer, and both
// outcomes occur often enough for the family to mean something.
void check_family(const char* name, std::uint64_t seed, std::size_t count, const Generator& generate,
                  double min_fraction = 0.05) {
  const FamilyStats stats = run_family(name, seed, count / kScale, generate);
  ::testing::Test::RecordProperty(std::string(name) + "_pairs", std::to_string(stats.pairs));
  ::testing::Test::RecordProperty(std::string(name) + "_intersecting", std::to_string(stats.intersecting));
  ::testing::Test::RecordProperty(std::string(name) + "_undecided", std::to_string(stats.undecided));
  EXPECT_EQ(stats.disagreements, 0u) << stats.first_problem;
  EXPECT_EQ(stats.known_wrong, 0u) << stats.first_problem;
  EXPECT_EQ(stats.batch_problems, 0u) << stats.first_problem;
  const double fraction = double(stats.intersecting) / double(stats.pairs);
  EXPECT_GE(fraction, min_fraction) << name << ": too few intersecting pairs for a meaningful family";
  EXPECT_LE(fraction, 1.0 - min_fraction) << name << ": too few disjoint pairs for a meaningful family";
}

// ---- generators: those of this test only; the shared ones are in support/triangle_families.hpp -------

// Q in the cone opposite P's corner p[0]: the two meet only at that vertex.
Tri2 touch_at_vertex(Rng& rng, const Tri2& p) {
  const auto opposite = [&]() -> Eigen::Vector2d {
    Eigen::Vector2d w = Eigen::Vector2d::Zero();
    do w = -double(integer(rng, 0, 3)) * (p[1] - p[0]) - double(integer(rng, 0, 3)) * (p[2] - p[0]);
    while (w.isZero(0.0));
    return p[0] + w;
  };
  return {p[0], opposite(), opposite()};
}

// Q's vertex at the midpoint of P's edge p0p1, the rest strictly beyond that edge.
Tri2 touch_vertex_on_edge(Rng& rng, const Tri2& p) {
  const Eigen::Vector2d mid = (p[0] + p[1]) / 2.0;
  const auto beyond = [&]() -> Eigen::Vector2d {
    return mid + double(integer(rng, -2, 2)) * (p[1] - p[0]) / 2.0 -
           double(integer(rng, 1, 3)) * (p[2] - mid);
  };
  return {mid, beyond(), beyond()};
}

// Q shares P's edge p0p1, or half of it, and lies beyond it.
Tri2 touch_along_edge(Rng& rng, const Tri2& p) {
  const Eigen::Vector2d mid = (p[0] + p[1]) / 2.0;
  const Eigen::Vector2d beyond =
      mid + double(integer(rng, -2, 2)) * (p[1] - p[0]) - double(integer(rng, 1, 3)) * (p[2] - mid);
  switch (integer(rng, 0, 2)) {
    case 0:
      return {p[0], p[1], beyond};
    case 1:
      return {p[0], mid, beyond};
    default:
      return {mid, p[1], beyond};
  }
}

// A random direction times 1e-12..1e-2, for `sharing`. The length is drawn first: the order in which g++
// evaluated this test's former random_unit(rng) * std::pow(10.0, uniform(rng, -12, -2)), now fixed for
// every compiler.
Vec3 small_offset(Rng& rng) {
  const double length = log_uniform(rng, -12, -2);
  const Vec3 direction = random_unit(rng);
  return direction * length;
}

// Q almost in P's plane: each vertex 1e-15..1e-12 (relative to unit size) off it, on a random side.
Pair near_parallel(Rng& rng) {
  const TrianglePoints p = general_pair(rng).p;
  const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  TrianglePoints q;
  for (Vec3& v : q) {
    const double offset = (coin(rng) ? 1.0 : -1.0) * std::pow(10.0, uniform(rng, -15, -12));
    v = p[0] + uniform(rng, -0.5, 1.2) * (p[1] - p[0]) + uniform(rng, -0.5, 1.2) * (p[2] - p[0]) + offset * n;
  }
  return {p, q, std::nullopt};
}

// ---- families ------------------------------------------------------------------------------------------

TEST(TriangleFamilies, GeneralPosition) {
  check_family("general_position", 1, 200'000, general_pair);
  // The filter must actually decide general-position pairs (else "fast" would be CGAL with extra steps).
  const FamilyStats stats = run_family("general_position_small", 11, 20'000 / kScale, general_pair);
  EXPECT_LT(double(stats.undecided) / double(stats.pairs), 0.001);
}

TEST(TriangleFamilies, CoplanarOverlapping) {
  check_family("coplanar_overlapping", 2, 60'000, [](Rng& rng) {
    const LatticePlane plane = LatticePlane::random(rng);
    const Tri2 p = random_tri2(rng, 20);
    const Tri2 q = shifted2(random_tri2(rng, 20), lattice2(rng, 15));
    return Pair{plane.map(p), plane.map(q), std::nullopt};
  });
}

TEST(TriangleFamilies, CoplanarTouchingAtVertex) {
  check_family("coplanar_touch_vertex", 3, 60'000,
               [](Rng& rng) { return coplanar_touching(rng, touch_at_vertex); });
  check_family("coplanar_vertex_on_edge", 4, 40'000,
               [](Rng& rng) { return coplanar_touching(rng, touch_vertex_on_edge); });
}

TEST(TriangleFamilies, CoplanarTouchingAlongEdge) {
  check_family("coplanar_touch_edge", 5, 60'000,
               [](Rng& rng) { return coplanar_touching(rng, touch_along_edge); });
}

TEST(TriangleFamilies, SharedEdge) {
  check_family("shared_edge", 6, 80'000, [](Rng& rng) { return sharing(rng, 2, small_offset); });
}

TEST(TriangleFamilies, SharedVertex) {
  check_family("shared_vertex", 7, 80'000, [](Rng& rng) { return sharing(rng, 1, small_offset); });
}

TEST(TriangleFamilies, VertexExactlyOnFace) {
  check_family("vertex_on_face", 8, 80'000, [](Rng& rng) { return vertex_on_face(rng, false); });
}

TEST(TriangleFamilies, VertexNearFace) {
  check_family("vertex_near_face", 9, 80'000, vertex_near_face);
}

TEST(TriangleFamilies, NearParallel) {
  check_family("near_parallel", 10, 80'000, near_parallel);
}

TEST(TriangleFamilies, DegenerateAgainstTriangle) {
  check_family("degenerate_vs_triangle", 12, 60'000, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 4), grid_triangle(rng, 4), std::nullopt};
  });
  check_family("near_degenerate", 13, 40'000, near_degenerate);
  check_family("degenerate_on_face", 19, 40'000, [](Rng& rng) { return vertex_on_face(rng, true); });
}

TEST(TriangleFamilies, DegenerateAgainstDegenerate) {
  check_family("degenerate_vs_degenerate", 14, 60'000, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 2), degenerate_triangle(rng, 2), std::nullopt};
  });
}

TEST(TriangleFamilies, AxisAligned) {
  check_family("axis_aligned", 20, 60'000, [](Rng& rng) {
    return Pair{axis_aligned_triangle(rng), axis_aligned_triangle(rng), std::nullopt};
  });
}

TEST(TriangleFamilies, TinyFarFromOrigin) {
  check_family("tiny_far", 15, 60'000, [](Rng& rng) {
    const Vec3 offset = Vec3::Constant(1e6) + uniform_point(rng, -1e5, 1e5);
    return rescaled(general_pair, 1e-3, offset)(rng);
  });
}

TEST(TriangleFamilies, Scales) {
  check_family("scale_1e-6", 16, 50'000, rescaled(general_pair, 1e-6, Vec3::Zero()));
  check_family("scale_1e6", 17, 50'000, rescaled(general_pair, 1e6, Vec3::Zero()));
}

TEST(TriangleFamilies, ExtremeMagnitudes) {
  // Products underflow (2^-1000) or overflow (2^1000): the filter must decline, never misjudge.
  check_family("extreme_magnitudes", 18, 40'000, [](Rng& rng) {
    const double scale = std::ldexp(1.0, int(integer(rng, -1020, 1020)));
    return rescaled(general_pair, scale, Vec3::Zero())(rng);
  });
}

// ---- the orientation filter alone, on mixed magnitudes --------------------------------------------------

int cgal_orientation(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  using P = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  const auto point = [](const Vec3& v) { return P(v.x(), v.y(), v.z()); };
  // CGAL's orientation(a, b, c, d) is sign det[b - a, c - a, d - a], the convention of certified_orient.
  return int(CGAL::orientation(point(a), point(b), point(c), point(d)));
}

TEST(TriangleFilter, CertifiedOrientNeverContradictsCgal) {
  Rng rng(21);
  const auto coordinate = [&rng](int min_exponent, int max_exponent) {
    return std::ldexp(uniform(rng, -1, 1), int(integer(rng, min_exponent, max_exponent)));
  };
  std::size_t decided = 0, wrong = 0, total = 300'000 / kScale;
  for (std::size_t i = 0; i < total; ++i) {
    Vec3 a, b, c, d;
    const double scale = std::ldexp(1.0, int(integer(rng, -1000, 1000)));
    switch (i % 4) {
      case 0:  // general position at one random scale, overflow and underflow included
        for (Vec3* v : {&a, &b, &c, &d}) *v = uniform_point(rng, -1, 1) * scale;
        break;
      case 1:  // almost coplanar: the rounded d lies within rounding of the plane
        for (Vec3* v : {&a, &b, &c}) *v = uniform_point(rng, -1, 1) * scale;
        d = a + uniform(rng, -1, 2) * (b - a) + uniform(rng, -1, 2) * (c - a);
        break;
      case 2:  // every coordinate at its own magnitude; products stay mostly in range
        for (Vec3* v : {&a, &b, &c, &d})
          *v = Vec3{coordinate(-340, 340), coordinate(-340, 340), coordinate(-340, 340)};
        break;
      default:  // every coordinate at its own magnitude, subnormals and overflow included
        for (Vec3* v : {&a, &b, &c, &d})
          *v = Vec3{coordinate(-1074, 1023), coordinate(-1074, 1023), coordinate(-1074, 1023)};
    }
    const int filtered = tri_detail::certified_orient(a, b, c, d);
    if (filtered == 0) continue;
    ++decided;
    wrong += filtered != cgal_orientation(a, b, c, d);
  }
  std::printf("[filter] orient3d samples=%zu decided=%zu wrong=%zu\n", total, decided, wrong);
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(decided, total / 4);  // the filter is not vacuous
}

TEST(TriangleFilter, SubnormalProductDoesNotFakeASign) {
  // n = (b - a) x (c - a) = (0, -s, s*s') where s*s' = 9 * 2^-1080 rounds to 0, and w_z = 2^60 scales that
  // lost term above the other one: true sign +, naive double evaluation -3 * 2^-1022 with a tiny relative
  // bound. The absolute underflow term must make the filter decline.
  const double s = 3 * std::ldexp(1.0, -540);
  const Vec3 a(0, 0, 0), b(s, 0, 0), c(0, s, 1), d(0, std::ldexp(1.0, -482), std::ldexp(1.0, 60));
  ASSERT_EQ(cgal_orientation(a, b, c, d), 1);
  EXPECT_NE(tri_detail::certified_orient(a, b, c, d), -1);
}

// ---- hand-written cases ----------------------------------------------------------------------------------

const Vec3 kO(0, 0, 0), kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

void expect_both(const TrianglePoints& p, const TrianglePoints& q, bool expected, const char* what) {
  EXPECT_EQ(triangles_intersect_exact(p, q), expected) << what << " (exact)";
  EXPECT_EQ(triangles_intersect(p, q), expected) << what << " (fast)";
  EXPECT_EQ(triangles_intersect_fast(q, p), expected) << what << " (fast, swapped)";
}

TEST(TriangleHandCases, TouchingCountsAsIntersecting) {
  const TrianglePoints p = {kO, kX, kY};
  expect_both(p, {kO, kX, kZ}, true, "shared edge, perpendicular");
  expect_both(p, {kX, kO, Vec3(0.5, -1, 0)}, true, "shared edge, coplanar, other side");
  expect_both(p, {kO, Vec3(-1, 0, 0), Vec3(0, 0, 1)}, true, "shared vertex only");
  expect_both(p, p, true, "identical");
  expect_both(p, {Vec3(0.25, 0.25, 0), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}, true, "vertex on face");
  expect_both(p, {Vec3(0.5, 0.5, 0), Vec3(0.5, 0.5, 1), Vec3(1, 1, 1)}, true, "vertex on hypotenuse");
  expect_both(p, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(3, 3, 0)}, true, "piercing");
}

TEST(TriangleHandCases, TinyGapsSeparate) {
  const TrianglePoints p = {kO, kX, kY};
  const Vec3 up(0, 0, 1e-300);
  expect_both(p, translated(p, up), false, "parallel copy 1e-300 above");
  expect_both(p, {Vec3(0.25, 0.25, 1e-300), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}, false,
              "vertex 1e-300 above the face");
  expect_both(p, {Vec3(0.25, 0.25, -1e-300), Vec3(0.25, 0.25, 1), Vec3(1, 1, 1)}, true,
              "vertex 1e-300 below the face: pierces");
  const double gap = std::nextafter(1.0, 2.0) - 1.0;
  expect_both(p, {Vec3(0.5 + gap, 0.5, -1), Vec3(0.5 + gap, 0.5, 1), Vec3(2, 2, 0)}, false,
              "edge crossing one ulp beyond the hypotenuse");
  expect_both(p, {Vec3(0.5, 0.5, -1), Vec3(0.5, 0.5, 1), Vec3(2, 2, 0)}, true,
              "edge crossing the hypotenuse");
}

TEST(TriangleHandCases, ExtremeScales) {
  for (const double scale : {1e-300, 1e-200, 1e200, 1e300}) {
    const TrianglePoints p = scaled({kO, kX, kY}, scale);
    expect_both(p, scaled({Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(3, 3, 0)}, scale), true,
                "piercing, scaled");
    expect_both(p, scaled({Vec3(0.7, 0.7, -1), Vec3(0.7, 0.7, 1), Vec3(3, 3, 0)}, scale), false,
                "missing, scaled");
  }
}

TEST(TriangleHandCases, DegenerateTriangles) {
  const TrianglePoints p = {kO, kX, kY};
  expect_both(p, {Vec3(1, 0, -1), Vec3(0.5, 0, -1), Vec3(0.25, 0.25, 0.5)}, true, "crossing triangle");
  const TrianglePoints collinear = {Vec3(-1, 0.25, 0), Vec3(-2, 0.25, 0), Vec3(0.5, 0.25, 0)};
  expect_both(p, collinear, true, "collinear, middle vertex first, reaching into the face");
  const TrianglePoints collinear_out = {Vec3(-0.5, 0.25, 0), Vec3(-1, 0.25, 0), Vec3(-2, 0.25, 0)};
  expect_both(p, collinear_out, false, "collinear, outside");
  const TrianglePoints vertical = {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 3), Vec3(0.2, 0.2, 1)};
  expect_both(p, vertical, true, "vertical segment ending on the face, middle vertex last");
  expect_both(p, translated(vertical, Vec3(0, 0, 1e-300)), false, "vertical segment 1e-300 above");
  expect_both(p, {Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 0)}, true, "point on face");
  expect_both(p, {Vec3(0.2, 0.2, 1e-300), Vec3(0.2, 0.2, 1e-300), Vec3(0.2, 0.2, 1e-300)}, false,
              "point off face");
  const TrianglePoints s1 = {Vec3(0, 0, 0), Vec3(2, 2, 2), Vec3(1, 1, 1)};
  expect_both(s1, {Vec3(0, 2, 0), Vec3(2, 0, 2), Vec3(0, 2, 0)}, true, "segments crossing at (1,1,1)");
  expect_both(s1, {Vec3(0, 2, 0), Vec3(2, 0, 2.5), Vec3(0, 2, 0)}, false, "skew segments");
  expect_both(s1, {Vec3(2, 2, 2), Vec3(3, 3, 3), Vec3(4, 4, 4)}, true, "collinear segments sharing an end");
  expect_both(s1, {Vec3(2.5, 2.5, 2.5), Vec3(3, 3, 3), Vec3(4, 4, 4)}, false, "collinear segments apart");
  expect_both(s1, {Vec3(1.5, 1.5, 1.5), Vec3(1.5, 1.5, 1.5), Vec3(1.5, 1.5, 1.5)}, true, "point on segment");
  expect_both(s1, {Vec3(1.5, 1.5, 1.6), Vec3(1.5, 1.5, 1.6), Vec3(1.5, 1.5, 1.6)}, false,
              "point off segment");
  expect_both({kX, kX, kX}, {kX, kX, kX}, true, "equal points");
  expect_both({kX, kX, kX}, {kY, kY, kY}, false, "different points");
}

TEST(TriangleHandCases, NonFiniteInputIsRejected) {
  const TrianglePoints p = {kO, kX, kY};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)triangles_intersect_exact(p, {kO, Vec3(nan, 0, 0), kZ}), std::invalid_argument);
  EXPECT_THROW((void)triangles_intersect(p, {kO, Vec3(nan, 0, 0), kZ}), std::invalid_argument);
  EXPECT_THROW((void)triangles_intersect({Vec3(inf, 0, 0), kX, kY}, p), std::invalid_argument);
  EXPECT_THROW((void)triangles_intersect_fast({Vec3(5, 5, 5), Vec3(6, 5, 5), Vec3(5, 5, inf)}, p),
               std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab
