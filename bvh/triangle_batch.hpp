// Four triangle pairs at once: the plane tests of the exact triangle test
// (bvh/triangle_intersection_fast.hpp) as a first rejection, one pair per lane. A pair is apart when the
// three vertices of one triangle lie strictly on one side of the other's plane, each side certified as there
// (the same operations in the same order, and the same error bound): such a pair is disjoint in exact
// arithmetic, so a walk may skip its exact test. A pair not rejected goes to the exact test as before, which
// stays the reference.
//
// The lanes are GCC/Clang vector types of two doubles (one SSE2 register; four-double types would change
// the calling convention on builds without AVX), the four pairs as two halves.
// `triangle_pairs_apart_scalar` is the reference, lane by lane.
#pragma once

#include "triangle_intersection_fast.hpp"

#include <cstring>

namespace bvhlab {

/// Four triangle pairs side by side (structure of arrays): coordinate c of vertex v of lane k's P is
/// p[v][c][k], likewise q. Unused lanes may hold anything finite; the caller ignores their bits.
struct TrianglePairs4 {
  alignas(32) double p[3][3][4];
  alignas(32) double q[3][3][4];

  void set(int lane, const TrianglePoints& tp, const TrianglePoints& tq) {
    set_p(lane, tp);
    set_q(lane, tq);
  }
  void set_p(int lane, const TrianglePoints& t) { put(p, lane, t); }
  void set_q(int lane, const TrianglePoints& t) { put(q, lane, t); }
  /// Lane `to` takes lane `from`'s Q (or both triangles).
  void copy_q(int to, int from) {
    for (auto& vertex : q)
      for (auto& coordinate : vertex) coordinate[to] = coordinate[from];
  }
  void copy(int to, int from) {
    for (auto& vertex : p)
      for (auto& coordinate : vertex) coordinate[to] = coordinate[from];
    copy_q(to, from);
  }
  [[nodiscard]] TrianglePoints q_triangle(int lane) const {
    TrianglePoints t;
    for (int v = 0; v < 3; ++v) t[v] = Vec3(q[v][0][lane], q[v][1][lane], q[v][2][lane]);
    return t;
  }

 private:
  static void put(double (&to)[3][3][4], int lane, const TrianglePoints& t) {
    for (int v = 0; v < 3; ++v)
      for (int c = 0; c < 3; ++c) to[v][c][lane] = t[v][c];
  }
};

namespace tri_batch_detail {

using D2 = double __attribute__((vector_size(16)));
using M2 = decltype(D2{} < D2{});  ///< a comparison's lanes: all ones where true

[[gnu::always_inline]] inline D2 load(const double* x) {
  D2 v;
  std::memcpy(&v, x, sizeof v);
  return v;
}
[[gnu::always_inline]] inline D2 splat(double x) {
  return D2{x, x};
}
[[gnu::always_inline]] inline D2 abs(D2 x) {
  const M2 magnitude = M2{} + 0x7fff'ffff'ffff'ffff;
  return reinterpret_cast<D2>(reinterpret_cast<M2>(x) & magnitude);
}

/// tri_detail::FilteredPlane in two lanes: the plane through t[0], t[1], t[2] of lanes h and h + 1.
struct Plane2 {
  D2 ox, oy, oz, nx, ny, nz, abs_x, abs_y, abs_z;

  [[gnu::always_inline]] Plane2(const double (&t)[3][3][4], int h) {
    ox = load(t[0][0] + h), oy = load(t[0][1] + h), oz = load(t[0][2] + h);
    const D2 ux = load(t[1][0] + h) - ox, uy = load(t[1][1] + h) - oy, uz = load(t[1][2] + h) - oz;
    const D2 vx = load(t[2][0] + h) - ox, vy = load(t[2][1] + h) - oy, vz = load(t[2][2] + h) - oz;
    const D2 yz = uy * vz, zy = uz * vy, zx = uz * vx, xz = ux * vz, xy = ux * vy, yx = uy * vx;
    nx = yz - zy;
    ny = zx - xz;
    nz = xy - yx;
    const D2 guard = splat(tri_detail::kUnderflowGuard);
    abs_x = (abs(yz) + abs(zy)) + guard;
    abs_y = (abs(zx) + abs(xz)) + guard;
    abs_z = (abs(xy) + abs(yx)) + guard;
  }

  /// Lanes whose three vertices of `t` are certified strictly on one side (all above or all below).
  [[gnu::always_inline]] M2 all_on_one_side(const double (&t)[3][3][4], int h) const {
    M2 above = M2{} - 1, below = M2{} - 1;
    for (int v = 0; v < 3; ++v) {
      const D2 wx = load(t[v][0] + h) - ox, wy = load(t[v][1] + h) - oy, wz = load(t[v][2] + h) - oz;
      const D2 det = wx * nx + wy * ny + wz * nz;
      const D2 permanent = abs(wx) * abs_x + abs(wy) * abs_y + abs(wz) * abs_z;
      const D2 bound = splat(tri_detail::kRelativeBound) * (permanent + splat(tri_detail::kUnderflowFloor));
      above &= det > bound;
      below &= det < -bound;
    }
    return above | below;
  }
};

}  // namespace tri_batch_detail

/// Bit k set when pair k (k < n) is proven apart by a plane test (see the top of this file); never set for a
/// pair that touches or intersects, nor for one holding NaN or infinity (no sign is certified there). Lanes
/// go two at a time: for an odd n, lane n is computed too, so it must hold a finite pair (its bit is left
/// for the caller to ignore).
[[gnu::always_inline]] inline unsigned triangle_pairs_apart(const TrianglePairs4& pairs, int n = 4) {
  using tri_batch_detail::M2;
  using tri_batch_detail::Plane2;
  unsigned mask = 0;
  for (int h = 0; h < n; h += 2) {
    // Most pairs a walk meets are apart by P's plane already: Q's is computed only where one of the two is
    // not.
    M2 apart = Plane2(pairs.p, h).all_on_one_side(pairs.q, h);
    if (!(apart[0] & apart[1])) apart |= Plane2(pairs.q, h).all_on_one_side(pairs.p, h);
    mask |= (unsigned(apart[0] & 1) | unsigned(apart[1] & 2)) << h;
  }
  return mask;
}

/// The reference: the same tests, one lane at a time, with the scalar certified plane.
inline unsigned triangle_pairs_apart_scalar(const TrianglePairs4& pairs) {
  const auto vertex = [](const double(&t)[3][3][4], int v, int lane) {
    return Vec3(t[v][0][lane], t[v][1][lane], t[v][2][lane]);
  };
  const auto one_side = [&](const double(&plane)[3][3][4], const double(&points)[3][3][4], int lane) {
    const tri_detail::FilteredPlane f(vertex(plane, 0, lane), vertex(plane, 1, lane), vertex(plane, 2, lane));
    const int s0 = f.certified_side(vertex(points, 0, lane)), s1 = f.certified_side(vertex(points, 1, lane)),
              s2 = f.certified_side(vertex(points, 2, lane));
    return s0 != 0 && s0 == s1 && s1 == s2;
  };
  unsigned mask = 0;
  for (int lane = 0; lane < 4; ++lane)
    if (one_side(pairs.p, pairs.q, lane) || one_side(pairs.q, pairs.p, lane)) mask |= 1u << lane;
  return mask;
}

}  // namespace bvhlab
