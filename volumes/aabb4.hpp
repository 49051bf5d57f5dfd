// Four axis-aligned boxes side by side (structure of arrays), tested against four others in one pass of the
// vector unit: the children of a wide node (bvh/wide_bvh.hpp) against one box of the other tree, broadcast.
// Each lane holds a box as centre and half-extents in float, with `mag` = max |centre| + max half-extent for
// the rounding slack. The whole test runs in float, one lane per box, with a slack that covers its rounding
// (below): conservative like Aabb::overlap, never false where the boxes share a point.
#pragma once

#include "aabb.hpp"
#include "float_pose.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__) && !defined(BVHLAB_AABB4_SCALAR)
#define BVHLAB_AABB4_SSE2 1
#include <emmintrin.h>
#else
#define BVHLAB_AABB4_SSE2 0
#endif

namespace bvhlab {

struct alignas(16) Aabb4 {
  using Volume = Aabb;
  static constexpr int kLanes = 4;
  /// An unused lane: a box no test can reach (negative half-extents far beyond any coordinate).
  static constexpr float kEmptyHalf = -1e30f;

  std::array<float, 4> cx{}, cy{}, cz{};
  std::array<float, 4> hx{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf};
  std::array<float, 4> hy{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf};
  std::array<float, 4> hz{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf};
  std::array<float, 4> mag{};

  /// The pose in float (FloatPose: R, t' = R o_b + t - o_a, a bound on |t'|) and |R| rounded and widened so
  /// that it is >= the exact |R| entrywise.
  struct PairContext : FloatPose {
    std::array<float, 9> abs_rotation;  // row-major
  };

  /// Rounding bound of the float test, relative to the magnitudes it combines: B's centre moved by R_f and
  /// t_f (about 5u (1.74 max|c_b| + |t|), u = 2^-24, the rounding of R and t included), its re-boxed
  /// half-extents (3u of 1.74 max h_b) and the gap's three subtractions (3u of their operands) add up to
  /// less than 14u max|c_b| + 11u max h_b + 8u |t| + 3u (max|c_a| + max h_a). The slack
  /// 16 FLT_EPSILON (|t| + 2 mag_a + 2 mag_b) = 32u (...) is more than twice that, its own rounding included.
  static constexpr float kSlackFactor = 16 * std::numeric_limits<float>::epsilon();

  /// The context for lanes stored relative to origins (set() with `origin`): A's lanes around origin_a, B's
  /// around origin_b (float_pose.hpp).
  static PairContext make_context(const RigidTransform& pose, const Vec3& origin_a = Vec3::Zero(),
                                  const Vec3& origin_b = Vec3::Zero()) {
    PairContext c{FloatPose::of(pose, origin_a, origin_b), {}};
    for (int e = 0; e < 9; ++e) c.abs_rotation[e] = widened(std::abs(c.rotation[e]));
    return c;
  }

