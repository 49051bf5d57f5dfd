// Inline, exact triangle-triangle test for the traversal's hot path.
//
// Design: a plane-interval test (Guigue-Devillers style) built only from sign(orient3d), each evaluated
// in double and accepted only when a certified forward error bound proves the sign. When any sign is
// unproven -- which covers every zero (touching, coplanar, degenerate triangles) and every overflow or NaN
// -- the pair goes to CGAL (triangles_intersect_exact). So the result equals CGAL's on every input: the
// filter never guesses, it only declines. A merely conservative test (report "touching" within a
// tolerance) was rejected: it makes results depend on scale and turns grazing contacts into false
// positives, which would pollute the false-positive rates the ADB experiments measure.
//
// Nothing is precomputed per triangle: the caller passes the six vertices.
#pragma once

#include "triangle_intersection.hpp"

#include <cmath>
#include <utility>

namespace bvhlab {

enum class FilteredVerdict : signed char { disjoint, intersecting, undecided };

namespace tri_detail {

// orient(a, b, c, d) := det[b - a, c - a, d - a] = n . w with n = (b - a) x (c - a), w = d - a.
// Evaluated as written below; the bound is Shewchuk-style (relative to the permanent), derived here for
// exactly this evaluation order. eps = 2^-53, round to nearest.
//
// Rounding: each of the 6 monomials u_i v_j w_k of det passes through at most 8 roundings (the three
// differences are rounded too, then the inner product, the 2x2 subtraction, the outer product, two
// additions), so |det_computed - det| <= ((1 + eps)^8 - 1) P, P = sum of |monomials| of the exact
// differences. |exact difference| <= |rounded| / (1 - eps) and the permanent below takes at most 6 monotone
// roundings of non-negative values, so P <= perm / (1 - eps)^9; two more round the bound itself. Hence
// kRelativeBound = 8 eps (1 + 16 eps) >= ((1 + eps)^8 - 1) / (1 - eps)^11, exactly 2^-50 + 2^-99.
//
// Underflow (the relative model fails for subnormal results): a subnormal product has an absolute error
// <= 2^-1075; additions with subnormal results are exact. The six inner products' errors are scaled by |w_i|,
// the three outer ones are not: total <= 2^-1074 (|w|_1 (1 + 5 eps) + 1.5 (1 + 2 eps)). kUnderflowGuard is
// added to each inner magnitude sum and contributes kRelativeBound * 2^-600 |w_i| per axis, far above
// 2^-1074 |w_i| (where |w_i| 2^-600 itself underflows, that axis needs less than 2^-1490); kUnderflowFloor
// adds kRelativeBound * 2^-1018 = 2^-1068 for the constant part and for rounding the bound itself.
// Both constants are normal numbers on purpose: subnormal operands or results cost ~100 cycles on x86, and
// 2^-600 keeps |w_i| abs_i normal even for axis-aligned triangles (where an inner sum is exactly zero).
// The price: triangles smaller than ~1e-95 (so n is below ~2^-650) are always left to CGAL.
//
// Overflow and NaN need no test: every intermediate of perm dominates the matching one of det in magnitude,
// so any overflow or NaN makes perm, hence the bound, inf or NaN, and then both comparisons are false: the
// sign is "unproven". (This needs IEEE semantics: no -ffast-math / -ffinite-math-only. FMA contraction is
// harmless: it only removes roundings.)
inline constexpr double kRelativeBound = 0x1p-50 + 0x1p-99;
inline constexpr double kUnderflowGuard = 0x1p-600;
inline constexpr double kUnderflowFloor = 0x1p-1018;

// The oriented plane through a, b, c with the magnitudes needed for the error bound.
struct FilteredPlane {
  double ox, oy, oz;           // a
  double nx, ny, nz;           // rounded (b - a) x (c - a)
  double abs_x, abs_y, abs_z;  // |u_y v_z| + |u_z v_y| + kUnderflowGuard etc.

  FilteredPlane(const Vec3& a, const Vec3& b, const Vec3& c) : ox(a.x()), oy(a.y()), oz(a.z()) {
    const double ux = b.x() - ox, uy = b.y() - oy, uz = b.z() - oz;
    const double vx = c.x() - ox, vy = c.y() - oy, vz = c.z() - oz;
    const double yz = uy * vz, zy = uz * vy, zx = uz * vx, xz = ux * vz, xy = ux * vy, yx = uy * vx;
    nx = yz - zy;
    ny = zx - xz;
    nz = xy - yx;
    abs_x = (std::fabs(yz) + std::fabs(zy)) + kUnderflowGuard;
    abs_y = (std::fabs(zx) + std::fabs(xz)) + kUnderflowGuard;
    abs_z = (std::fabs(xy) + std::fabs(yx)) + kUnderflowGuard;
  }

