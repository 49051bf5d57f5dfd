// Random and adversarial triangle pairs for the exact triangle tests, intersection
// (tests/bvh/test_triangle_intersection.cpp) and distance (tests/bvh/test_triangle_distance.cpp): general
// position, coplanar pairs on an exact lattice, shared vertices and edges, vertices exactly or nearly on a
// face, degenerate and near-degenerate triangles, axis-aligned triangles and rescaled pairs, with the small
// helpers they are built from. Each test draws them from its own fixed seeds, so changing what a family draws
// changes the pairs of both tests.
//
// Random draws in a fixed order (braces, one per statement): g++ and clang evaluate function arguments in
// different orders, and a draw inside an argument list would give each compiler other pairs.
#pragma once

#include "bench/core/generators.hpp"
#include "volumes/geometry.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>

namespace bvhlab::testing {

using Rng = std::mt19937_64;

// ---- small helpers -----------------------------------------------------------------------------------

inline long long integer(Rng& rng, long long lo, long long hi) {
  return std::uniform_int_distribution<long long>(lo, hi)(rng);
}
inline bool coin(Rng& rng) {
  return integer(rng, 0, 1) == 1;
}
inline double log_uniform(Rng& rng, double lo_exponent, double hi_exponent) {
  return std::pow(10.0, generators::uniform(rng, lo_exponent, hi_exponent));
}
inline Vec3 integer_point(Rng& rng, long long lo, long long hi) {
  return Vec3{double(integer(rng, lo, hi)), double(integer(rng, lo, hi)), double(integer(rng, lo, hi))};
}
// One of the 6 vertex orders, reflections included (they flip the orientation the test must not rely on).
inline TrianglePoints permuted(const TrianglePoints& t, Rng& rng) {
  static constexpr int kOrders[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  const auto& o = kOrders[integer(rng, 0, 5)];
  return {t[o[0]], t[o[1]], t[o[2]]};
}
inline TrianglePoints translated(const TrianglePoints& t, const Vec3& by) {
  return {t[0] + by, t[1] + by, t[2] + by};
}
inline TrianglePoints scaled(const TrianglePoints& t, double s) {
  return {t[0] * s, t[1] * s, t[2] * s};
}
// For small-integer triangles only (products exact).
inline bool exactly_degenerate(const TrianglePoints& t) {
  return (t[1] - t[0]).cross(t[2] - t[0]).isZero(0.0);
}

// The vertices with every bit (hexadecimal floats), for failure messages.
inline std::string describe(const TrianglePoints& t) {
  std::ostringstream out;
  char buffer[96];
  for (const Vec3& v : t) {
    std::snprintf(buffer, sizeof buffer, "(%a, %a, %a) ", v.x(), v.y(), v.z());
    out << buffer;
  }
  return out.str();
}

// ---- pairs -------------------------------------------------------------------------------------------

struct Pair {
  TrianglePoints p, q;
  std::optional<bool> known = std::nullopt;  // the answer by construction, when the family guarantees one
};
using Generator = std::function<Pair(Rng&)>;

// Two triangles whose centres lie in a common box: about half intersect.
inline Pair general_pair(Rng& rng) {
  const TrianglePoints p = generators::random_triangle(rng, generators::uniform_point(rng, 0.0, 0.5));
  return {p, generators::random_triangle(rng, generators::uniform_point(rng, 0.0, 0.5))};
}

// ---- coplanar pairs on a lattice -----------------------------------------------------------------------

// An exactly representable plane: integer origin and integer basis, times a power of two. Lattice
// points (i, j) map to exact doubles, so coplanarity and touching are exact, not rounded.
struct LatticePlane {
  Vec3 origin, e1, e2;
  double unit = 1.0;
  static LatticePlane random(Rng& rng) {
    LatticePlane plane;
    do {
      plane.e1 = integer_point(rng, -9, 9);
      plane.e2 = integer_point(rng, -9, 9);
    } while (plane.e1.cross(plane.e2).isZero(0.0));
    plane.origin = integer_point(rng, -1000, 1000);
    plane.unit = std::ldexp(1.0, int(integer(rng, -20, 20)));
    return plane;
  }
  [[nodiscard]] Vec3 at(const Eigen::Vector2d& ij) const {
    return (origin + ij.x() * e1 + ij.y() * e2) * unit;
  }
  [[nodiscard]] TrianglePoints map(const std::array<Eigen::Vector2d, 3>& t) const {
    return {at(t[0]), at(t[1]), at(t[2])};
  }
};
using Tri2 = std::array<Eigen::Vector2d, 3>;
inline Eigen::Vector2d lattice2(Rng& rng, long long r) {
  return {double(integer(rng, -r, r)), double(integer(rng, -r, r))};
}
inline bool degenerate2(const Tri2& t) {
  const Eigen::Vector2d u = t[1] - t[0], v = t[2] - t[0];
  return u.x() * v.y() - u.y() * v.x() == 0.0;
}
inline Tri2 random_tri2(Rng& rng, long long r) {
  Tri2 t;
  do t = {lattice2(rng, r), lattice2(rng, r), lattice2(rng, r)};
  while (degenerate2(t));
  return t;
}
inline Tri2 shifted2(const Tri2& t, const Eigen::Vector2d& by) {
  return {t[0] + by, t[1] + by, t[2] + by};
}

// P on the lattice with even coordinates and Q = touching_q(rng, P) touching it exactly. Half of the pairs
// touch (known: true); the other half move Q by one small lattice step, which makes it overlap or separate.
inline Pair coplanar_touching(Rng& rng, const std::function<Tri2(Rng&, const Tri2&)>& touching_q) {
  const LatticePlane plane = LatticePlane::random(rng);
  Tri2 p = random_tri2(rng, 20);
  p = {2.0 * p[0], 2.0 * p[1], 2.0 * p[2]};  // even coordinates: edge midpoints are lattice points
  Tri2 q;
  do q = touching_q(rng, p);
  while (degenerate2(q));
  std::optional<bool> known = true;
  if (coin(rng)) {
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    do step = lattice2(rng, 2);
    while (step.isZero(0.0));
    q = shifted2(q, step);
    known.reset();
  }
  return {permuted(plane.map(p), rng), permuted(plane.map(q), rng), known};
}

// ---- contacts in general position ----------------------------------------------------------------------

// Sharing a vertex (shared == 1) or an edge (shared == 2), not coplanar: exact sharing half the time
// (known: true), else Q moved by the small vector `offset(rng)`. The tests draw that vector's direction and
// length in different orders, so each passes its own.
inline Pair sharing(Rng& rng, int shared, const std::function<Vec3(Rng&)>& offset) {
  const Pair base = general_pair(rng);
  TrianglePoints q = base.q;
  q[0] = base.p[0];
  if (shared == 2) q[1] = base.p[1];
  std::optional<bool> known = true;
  if (coin(rng)) {
    q = translated(q, offset(rng));
    known.reset();
  }
  return {permuted(base.p, rng), permuted(q, rng), known};
}

// Integer triangle P = m * G and a lattice point q0 = a G0 + b G1 + c G2 (a + b + c = m) exactly on its
// face or an edge; Q's other vertices on one side. Half the time Q moves one unit along an axis.
// With `collapse`, Q becomes a point, a segment or a collinear triple that still contains q0.
inline Pair vertex_on_face(Rng& rng, bool collapse) {
  std::array<Vec3, 3> g;
  do g = {integer_point(rng, -40, 40), integer_point(rng, -40, 40), integer_point(rng, -40, 40)};
  while (exactly_degenerate(g));
  long long a, b, c;
  do {
    a = integer(rng, 0, 5);
    b = integer(rng, 0, 5);
    c = integer(rng, 0, 5);
  } while (int(a > 0) + int(b > 0) + int(c > 0) < 2);
  const double m = double(a + b + c);
  const TrianglePoints p = {m * g[0], m * g[1], m * g[2]};
  const Vec3 q0 = double(a) * g[0] + double(b) * g[1] + double(c) * g[2];
  const Vec3 normal = (p[1] - p[0]).cross(p[2] - p[0]);  // small integers: exact
  const double side = coin(rng) ? 1.0 : -1.0;
  const auto off_plane = [&]() -> Vec3 {
    Vec3 v = Vec3::Zero();
    do v = integer_point(rng, -30, 30);
    while (side * normal.dot(v) <= 0.0);
    return q0 + v;
  };
  TrianglePoints q = {q0, off_plane(), off_plane()};
  if (collapse) {
    switch (integer(rng, 0, 2)) {
      case 0:
        q = {q0, q0, q0};
        break;
      case 1:
        q = {q0, q[1], q[1]};
        break;
      default:
        q = {q[1], q0 + 2.0 * (q[1] - q0), q0};
    }
  }
  std::optional<bool> known = true;
  if (coin(rng)) {
    Vec3 step = Vec3::Zero();
    step[integer(rng, 0, 2)] = coin(rng) ? 1.0 : -1.0;
    q = translated(q, step);
    known.reset();
  }
  const double unit = std::ldexp(1.0, int(integer(rng, -30, 30)));
  return {permuted(scaled(p, unit), rng), permuted(scaled(q, unit), rng), known};
}

// Q's vertex at a barycentric point of P computed in double: on the face up to rounding.
inline Pair vertex_near_face(Rng& rng) {
  const TrianglePoints p = general_pair(rng).p;
  const double a = generators::uniform(rng, 0, 1), b = generators::uniform(rng, 0, 1 - a);
  const Vec3 on_face = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]);
  const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]);
  const double side = coin(rng) ? 1.0 : -1.0;
  TrianglePoints q = {on_face, on_face + generators::uniform_point(rng, -0.5, 0.5),
                      on_face + generators::uniform_point(rng, -0.5, 0.5)};
  for (int i = 1; i < 3; ++i)
    if (side * n.dot(q[i] - on_face) < 0) q[i] = on_face - (q[i] - on_face);
  return {p, permuted(q, rng)};
}