  /// Lane `lane` holds `box` (a non-empty Aabb) less `origin`: centre rounded to nearest, half-extents
  /// rounded up, with a margin for the double subtraction, so that the lane's box contains the stored one.
  void set(int lane, const Aabb& box, const Vec3& origin = Vec3::Zero()) {
    const Vec3 lo = to_vec(box.lo), hi = to_vec(box.hi);
    std::array<float, 3> c{}, h{};
    for (int k = 0; k < 3; ++k) {
      c[k] = rounded_to_float((lo[k] + hi[k]) * 0.5 - origin[k]);
      const double reach = std::max(hi[k] - origin[k] - c[k], c[k] - (lo[k] - origin[k]));
      const double rounding = 4 * std::numeric_limits<double>::epsilon() *
                              (std::abs(lo[k]) + std::abs(hi[k]) + std::abs(origin[k]) + std::abs(c[k]));
      h[k] = float_up(reach + rounding);
    }
    cx[lane] = c[0], cy[lane] = c[1], cz[lane] = c[2];
    hx[lane] = h[0], hy[lane] = h[1], hz[lane] = h[2];
    mag[lane] = float_up(std::max({std::abs(double(c[0])), std::abs(double(c[1])), std::abs(double(c[2]))}) +
                         std::max({double(h[0]), double(h[1]), double(h[2])}));
  }
  /// Lane `lane` as an empty box, which overlaps nothing.
  void clear(int lane) {
    cx[lane] = cy[lane] = cz[lane] = mag[lane] = 0;
    hx[lane] = hy[lane] = hz[lane] = kEmptyHalf;
  }
  /// Four lanes holding lane `lane` of `from`.
  static Aabb4 broadcast(const Aabb4& from, int lane) {
    Aabb4 out;
    for (int k = 0; k < kLanes; ++k) {
      out.cx[k] = from.cx[lane], out.cy[k] = from.cy[lane], out.cz[k] = from.cz[lane];
      out.hx[k] = from.hx[lane], out.hy[k] = from.hy[lane], out.hz[k] = from.hz[lane];
      out.mag[k] = from.mag[lane];
    }
    return out;
  }
  /// B's boxes placed in A's frame (place()) are Aabb4s too. A wide walk places them again when it needs
  /// them rather than keep them: three products a lane are cheaper than the memory (kKeepsPlaced).
  using Placed = Aabb4;
  static constexpr bool kKeepsPlaced = false;
  /// A wide walk meets many leaf pairs whose triangles' planes part them: it tests their planes four pairs at
  /// once (traversal/wide_exact.hpp; layouts without this member test pair by pair).
  static constexpr bool kBatchesLeafPairs = true;
  static Placed broadcast_placed(const Placed& from, int lane) { return broadcast(from, lane); }
  /// Per lane, the squared distance between the centres of `a`'s lane and `b`'s (placed in A's frame): the
  /// wide walk takes the nearest of the overlapping pairs first (traversal/wide_exact.hpp).
  static std::array<float, 4> center_distances(const Aabb4& a, const Placed& b) {
    return squared_center_distances(a, b);
  }
  /// The box volume of a lane (the descent splits the larger of two nodes).
  [[nodiscard]] float volume(int lane) const { return hx[lane] * hy[lane] * hz[lane]; }
  [[nodiscard]] bool empty(int lane) const { return hx[lane] < 0; }

  /// Bit k set: lane k of `a` (A's frame) and lane k of `b` (B's frame, placed by the pose) may overlap.
  /// Lanes of an empty box never do. place() then overlap_placed(), in the vector unit where there is SSE2:
  /// the float operations of overlap_scalar in the same order, so both answer alike
  /// (tests/volumes/test_aabb4.cpp).
  [[gnu::always_inline]] static unsigned overlap(const Aabb4& a, const Aabb4& b, const PairContext& c) {
    return overlap_placed(a, place(b, c), c);
  }

