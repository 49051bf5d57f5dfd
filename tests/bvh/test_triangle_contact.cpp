// Property tests: triangle_contact against CGAL's exact intersection (Epeck) on the adversarial triangle
// families (support/triangle_families.hpp), plus hand-written cases with known answers. Fixed seeds.
//
// Tolerance: kRelative of the pair's size (its longest edge), plus 4 eps of the largest coordinate for points
// stored in world coordinates (each component rounds to half an ulp of its magnitude, which matters only for
// small pairs far from the origin). Conditioning: where the planes meet at a small angle, rounding moves the
// segment along itself by (rounding / sine), though not off the triangles; so the end points are checked on
// both triangles always, and against CGAL's segment or point only where the sine of the planes' angle exceeds
// kWellConditioned (or a triangle is exactly degenerate: the grid families, exact in doubles).
#include "bench/core/generators.hpp"
#include "bvh/triangle_contact.hpp"
#include "bvh/triangle_intersection.hpp"
#include "support/exact_triangles.hpp"
#include "support/triangle_families.hpp"

#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace bvhlab {
namespace {

using namespace testing;  // support/triangle_families.hpp, support/exact_triangles.hpp
using generators::random_unit;
using generators::uniform;
using generators::uniform_point;

constexpr double kRelative = 1e-9;
constexpr double kWellConditioned = 1e-3;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// ---- exact ground truth ----------------------------------------------------------------------------------

Vec3 approximate(const ExactPoint& x) {
  return {to_double(x.x(), 1e-15), to_double(x.y(), 1e-15), to_double(x.z(), 1e-15)};
}

// A triangle as CGAL's intersection takes it: a degenerate one as the segment or point it is (CGAL's triangle
// constructions require a proper triangle).
using Shape = std::variant<ExactPoint, K::Segment_3, K::Triangle_3>;
Shape exact_shape(const TrianglePoints& t) {
  std::array<ExactPoint, 3> v = {exact_point(t[0]), exact_point(t[1]), exact_point(t[2])};
  if (!CGAL::collinear(v[0], v[1], v[2])) return K::Triangle_3(v[0], v[1], v[2]);
  // Lexicographic order is monotone along a line: its extremes are the segment's ends.
  std::sort(v.begin(), v.end(), [](const ExactPoint& a, const ExactPoint& b) { return a < b; });
  if (v[0] == v[2]) return v[0];
  return K::Segment_3(v[0], v[2]);
}
bool degenerate(const Shape& s) {
  return !std::holds_alternative<K::Triangle_3>(s);
}

// CGAL's P ∩ Q: its kind and its vertices.
struct Truth {
  enum class Kind { none, point, segment, polygon } kind = Kind::none;
  std::vector<Vec3> vertices;
};
struct TruthOf {
  Truth operator()(const ExactPoint& x) const { return {Truth::Kind::point, {approximate(x)}}; }
  Truth operator()(const K::Segment_3& s) const {
    return {Truth::Kind::segment, {approximate(s.source()), approximate(s.target())}};
  }
  Truth operator()(const K::Triangle_3& t) const {
    return {Truth::Kind::polygon,
            {approximate(t.vertex(0)), approximate(t.vertex(1)), approximate(t.vertex(2))}};
  }
  Truth operator()(const std::vector<ExactPoint>& polygon) const {
    Truth truth{Truth::Kind::polygon, {}};
    for (const ExactPoint& x : polygon) truth.vertices.push_back(approximate(x));
    return truth;
  }
};
template <class A, class B>
Truth intersect(const A& a, const B& b) {
  const auto result = CGAL::intersection(a, b);
  return result ? boost::apply_visitor(TruthOf{}, *result) : Truth{};
}
template <class B>
Truth intersect(const ExactPoint& x, const B& b) {
  return CGAL::do_intersect(x, b) ? TruthOf{}(x) : Truth{};
}
template <class A>
Truth intersect(const A& a, const ExactPoint& x) {
  return intersect(x, a);
}
Truth intersect(const ExactPoint& x, const ExactPoint& y) {
  return x == y ? TruthOf{}(x) : Truth{};
}
Truth exact_intersection(const Shape& p, const Shape& q) {
  return std::visit([](const auto& a, const auto& b) { return intersect(a, b); }, p, q);
}

// x's distance from s: the upper end of the exact squared distance's interval, refined (exactly where need
// be) unless far below the tolerance. A sliver's interval is loose: its plane divides by a tiny |normal|^2.
double distance_to(const Vec3& x, const Shape& s, double tolerance) {
  const ExactPoint e = exact_point(x);
  const K::FT squared = std::visit([&](const auto& shape) { return CGAL::squared_distance(e, shape); }, s);
  const double upper = std::sqrt(CGAL::to_interval(squared).second);
  return upper <= 1e-6 * tolerance ? upper : std::sqrt(to_double(squared, 1e-6));
}

// ---- pairs -----------------------------------------------------------------------------------------------

// The pair scaled by a power of two (exactly) to coordinates below 1, as CGAL is given it: its interval
// filters would otherwise overflow or underflow at 2^-900..2^1000 and fall back to rationals.
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
};