  // +1 / -1 when sign(orient(a, b, c, d)) is proven, 0 when it is not (zero, near zero, NaN, overflow).
  [[nodiscard]] int certified_side(const Vec3& d) const {
    const double wx = d.x() - ox, wy = d.y() - oy, wz = d.z() - oz;
    const double det = wx * nx + wy * ny + wz * nz;
    const double permanent = std::fabs(wx) * abs_x + std::fabs(wy) * abs_y + std::fabs(wz) * abs_z;
    const double bound = kRelativeBound * (permanent + kUnderflowFloor);
    return static_cast<int>(det > bound) - static_cast<int>(det < -bound);
  }
};

inline int certified_orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return FilteredPlane(a, b, c).certified_side(d);
}

// Index of the vertex whose (non-zero) side differs from the other two; the signs are not all equal.
inline int lone_vertex(int s0, int s1, int s2) {
  return s0 == s1 ? 2 : (s0 == s2 ? 1 : 0);
}

}  // namespace tri_detail

/// Decides the pair in double arithmetic when every sign it needs is certified; otherwise `undecided`.
/// Never wrong: a decided verdict equals CGAL's exact answer (closed triangles, touching intersects).
///
/// Why the final two orientations decide (own derivation): let both triangles be non-degenerate and
/// non-coplanar with all six vertex-plane signs non-zero and each triangle straddling the other's plane.
/// Rotate P so p0 is alone on its side of plane(Q) and Q so q0 is alone on its side of plane(P); swap
/// q1, q2 (flips n_Q) so that p0 is on the positive side of plane(Q), and p1, p2 so that q0 is on the
/// positive side of plane(P). On the line L = plane(P) n plane(Q), directed by d = n_P x n_Q, P covers
/// [j, i] (i on edge p0p1, j on p0p2) and Q covers [k, l] (k on q0q1, l on q0q2). Since
/// orient(p0, p1, q0, q1) = ((p1 - p0) x (q1 - q0)) . (i - k) and ((p1 - p0) x (q1 - q0)) . d =
/// -(n_Q.(p0 - p1)) (n_P.(q0 - q1)) < 0, we get k <= i  <=>  orient(p0, p1, q0, q1) <= 0; likewise
/// j <= l  <=>  orient(p0, p2, q0, q2) >= 0. The intervals overlap iff both hold.
inline FilteredVerdict triangles_intersect_filtered(const Vec3& p0, const Vec3& p1, const Vec3& p2,
                                                    const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  using tri_detail::certified_orient;
  using tri_detail::FilteredPlane;
  constexpr auto undecided = FilteredVerdict::undecided;

  const FilteredPlane plane_p(p0, p1, p2);
  const int sq[3] = {plane_p.certified_side(q0), plane_p.certified_side(q1), plane_p.certified_side(q2)};
  if (sq[0] == 0 || sq[1] == 0 || sq[2] == 0) return undecided;
  if (sq[0] == sq[1] && sq[1] == sq[2]) return FilteredVerdict::disjoint;

  const FilteredPlane plane_q(q0, q1, q2);
  const int sp[3] = {plane_q.certified_side(p0), plane_q.certified_side(p1), plane_q.certified_side(p2)};
  if (sp[0] == 0 || sp[1] == 0 || sp[2] == 0) return undecided;
  if (sp[0] == sp[1] && sp[1] == sp[2]) return FilteredVerdict::disjoint;

  const Vec3* const p[3] = {&p0, &p1, &p2};
  const Vec3* const q[3] = {&q0, &q1, &q2};
  const int ip = tri_detail::lone_vertex(sp[0], sp[1], sp[2]);
  const int iq = tri_detail::lone_vertex(sq[0], sq[1], sq[2]);
  const Vec3& a = *p[ip];
  const Vec3* b = p[(ip + 1) % 3];
  const Vec3* c = p[(ip + 2) % 3];
  const Vec3& d = *q[iq];
  const Vec3* e = q[(iq + 1) % 3];
  const Vec3* f = q[(iq + 2) % 3];
  if (sq[iq] < 0) std::swap(b, c);  // flips n_P, so q's apex becomes positive
  if (sp[ip] < 0) std::swap(e, f);  // flips n_Q, so p's apex becomes positive

  const int first = certified_orient(a, *b, d, *e);
  if (first == 0) return undecided;
  if (first > 0) return FilteredVerdict::disjoint;
  const int second = certified_orient(a, *c, d, *f);
  if (second == 0) return undecided;
  return second > 0 ? FilteredVerdict::intersecting : FilteredVerdict::disjoint;
}

/// Exact on every input: the certified double path, CGAL for what it cannot prove (touching, coplanar,
/// degenerate, NaN/inf: the latter throw std::invalid_argument from triangles_intersect_exact).
inline bool triangles_intersect_fast(const TrianglePoints& p, const TrianglePoints& q) {
  const FilteredVerdict verdict = triangles_intersect_filtered(p[0], p[1], p[2], q[0], q[1], q[2]);
  if (verdict != FilteredVerdict::undecided) [[likely]]
    return verdict == FilteredVerdict::intersecting;
  return triangles_intersect_exact(p, q);
}

inline bool triangles_intersect_fast(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0,
                                     const Vec3& q1, const Vec3& q2) {
  const FilteredVerdict verdict = triangles_intersect_filtered(p0, p1, p2, q0, q1, q2);
  if (verdict != FilteredVerdict::undecided) [[likely]]
    return verdict == FilteredVerdict::intersecting;
  return triangles_intersect_exact({p0, p1, p2}, {q0, q1, q2});
}

}  // namespace bvhlab