// ---- degenerate and special triangles ------------------------------------------------------------------

// Degenerate "triangles" on a small integer grid, so coincidences are frequent and exact.
inline TrianglePoints degenerate_triangle(Rng& rng, long long grid) {
  const Vec3 a = integer_point(rng, 0, grid);
  switch (integer(rng, 0, 3)) {
    case 0:  // a point
      return {a, a, a};
    case 1: {  // a repeated vertex
      return {a, a, integer_point(rng, 0, grid)};
    }
    default: {  // three collinear points, middle one anywhere in the order, possibly repeated
      Vec3 d = Vec3::Zero();
      do d = integer_point(rng, -1, 1);
      while (d.isZero(0.0));
      return {a + double(integer(rng, -2, 2)) * d, a + double(integer(rng, -2, 2)) * d,
              a + double(integer(rng, -2, 2)) * d};
    }
  }
}
// A proper triangle on the same grid.
inline TrianglePoints grid_triangle(Rng& rng, long long grid) {
  TrianglePoints t;
  do t = {integer_point(rng, 0, grid), integer_point(rng, 0, grid), integer_point(rng, 0, grid)};
  while (exactly_degenerate(t));
  return t;
}

// P's third vertex the rounded point a + t (b - a): almost, rarely exactly, a segment.
inline Pair near_degenerate(Rng& rng) {
  const Pair base = general_pair(rng);
  TrianglePoints p = base.p;
  p[2] = p[0] + generators::uniform(rng, -0.5, 1.5) * (p[1] - p[0]);
  return {permuted(p, rng), base.q};
}