// Sine of the angle between the planes (rounded: enough to tell 1e-3), 0 where a triangle has no plane.
double plane_sine(const TrianglePoints& p, const TrianglePoints& q) {
  const Vec3 np = (p[1] - p[0]).cross(p[2] - p[0]), nq = (q[1] - q[0]).cross(q[2] - q[0]);
  if (np.isZero(0.0) || nq.isZero(0.0)) return 0;
  return np.normalized().cross(nq.normalized()).norm();
}

// ---- the checks ----------------------------------------------------------------------------------------

// Worst errors over their tolerances (1 = at the tolerance): the margins the report quotes.
struct FamilyStats {
  std::size_t pairs = 0, intersecting = 0, compared = 0, coplanar = 0, failures = 0;
  double max_off = 0;      // an end point's distance from P or Q
  double max_miss = 0;     // an end point's miss of CGAL's point or segment (well conditioned)
  double max_polygon = 0;  // coplanar: an end point's miss of CGAL's polygon's vertices, the diameter's error
  double max_normal = 0;   // |normal . (to - from)| (not coplanar, well conditioned)
  std::string first_failure;
};

void fail(FamilyStats& stats, const std::string& what, const Pair& pair) {
  if (stats.failures++ > 0) return;
  stats.first_failure = what + " P=" + describe(pair.p) + " Q=" + describe(pair.q);
}

// What one pair is checked against, in normalised coordinates.
struct Reference {
  Shape p, q;
  Truth truth;
  bool conditioned;  // the segment or point is determined to well within the tolerance
  bool coplanar;     // exactly
  double size;
};

double nearest_vertex(const Vec3& x, const std::vector<Vec3>& vertices) {
  double d = std::numeric_limits<double>::infinity();
  for (const Vec3& v : vertices) d = std::min(d, (x - v).norm());
  return d;
}

double polygon_diameter(const std::vector<Vec3>& vertices) {
  double d = 0;
  for (const Vec3& a : vertices)
    for (const Vec3& b : vertices) d = std::max(d, (a - b).norm());
  return d;
}

// (c): the ends against CGAL's intersection; returns the worst miss.
double miss_of_truth(const Vec3& from, const Vec3& to, const Truth& truth) {
  const std::vector<Vec3>& v = truth.vertices;
  if (truth.kind == Truth::Kind::point) return std::max((from - v[0]).norm(), (to - v[0]).norm());
  const double same = std::max((from - v[0]).norm(), (to - v[1]).norm());
  return std::min(same, std::max((from - v[1]).norm(), (to - v[0]).norm()));
}

void check_contact(const TriangleContact& c, const Pair& pair, const Normalised& n, const Reference& ref,
                   FamilyStats& stats) {
  const Vec3 from = n.local(c.from), to = n.local(c.to);
  if (!from.allFinite() || !to.allFinite() || !c.normal.allFinite()) return fail(stats, "not finite", pair);
  const double tolerance =
      kRelative * ref.size + 4 * kEps *
                                 n.local(largest_coordinate({pair.p[0], pair.p[1], pair.p[2], pair.q[0],
                                                             pair.q[1], pair.q[2], c.from, c.to}));
  // (b) on both triangles.
  double off = 0;
  for (const Vec3& x : {from, to})
    for (const Shape* s : {&ref.p, &ref.q}) off = std::max(off, distance_to(x, *s, tolerance));
  stats.max_off = std::max(stats.max_off, off / tolerance);
  if (!(off <= tolerance)) fail(stats, "end point off a triangle by " + std::to_string(off), pair);
  // (c) against CGAL.
  const Truth& truth = ref.truth;
  if (truth.kind == Truth::Kind::polygon) {
    if (!c.coplanar) fail(stats, "CGAL says polygon, not coplanar", pair);
    const double miss = std::max({nearest_vertex(from, truth.vertices), nearest_vertex(to, truth.vertices),
                                  std::abs((to - from).norm() - polygon_diameter(truth.vertices))});
    stats.max_polygon = std::max(stats.max_polygon, miss / tolerance);
    if (!(miss <= tolerance))
      fail(stats, "coplanar polygon's diameter missed by " + std::to_string(miss), pair);
  } else if (ref.conditioned || ref.coplanar) {
    ++stats.compared;
    const double miss = miss_of_truth(from, to, truth);
    stats.max_miss = std::max(stats.max_miss, miss / tolerance);
    if (!(miss <= tolerance)) fail(stats, "CGAL's point or segment missed by " + std::to_string(miss), pair);
  }
  // (d) the normal.
  const double length = c.normal.norm();
  if (length == 0 ? !(degenerate(ref.p) && degenerate(ref.q)) : !(std::abs(length - 1) <= 1e-12))
    fail(stats, "normal of length " + std::to_string(length), pair);
  if (!c.coplanar && ref.conditioned) {
    const double along = std::abs(c.normal.dot(to - from));
    const double allowed = kRelative * (to - from).norm() + tolerance;
    stats.max_normal = std::max(stats.max_normal, along / allowed);
    if (!(along <= allowed)) fail(stats, "normal not perpendicular: " + std::to_string(along), pair);
  }
}