  /// The reference: lane by lane in scalar float.
  static unsigned overlap_scalar(const Aabb4& a, const Aabb4& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float bc[3] = {b.cx[k], b.cy[k], b.cz[k]};
      const float bh[3] = {b.hx[k], b.hy[k], b.hz[k]};
      const float ac[3] = {a.cx[k], a.cy[k], a.cz[k]};
      const float ah[3] = {a.hx[k], a.hy[k], a.hz[k]};
      const float slack = kSlackFactor * (c.translation_magnitude + 2 * (a.mag[k] + b.mag[k]));
      bool apart = false;
      for (int r = 0; r < 3; ++r) {
        const float* R = &c.rotation[3 * r];
        const float* A = &c.abs_rotation[3 * r];
        const float center = ((R[0] * bc[0] + R[1] * bc[1]) + R[2] * bc[2]) + c.translation[r];
        const float half = (A[0] * bh[0] + A[1] * bh[1]) + A[2] * bh[2];
        const float gap = (std::abs(center - ac[r]) - ah[r]) - half;
        apart = apart || !(gap <= slack);
      }
      if (!apart) mask |= 1u << k;
    }
    return mask;
  }

#if BVHLAB_AABB4_SSE2
  /// B's four boxes placed in A's frame: centres R c + t, half-extents |R| h (float, the pose's context);
  /// mag stays B's own, for the slack.
  [[gnu::always_inline]] static Aabb4 place(const Aabb4& b, const PairContext& c) {
    const __m128 bcx = _mm_load_ps(b.cx.data()), bcy = _mm_load_ps(b.cy.data()),
                 bcz = _mm_load_ps(b.cz.data());
    const __m128 bhx = _mm_load_ps(b.hx.data()), bhy = _mm_load_ps(b.hy.data()),
                 bhz = _mm_load_ps(b.hz.data());
    Aabb4 out;
    float* centers[3] = {out.cx.data(), out.cy.data(), out.cz.data()};
    float* halves[3] = {out.hx.data(), out.hy.data(), out.hz.data()};
    for (int r = 0; r < 3; ++r) {
      const float* R = &c.rotation[3 * r];
      const float* A = &c.abs_rotation[3 * r];
      _mm_store_ps(centers[r], _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(R[0]), bcx),
                                                                _mm_mul_ps(_mm_set1_ps(R[1]), bcy)),
                                                     _mm_mul_ps(_mm_set1_ps(R[2]), bcz)),
                                          _mm_set1_ps(c.translation[r])));
      _mm_store_ps(halves[r], _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(A[0]), bhx),
                                                    _mm_mul_ps(_mm_set1_ps(A[1]), bhy)),
                                         _mm_mul_ps(_mm_set1_ps(A[2]), bhz)));
    }
    out.mag = b.mag;
    return out;
  }
  /// overlap() of A's boxes and B's already placed ones (place()).
  [[gnu::always_inline]] static unsigned overlap_placed(const Aabb4& a, const Aabb4& placed,
                                                        const PairContext& c) {
    const __m128 slack = _mm_mul_ps(
        _mm_set1_ps(kSlackFactor),
        _mm_add_ps(_mm_set1_ps(c.translation_magnitude),
                   _mm_mul_ps(_mm_set1_ps(2),
                              _mm_add_ps(_mm_load_ps(a.mag.data()), _mm_load_ps(placed.mag.data())))));
    const __m128 sign = _mm_set1_ps(-0.0f);
    const float* centers_a[3] = {a.cx.data(), a.cy.data(), a.cz.data()};
    const float* halves_a[3] = {a.hx.data(), a.hy.data(), a.hz.data()};
    const float* centers_b[3] = {placed.cx.data(), placed.cy.data(), placed.cz.data()};
    const float* halves_b[3] = {placed.hx.data(), placed.hy.data(), placed.hz.data()};
    __m128 apart = _mm_setzero_ps();
    for (int r = 0; r < 3; ++r) {
      const __m128 distance =
          _mm_andnot_ps(sign, _mm_sub_ps(_mm_load_ps(centers_b[r]), _mm_load_ps(centers_a[r])));
      const __m128 gap = _mm_sub_ps(_mm_sub_ps(distance, _mm_load_ps(halves_a[r])), _mm_load_ps(halves_b[r]));
      apart = _mm_or_ps(apart, _mm_cmpnle_ps(gap, slack));  // not (gap <= slack): NaN counts as apart
    }
    return static_cast<unsigned>(_mm_movemask_ps(apart)) ^ 0xFu;
  }
#else
  static Aabb4 place(const Aabb4& b, const PairContext& c) {
    Aabb4 out;
    for (int k = 0; k < kLanes; ++k) {
      const float bc[3] = {b.cx[k], b.cy[k], b.cz[k]}, bh[3] = {b.hx[k], b.hy[k], b.hz[k]};
      float* centers[3] = {&out.cx[k], &out.cy[k], &out.cz[k]};
      float* halves[3] = {&out.hx[k], &out.hy[k], &out.hz[k]};
      for (int r = 0; r < 3; ++r) {
        const float* R = &c.rotation[3 * r];
        const float* A = &c.abs_rotation[3 * r];
        *centers[r] = ((R[0] * bc[0] + R[1] * bc[1]) + R[2] * bc[2]) + c.translation[r];
        *halves[r] = (A[0] * bh[0] + A[1] * bh[1]) + A[2] * bh[2];
      }
    }
    out.mag = b.mag;
    return out;
  }
  static unsigned overlap_placed(const Aabb4& a, const Aabb4& placed, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float slack = kSlackFactor * (c.translation_magnitude + 2 * (a.mag[k] + placed.mag[k]));
      const float bc[3] = {placed.cx[k], placed.cy[k], placed.cz[k]},
                  bh[3] = {placed.hx[k], placed.hy[k], placed.hz[k]};
      const float ac[3] = {a.cx[k], a.cy[k], a.cz[k]}, ah[3] = {a.hx[k], a.hy[k], a.hz[k]};
      bool apart = false;
      for (int r = 0; r < 3; ++r) apart = apart || !((std::abs(bc[r] - ac[r]) - ah[r]) - bh[r] <= slack);
      if (!apart) mask |= 1u << k;
    }
    return mask;
  }
#endif
};

}  // namespace bvhlab