// Triangles in axis planes (CAD-like): exact zeros inside the normal and many exact contacts.
inline TrianglePoints axis_aligned_triangle(Rng& rng) {
  const int axis = int(integer(rng, 0, 2));
  const double level = double(integer(rng, 0, 8)) / 2;
  TrianglePoints t;
  do {
    for (Vec3& v : t) {
      v = generators::uniform(rng, 0, 1) < 0.5 ? integer_point(rng, 0, 4)
                                               : generators::uniform_point(rng, 0, 4);
      v[axis] = level;
    }
  } while ((t[1] - t[0]).cross(t[2] - t[0]).isZero(0.0));
  return t;
}

// ---- scales --------------------------------------------------------------------------------------------

// The pair `base` draws, scaled by `scale(rng)`, then translated by `offset(rng)` (drawn in that order).
// The translation rounds, which can join or separate the triangles: no known answer.
inline Generator rescaled(const Generator& base, const std::function<double(Rng&)>& scale,
                          const std::function<Vec3(Rng&)>& offset) {
  return [=](Rng& rng) {
    const Pair pair = base(rng);
    const double s = scale(rng);
    const Vec3 by = offset(rng);
    return Pair{translated(scaled(pair.p, s), by), translated(scaled(pair.q, s), by)};
  };
}
// A fixed scale and offset: no draws besides those of `base`.
inline Generator rescaled(const Generator& base, double scale, const Vec3& offset) {
  return rescaled(
      base, [scale](Rng&) { return scale; }, [offset](Rng&) { return offset; });
}

/// The scale families of `base`: size 1e-3 around (1e6, 1e6, 1e6) +- 1e5 (the translation to a vertex must
/// keep their digits), 1e-6, 1e6, and powers of two 2^-900..2^1000 (squares and products under- or overflow
/// without a local rescaling). Each is handed to check(name, seed, generator), seeds first_seed onwards.
template <class Check>
void for_each_scale_family(const Generator& base, std::uint64_t first_seed, Check&& check) {
  check("tiny_far", first_seed,
        rescaled(
            base, [](Rng&) { return 1e-3; },
            [](Rng& rng) { return Vec3(Vec3::Constant(1e6) + generators::uniform_point(rng, -1e5, 1e5)); }));
  check("scale_1e-6", first_seed + 1, rescaled(base, 1e-6, Vec3::Zero()));
  check("scale_1e6", first_seed + 2, rescaled(base, 1e6, Vec3::Zero()));
  check("scale_2^-900..2^1000", first_seed + 3,
        rescaled(
            base, [](Rng& rng) { return std::ldexp(1.0, int(integer(rng, -900, 1000))); },
            [](Rng&) { return Vec3(Vec3::Zero()); }));
}

}  // namespace bvhlab::testing