// Per pair: nullopt exactly when the triangles do not intersect (CGAL's predicates), then the contact and
// that of the swapped pair (vertices permuted, orientations reflected) against CGAL's exact intersection.
void check_pair(const Pair& pair, Rng& rng, FamilyStats& stats) {
  ++stats.pairs;
  const bool intersecting = triangles_intersect_exact(pair.p, pair.q);
  const std::optional<TriangleContact> contact = triangle_contact(pair.p, pair.q);
  if (contact.has_value() != intersecting)
    return fail(stats, intersecting ? "intersecting, no contact" : "disjoint, a contact", pair);
  if (!intersecting) return;
  ++stats.intersecting;
  const Normalised n(pair);
  Reference ref{exact_shape(n.p), exact_shape(n.q), {}, false, false, 0};
  ref.truth = exact_intersection(ref.p, ref.q);
  if (ref.truth.kind == Truth::Kind::none) return fail(stats, "CGAL finds no intersection", pair);
  ref.conditioned = degenerate(ref.p) || degenerate(ref.q) || plane_sine(n.p, n.q) > kWellConditioned;
  const ExactPoint p0 = exact_point(n.p[0]), p1 = exact_point(n.p[1]), p2 = exact_point(n.p[2]);
  ref.coplanar =
      !degenerate(ref.p) && !degenerate(ref.q) && CGAL::coplanar(p0, p1, p2, exact_point(n.q[0])) &&
      CGAL::coplanar(p0, p1, p2, exact_point(n.q[1])) && CGAL::coplanar(p0, p1, p2, exact_point(n.q[2]));
  ref.size = n.local(std::max(longest_edge(pair.p), longest_edge(pair.q)));
  stats.coplanar += contact->coplanar;
  check_contact(*contact, pair, n, ref, stats);

  const Pair swapped{permuted(pair.q, rng), permuted(pair.p, rng)};
  const std::optional<TriangleContact> other = triangle_contact(swapped.p, swapped.q);
  if (!other) return fail(stats, "swapped: no contact", pair);
  check_contact(*other, swapped, n, ref, stats);
}

void check_family(const char* name, std::uint64_t seed, std::size_t count, const Generator& generate) {
  Rng rng(seed);
  FamilyStats stats;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < count / kFamilyScale; ++i) check_pair(generate(rng), rng, stats);
  const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
  std::printf(
      "[family] %-24s pairs=%zu intersecting=%zu compared=%zu coplanar=%zu | over tolerance: off=%.3g "
      "miss=%.3g polygon=%.3g normal=%.3g | failures=%zu (%.0f ms)\n",
      name, stats.pairs, stats.intersecting, stats.compared, stats.coplanar, stats.max_off, stats.max_miss,
      stats.max_polygon, stats.max_normal, stats.failures, elapsed.count());
  ::testing::Test::RecordProperty(std::string(name) + "_max_off", std::to_string(stats.max_off));
  EXPECT_EQ(stats.failures, 0u) << name << ": " << stats.first_failure;
  EXPECT_GE(stats.intersecting, stats.pairs / 20) << name << ": too few intersecting pairs to mean much";
}

// ---- generators of this test; the shared ones are in support/triangle_families.hpp ---------------------

constexpr std::size_t kPairs = 2'000;

// Q meeting P's corner p[0] from the opposite cone, at P's edge midpoint, or along P's edge (whole or half).
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

// A random direction times 1e-12..1e-2, for `sharing`.
Vec3 small_offset(Rng& rng) {
  const Vec3 direction = random_unit(rng);
  return direction * log_uniform(rng, -12, -2);
}

// Q almost in P's plane: each vertex 1e-15..1e-12 off it, on a random side.
Pair near_parallel(Rng& rng) {
  const TrianglePoints p = general_pair(rng).p;
  const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
  TrianglePoints q;
  for (Vec3& v : q) {
    const double s = uniform(rng, -0.5, 1.2), t = uniform(rng, -0.5, 1.2);
    const double offset = (coin(rng) ? 1.0 : -1.0) * log_uniform(rng, -15, -12);
    v = p[0] + s * (p[1] - p[0]) + t * (p[2] - p[0]) + offset * n;
  }
  return {p, q};
}

// A sliver (third vertex 1e-14..1e-3 off the long edge) or a needle (one edge that short) through y.
TrianglePoints thin_through(Rng& rng, const Vec3& y) {
  const bool needle = coin(rng);
  const double thin = log_uniform(rng, -14, -3);
  const Vec3 along = random_unit(rng);
  const Vec3 side = along.cross(random_unit(rng)).normalized();
  const double back = uniform(rng, 0.05, 0.5), ahead = uniform(rng, 0.05, 0.5);
  const Vec3 a = y - back * along, b = y + ahead * along;
  const double t = needle ? 1.0 : uniform(rng, -0.5, 1.5);
  return {a, b, a + t * (b - a) + thin * side};
}

// Two thin triangles, Q's long edge through a point of P (rounded, then moved 1e-16..1e-12): both prisms
// have needle-sharp corners, and most pairs cross.
Pair thin_pair(Rng& rng) {
  const TrianglePoints p = thin_through(rng, uniform_point(rng, -0.2, 0.2));
  const double u = uniform(rng, 0, 1), v = uniform(rng, 0, 1 - u);
  const Vec3 moved = random_unit(rng) * log_uniform(rng, -16, -12);
  const Vec3 y = p[0] + u * (p[1] - p[0]) + v * (p[2] - p[0]) + moved;
  return {permuted(p, rng), permuted(thin_through(rng, y), rng)};
}

// ---- families ------------------------------------------------------------------------------------------

TEST(TriangleContactFamilies, GeneralPosition) {
  check_family("general_position", 1, kPairs, general_pair);
}

TEST(TriangleContactFamilies, Coplanar) {
  check_family("coplanar_overlapping", 2, kPairs, [](Rng& rng) {
    const LatticePlane plane = LatticePlane::random(rng);
    const Tri2 p = random_tri2(rng, 20), q = shifted2(random_tri2(rng, 20), lattice2(rng, 30));
    return Pair{permuted(plane.map(p), rng), permuted(plane.map(q), rng)};
  });
  check_family("coplanar_touching", 3, kPairs, [](Rng& rng) { return coplanar_touching(rng, touching_q); });
}

TEST(TriangleContactFamilies, Sharing) {
  check_family("shared_edge", 4, kPairs, [](Rng& rng) { return sharing(rng, 2, small_offset); });
  check_family("shared_vertex", 5, kPairs, [](Rng& rng) { return sharing(rng, 1, small_offset); });
}

TEST(TriangleContactFamilies, VertexOnOrNearFace) {
  check_family("vertex_on_face", 6, kPairs, [](Rng& rng) { return vertex_on_face(rng, false); });
  check_family("vertex_near_face", 7, kPairs, vertex_near_face);
}

TEST(TriangleContactFamilies, NearParallel) {
  check_family("near_parallel", 8, kPairs, near_parallel);
}

TEST(TriangleContactFamilies, Degenerate) {
  check_family("degenerate_vs_triangle", 9, kPairs, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 4), grid_triangle(rng, 4)};
  });
  check_family("near_degenerate", 10, kPairs, near_degenerate);
  check_family("thin_pairs", 18, kPairs, thin_pair);
  check_family("degenerate_on_face", 11, kPairs, [](Rng& rng) { return vertex_on_face(rng, true); });
  check_family("degenerate_vs_degenerate", 12, kPairs, [](Rng& rng) {
    return Pair{degenerate_triangle(rng, 2), degenerate_triangle(rng, 2)};
  });
}

TEST(TriangleContactFamilies, AxisAligned) {
  check_family("axis_aligned", 13, kPairs, [](Rng& rng) {
    return Pair{axis_aligned_triangle(rng), axis_aligned_triangle(rng)};
  });
}

TEST(TriangleContactFamilies, Scales) {
  for_each_scale_family(general_pair, 14, [](const char* name, std::uint64_t seed, const Generator& make) {
    check_family(name, seed, kPairs, make);
  });
}

// ---- hand-written cases ----------------------------------------------------------------------------------

const Vec3 kO(0, 0, 0), kX(1, 0, 0), kY(0, 1, 0), kZ(0, 0, 1);

// The ends equal {a, b} in either order, within `tolerance`.
::testing::AssertionResult ends_are(const TriangleContact& c, const Vec3& a, const Vec3& b,
                                    double tolerance) {
  const double same = std::max((c.from - a).norm(), (c.to - b).norm());
  const double miss = std::min(same, std::max((c.from - b).norm(), (c.to - a).norm()));
  if (miss <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "from " << c.from.transpose() << " to " << c.to.transpose() << " misses by " << miss;
}

// P in z = 0 (normal +z), Q in x = 0.5 (normal -x) crossing it: they meet in x = 0.5, y in [0, 1.5].
const TrianglePoints kFloor = {kO, Vec3(2, 0, 0), Vec3(0, 2, 0)};
const TrianglePoints kWall = {Vec3(0.5, -1, -1), Vec3(0.5, -1, 1), Vec3(0.5, 3, 0)};

TEST(TriangleContactCases, CrossingInAKnownSegment) {
  const auto c = triangle_contact(kFloor, kWall);
  ASSERT_TRUE(c);
  EXPECT_TRUE(ends_are(*c, Vec3(0.5, 0, 0), Vec3(0.5, 1.5, 0), 1e-15));
  EXPECT_FALSE(c->coplanar);
  EXPECT_TRUE(c->normal.isApprox(Vec3(1, 0, 1).normalized(), 1e-15)) << c->normal.transpose();
  // Swapped: the same segment, the normal reversed.
  const auto back = triangle_contact(kWall, kFloor);
  ASSERT_TRUE(back);
  EXPECT_TRUE(ends_are(*back, Vec3(0.5, 0, 0), Vec3(0.5, 1.5, 0), 1e-15));
  EXPECT_TRUE(back->normal.isApprox(-c->normal, 1e-15));
  // Moved up by 3: apart.
  EXPECT_FALSE(triangle_contact(kFloor, translated(kWall, Vec3(0, 0, 3))));
}

TEST(TriangleContactCases, FaceToFaceIsCoplanarAlongThePolygonsDiameter) {
  const TrianglePoints p = {kO, kX, kY};
  // Q inside P, facing the other way (normal -z): the contact is Q itself, whose longest side is its
  // diameter.
  const TrianglePoints q = {Vec3(0.1, 0.1, 0), Vec3(0.1, 0.5, 0), Vec3(0.5, 0.1, 0)};
  const auto c = triangle_contact(p, q);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->coplanar);
  EXPECT_TRUE(ends_are(*c, Vec3(0.1, 0.5, 0), Vec3(0.5, 0.1, 0), 1e-14));
  EXPECT_EQ(c->normal, kZ);
  // The same orientation: n_p - n_q vanishes, n_p stands for it.
  const auto same = triangle_contact(p, {q[0], q[2], q[1]});
  ASSERT_TRUE(same);
  EXPECT_TRUE(same->coplanar);
  EXPECT_EQ(same->normal, kZ);
  // Overlapping partly: P ∩ Q' is the triangle (0.5, 0), (1, 0), (0.5, 0.5).
  const auto part = triangle_contact(p, {Vec3(0.5, 0, 0), Vec3(0.5, 2, 0), Vec3(2, 0, 0)});
  ASSERT_TRUE(part);
  EXPECT_TRUE(part->coplanar);
  EXPECT_TRUE(ends_are(*part, Vec3(1, 0, 0), Vec3(0.5, 0.5, 0), 1e-14));  // its longest side
}

TEST(TriangleContactCases, VertexOnAFaceIsAPoint) {
  const TrianglePoints p = {kO, kX, kY};
  const auto c = triangle_contact(p, {Vec3(0.25, 0.25, 0), Vec3(0, 0, 1), Vec3(1, 1, 1)});
  ASSERT_TRUE(c);
  EXPECT_TRUE(ends_are(*c, Vec3(0.25, 0.25, 0), Vec3(0.25, 0.25, 0), 1e-15));
  EXPECT_FALSE(c->coplanar);
  EXPECT_NEAR(c->normal.norm(), 1, 1e-15);
  EXPECT_FALSE(triangle_contact(p, {Vec3(0.25, 0.25, 1e-300), Vec3(0, 0, 1), Vec3(1, 1, 1)}));
}

TEST(TriangleContactCases, SharedEdgeIsTheWholeEdge) {
  const TrianglePoints p = {kO, kX, kY};
  for (const Vec3& apex : {Vec3(0.3, -1, 0.7), Vec3(0.3, 1, 0.7), Vec3(0.3, 0.1, 1e-3)}) {
    const auto c = triangle_contact(p, {kX, kO, apex});
    ASSERT_TRUE(c) << apex.transpose();
    EXPECT_TRUE(ends_are(*c, kO, kX, 1e-15)) << apex.transpose();
  }
}

TEST(TriangleContactCases, DegenerateTriangles) {
  const TrianglePoints p = {kO, kX, kY};
  // A segment through the face: one point; lying in the face: its part over the face.
  const auto through = triangle_contact(p, {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 1)});
  ASSERT_TRUE(through);
  EXPECT_TRUE(ends_are(*through, Vec3(0.2, 0.2, 0), Vec3(0.2, 0.2, 0), 1e-15));
  EXPECT_EQ(through->normal, kZ);
  const auto lying = triangle_contact({Vec3(-1, 0.25, 0), Vec3(2, 0.25, 0), Vec3(2, 0.25, 0)}, p);
  ASSERT_TRUE(lying);
  EXPECT_TRUE(ends_are(*lying, Vec3(0, 0.25, 0), Vec3(0.75, 0.25, 0), 1e-15));
  EXPECT_FALSE(lying->coplanar);
  EXPECT_EQ(lying->normal, -kZ);  // P has no normal: -n_q
  // Two segments along one line overlap in a segment; crossing ones meet in a point; no normal.
  const auto collinear =
      triangle_contact({kO, Vec3(2, 0, 0), kX}, {Vec3(1.5, 0, 0), Vec3(3, 0, 0), Vec3(3, 0, 0)});
  ASSERT_TRUE(collinear);
  EXPECT_TRUE(ends_are(*collinear, Vec3(1.5, 0, 0), Vec3(2, 0, 0), 1e-15));
  EXPECT_EQ(collinear->normal, Vec3::Zero());
  const auto crossing = triangle_contact({kO, Vec3(2, 2, 0), kO}, {Vec3(2, 0, 0), kY, kY});
  ASSERT_TRUE(crossing);
  EXPECT_TRUE(ends_are(*crossing, Vec3(2, 2, 0) / 3, Vec3(2, 2, 0) / 3, 1e-15));
  // Points.
  const auto on_face = triangle_contact({Vec3(0.2, 0.3, 0), Vec3(0.2, 0.3, 0), Vec3(0.2, 0.3, 0)}, p);
  ASSERT_TRUE(on_face);
  EXPECT_TRUE(ends_are(*on_face, Vec3(0.2, 0.3, 0), Vec3(0.2, 0.3, 0), 0));
  EXPECT_FALSE(triangle_contact({kZ, kZ, kZ}, p));
}

// The crossing case translated by 1e6 (exactly): the segment keeps the digits the representation allows.
TEST(TriangleContactCases, FarFromOriginKeepsRelativePrecision) {
  const Vec3 far = Vec3::Constant(1e6);
  const auto c = triangle_contact(translated(kFloor, far), translated(kWall, far));
  ASSERT_TRUE(c);
  const double tolerance = 4 * kEps * 1e6;  // a few ulps at 1e6: 1e-9 of the pair's size of 2
  EXPECT_TRUE(ends_are(*c, far + Vec3(0.5, 0, 0), far + Vec3(0.5, 1.5, 0), tolerance));
  EXPECT_TRUE(c->normal.isApprox(Vec3(1, 0, 1).normalized(), 1e-15));
}

TEST(TriangleContactCases, NonFiniteInputIsRejected) {
  const TrianglePoints p = {kO, kX, kY};
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)triangle_contact(p, {kO, Vec3(nan, 0, 0), kZ}), std::invalid_argument);
  EXPECT_THROW((void)triangle_contact({Vec3(inf, 0, 0), kX, kY}, p), std::invalid_argument);
  try {
    (void)triangle_contact(p, {kO, kX, Vec3(0, -inf, 0)});
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("Q vertex 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bvhlab
