// Four oriented boxes side by side (structure of arrays: each axis entry, centre coordinate and half-extent
// for four lanes together, in float), tested against four others in one pass of the vector unit: the
// children of a wide node (bvh/wide_bvh.hpp) against one box of the other tree, broadcast. The test is the
// OBB's 15-axis separating-axis test (obb.hpp) on four lanes; one template computes it for the vector unit
// and, lane by lane, for the scalar reference, in the same order. Centres are stored relative to an origin.
#pragma once

#include "float_pose.hpp"
#include "obb.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#if defined(__SSE2__) && !defined(BVHLAB_OBB4_SCALAR)
#define BVHLAB_OBB4_SSE2 1
#include <emmintrin.h>
#else
#define BVHLAB_OBB4_SSE2 0
#endif

namespace bvhlab {

namespace obb4_detail {
#if BVHLAB_OBB4_SSE2
/// Four floats in the vector unit, with the few operations the test needs.
struct F4 {
  __m128 v;
};
inline F4 operator+(F4 a, F4 b) {
  return {_mm_add_ps(a.v, b.v)};
}
inline F4 operator-(F4 a, F4 b) {
  return {_mm_sub_ps(a.v, b.v)};
}
inline F4 operator*(F4 a, F4 b) {
  return {_mm_mul_ps(a.v, b.v)};
}
inline F4 abs(F4 a) {
  return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)};
}
inline F4 max(F4 a, F4 b) {
  return {_mm_max_ps(a.v, b.v)};
}
inline F4 zero_like(F4) {
  return {_mm_setzero_ps()};
}
inline F4 splat_like(F4, float x) {
  return {_mm_set1_ps(x)};
}
inline F4 operator/(F4 a, F4 b) {
  return {_mm_div_ps(a.v, b.v)};
}
/// `value` where `x` >= `threshold`, else 0.
inline F4 where_at_least(F4 x, F4 threshold, F4 value) {
  return {_mm_and_ps(_mm_cmpge_ps(x.v, threshold.v), value.v)};
}
#endif
inline float abs(float a) {
  return std::abs(a);
}
inline float max(float a, float b) {
  return a > b ? a : b;
}
inline float zero_like(float) {
  return 0;
}
inline float splat_like(float, float x) {
  return x;
}
inline float where_at_least(float x, float threshold, float value) {
  return x >= threshold ? value : 0.0f;
}
}  // namespace obb4_detail

struct alignas(16) Obb4 {
  using Volume = Obb;
  static constexpr int kLanes = 4;
  static constexpr float kEmptyHalf = -1e30f;
  using Row = std::array<float, 4>;

  /// Entry (k, i) of the frame (axis i's k-th coordinate) at axes[3 k + i]; centre relative to the origin.
  std::array<Row, 9> axes{};
  std::array<Row, 3> center{};
  std::array<Row, 3> half = {Row{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf},
                             Row{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf},
                             Row{kEmptyHalf, kEmptyHalf, kEmptyHalf, kEmptyHalf}};
  Row mag{};  ///< per lane, max |centre| + the sum of the half-extents: the slack's scale

  using PairContext = FloatPose;

  /// Rounding bound, relative to M = mag_a + mag_b + |t| (u = 2^-24): the frames' and the pose's rounding to
  /// float moves every projection by a few u of the half-extents; B's axes in A's box frame (m = A^T R B)
  /// round by about 10u a unit entry, covered by widening |m| by kWidenM; B's centre in A's box frame by
  /// about 20u M; the face gaps of B and the edge gaps combine the centre with m, up to about 60u M. The
  /// slack 64 FLT_EPSILON M = 128u M is twice that.
  static constexpr float kSlackFactor = 64 * std::numeric_limits<float>::epsilon();
  static constexpr float kWidenM = 32 * std::numeric_limits<float>::epsilon();
  /// The distance bound's squares, sums and root round by a few float ulps, and the face axes are unit to a
  /// few: the bound is shrunk by this factor to stay below the distance.
  static constexpr float kBoundRounding = 1 - 16 * std::numeric_limits<float>::epsilon();
  /// The distance bound's shortest edge axis, squared (obb.hpp's kMinEdgeAxis).
  static constexpr float kMinEdgeAxisSquared = 0.01f;

  /// The pose for lanes stored relative to origin_a (A's) and origin_b (B's): float_pose.hpp.
  static PairContext make_context(const RigidTransform& pose, const Vec3& origin_a = Vec3::Zero(),
                                  const Vec3& origin_b = Vec3::Zero()) {
    return FloatPose::of(pose, origin_a, origin_b);
  }

  /// Lane `lane` holds `box` (not empty) less `origin`: its frame (axes_of, as the double test uses it) and
  /// centre rounded to nearest, the half-extents grown by the centre's move and rounded up.
  void set(int lane, const Obb& box, const Vec3& origin = Vec3::Zero()) {
    const Mat3 frame = Obb::axes_of(box.orientation);
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) axes[3 * k + i][lane] = static_cast<float>(frame(k, i));
    const Vec3 exact = to_vec(box.center) - origin;
    double moved = 0, largest = 0, sum = 0;
    for (int k = 0; k < 3; ++k) {
      center[k][lane] = rounded_to_float(exact[k]);
      moved += std::abs(exact[k] - center[k][lane]);
      largest = std::max(largest, std::abs(double(center[k][lane])));
    }
    const double rounding = origin_shift_rounding(to_vec(box.center).cwiseAbs().sum(), origin);
    for (int k = 0; k < 3; ++k) {
      half[k][lane] = float_up(double(box.half[k]) + moved + rounding);
      sum += half[k][lane];
    }
    mag[lane] = float_up(largest + sum);
  }
  static Obb4 broadcast(const Obb4& from, int lane) {
    Obb4 out;
    for (int e = 0; e < 9; ++e) out.axes[e].fill(from.axes[e][lane]);
    for (int k = 0; k < 3; ++k)
      out.center[k].fill(from.center[k][lane]), out.half[k].fill(from.half[k][lane]);
    out.mag.fill(from.mag[lane]);
    return out;
  }
  /// The volume of a lane's box (the descent splits the larger of two nodes).
  [[nodiscard]] float volume(int lane) const { return half[0][lane] * half[1][lane] * half[2][lane]; }
  [[nodiscard]] bool empty(int lane) const { return half[0][lane] < 0; }

  /// B's boxes placed in A's object frame (axes R B, centres R c + t) are Obb4s too. Keeping them for later
  /// steps (kKeepsPlaced) measured no faster than placing again (bench/RESULTS.md, "Wide trees").
  using Placed = Obb4;
  static constexpr bool kKeepsPlaced = false;
  static Placed broadcast_placed(const Placed& from, int lane) { return broadcast(from, lane); }
  /// Per lane, the squared distance between the centres of `a`'s lane and `b`'s (placed in A's frame): the
  /// wide walk takes the nearest of the overlapping pairs first (traversal/wide_exact.hpp).
  static Row center_distances(const Obb4& a, const Placed& b) {
    Row out{};
    for (int k = 0; k < kLanes; ++k)
      for (int r = 0; r < 3; ++r) {
        const float d = a.center[r][k] - b.center[r][k];
        out[k] += d * d;
      }
    return out;
  }

  /// Bit k set: lane k of `a` and lane k of `b` (placed by the pose) may overlap; empty lanes never do.
  static unsigned overlap(const Obb4& a, const Obb4& b, const PairContext& c) {
    return overlap_placed(a, place(b, c), c);
  }

  /// The reference: lane by lane in scalar float, the same template as the vector path.
  static unsigned overlap_scalar(const Obb4& a, const Obb4& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      Lane<float> la = load_lane(a, k), lb = load_lane(b, k);
      lb = place_lane(lb, c, [](float x) { return x; });
      const float slack = kSlackFactor * ((a.mag[k] + b.mag[k]) + c.translation_magnitude);
      if (!(largest_gap(la, lb, kWidenM) > slack)) mask |= 1u << k;
    }
    return mask;
  }

  /// The distance bound on four lanes (the wide distance walk, traversal/wide_distance.hpp): per lane a
  /// lower bound on the distance between `a`'s box and `b`'s (placed), the larger of the Euclidean lengths
  /// of the three face gaps in either box's frame or an edge-axis gap over the axis's length, each gap less
  /// overlap()'s slack: obb.hpp's bound, in float. Infinity for an empty lane. A lane's bound is positive
  /// only where overlap_placed() parts it (the same face gaps, computed alike).
  static Row distance_bounds_scalar(const Obb4& a, const Placed& b, const PairContext& c) {
    Row out{};
    for (int k = 0; k < kLanes; ++k) {
      const float slack = kSlackFactor * ((a.mag[k] + b.mag[k]) + c.translation_magnitude);
      const float squared = squared_bound(load_lane(a, k), load_lane(b, k), kWidenM, slack);
      out[k] = a.empty(k) || b.empty(k) ? std::numeric_limits<float>::infinity()
                                        : std::sqrt(squared) * kBoundRounding;
    }
    return out;
  }

#if BVHLAB_OBB4_SSE2
  [[gnu::always_inline]] static Placed place(const Obb4& b, const PairContext& c) {
    const Lane<obb4_detail::F4> placed =
        place_lane(load_vector(b), c, [](float x) { return obb4_detail::F4{_mm_set1_ps(x)}; });
    Obb4 out;
    for (int e = 0; e < 9; ++e) _mm_store_ps(out.axes[e].data(), placed.axes[e].v);
    for (int k = 0; k < 3; ++k) _mm_store_ps(out.center[k].data(), placed.center[k].v);
    out.half = b.half;
    out.mag = b.mag;
    return out;
  }
  [[gnu::always_inline]] static unsigned overlap_placed(const Obb4& a, const Placed& b,
                                                        const PairContext& c) {
    using obb4_detail::F4;
    const F4 slack =
        F4{_mm_set1_ps(kSlackFactor)} * ((F4{_mm_load_ps(a.mag.data())} + F4{_mm_load_ps(b.mag.data())}) +
                                         F4{_mm_set1_ps(c.translation_magnitude)});
    // A's face axes first: where they separate all four lanes (a gap only grows with more axes), the
    // other twelve cannot change the answer.
    const Lane<F4> la = load_vector(a), lb = load_vector(b);
    Relative<F4> r;
    F4 gap = face_gap_a(la, lb, F4{_mm_set1_ps(kWidenM)}, r);
    if (_mm_movemask_ps(_mm_cmpgt_ps(gap.v, slack.v)) == 0xF) return 0;
    gap = other_gap(la, lb, r, gap);
    return static_cast<unsigned>(_mm_movemask_ps(_mm_cmpgt_ps(gap.v, slack.v))) ^ 0xFu;
  }
  [[gnu::always_inline]] static Row distance_bounds(const Obb4& a, const Placed& b, const PairContext& c) {
    return bounds_of(load_vector(a), load_vector(b), load_row(a.mag), load_row(b.mag), c);
  }
  /// The walk's two steps, without an Obb4 made for the broadcast or placed volumes (building one costs
  /// its 64 floats twice): lane `a_lane` of `a` against B's `b_children`, placed by the pose, and A's
  /// `a_children` against lane `b_lane` of `b`, placed. Equal to distance_bounds on broadcast() and place().
  [[gnu::always_inline]] static Row distance_bounds_to_b(const Obb4& a, int a_lane, const Obb4& b_children,
                                                         const PairContext& c) {
    return bounds_of(load_broadcast(a, a_lane), place_lane(load_vector(b_children), c, splat_float),
                     obb4_detail::F4{_mm_set1_ps(a.mag[a_lane])}, load_row(b_children.mag), c);
  }
  [[gnu::always_inline]] static Row distance_bounds_to_a(const Obb4& a_children, const Obb4& b, int b_lane,
                                                         const PairContext& c) {
    return bounds_of(load_vector(a_children), place_lane(load_broadcast(b, b_lane), c, splat_float),
                     load_row(a_children.mag), obb4_detail::F4{_mm_set1_ps(b.mag[b_lane])}, c);
  }
#else
  static Placed place(const Obb4& b, const PairContext& c) {
    Obb4 out = b;
    for (int k = 0; k < kLanes; ++k) {
      const Lane<float> placed = place_lane(load_lane(b, k), c, [](float x) { return x; });
      for (int e = 0; e < 9; ++e) out.axes[e][k] = placed.axes[e];
      for (int r = 0; r < 3; ++r) out.center[r][k] = placed.center[r];
    }
    return out;
  }
  static unsigned overlap_placed(const Obb4& a, const Placed& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float slack = kSlackFactor * ((a.mag[k] + b.mag[k]) + c.translation_magnitude);
      if (!(largest_gap(load_lane(a, k), load_lane(b, k), kWidenM) > slack)) mask |= 1u << k;
    }
    return mask;
  }
  static Row distance_bounds(const Obb4& a, const Placed& b, const PairContext& c) {
    return distance_bounds_scalar(a, b, c);
  }
  static Row distance_bounds_to_b(const Obb4& a, int a_lane, const Obb4& b_children, const PairContext& c) {
    return distance_bounds_scalar(broadcast(a, a_lane), place(b_children, c), c);
  }
  static Row distance_bounds_to_a(const Obb4& a_children, const Obb4& b, int b_lane, const PairContext& c) {
    return distance_bounds_scalar(a_children, place(broadcast(b, b_lane), c), c);
  }
#endif

 private:
  /// One box in the lane type V (float for one lane, F4 for four).
  template <class V>
  struct Lane {
    V axes[9], center[3], half[3];
  };
  static Lane<float> load_lane(const Obb4& b, int k) {
    Lane<float> out;
    for (int e = 0; e < 9; ++e) out.axes[e] = b.axes[e][k];
    for (int r = 0; r < 3; ++r) out.center[r] = b.center[r][k], out.half[r] = b.half[r][k];
    return out;
  }
#if BVHLAB_OBB4_SSE2
  [[gnu::always_inline]] static Lane<obb4_detail::F4> load_vector(const Obb4& b) {
    Lane<obb4_detail::F4> out;
    for (int e = 0; e < 9; ++e) out.axes[e] = {_mm_load_ps(b.axes[e].data())};
    for (int r = 0; r < 3; ++r)
      out.center[r] = {_mm_load_ps(b.center[r].data())}, out.half[r] = {_mm_load_ps(b.half[r].data())};
    return out;
  }
  [[gnu::always_inline]] static Lane<obb4_detail::F4> load_broadcast(const Obb4& b, int k) {
    Lane<obb4_detail::F4> out;
    for (int e = 0; e < 9; ++e) out.axes[e] = {_mm_set1_ps(b.axes[e][k])};
    for (int r = 0; r < 3; ++r)
      out.center[r] = {_mm_set1_ps(b.center[r][k])}, out.half[r] = {_mm_set1_ps(b.half[r][k])};
    return out;
  }
  [[gnu::always_inline]] static obb4_detail::F4 load_row(const Row& row) {
    return {_mm_load_ps(row.data())};
  }
  [[gnu::always_inline]] static obb4_detail::F4 splat(float x) {
    return {_mm_set1_ps(x)};
  }
  static constexpr auto splat_float = [](float x) { return obb4_detail::F4{_mm_set1_ps(x)}; };
  /// The four bounds of A's lanes `la` and B's placed lanes `lb` (scales `mag_a`, `mag_b`): as
  /// distance_bounds_scalar, lane by lane.
  [[gnu::always_inline]] static Row bounds_of(const Lane<obb4_detail::F4>& la,
                                              const Lane<obb4_detail::F4>& lb, obb4_detail::F4 mag_a,
                                              obb4_detail::F4 mag_b, const PairContext& c) {
    using obb4_detail::F4;
    const F4 slack = splat(kSlackFactor) * ((mag_a + mag_b) + splat(c.translation_magnitude));
    const F4 squared = squared_bound(la, lb, splat(kWidenM), slack);
    const __m128 bound = _mm_mul_ps(_mm_sqrt_ps(squared.v), _mm_set1_ps(kBoundRounding));
    const __m128 zero = _mm_setzero_ps();
    const __m128 empty = _mm_or_ps(_mm_cmplt_ps(la.half[0].v, zero), _mm_cmplt_ps(lb.half[0].v, zero));
    Row out;
    _mm_storeu_ps(out.data(),
                  _mm_or_ps(_mm_and_ps(empty, _mm_set1_ps(std::numeric_limits<float>::infinity())),
                            _mm_andnot_ps(empty, bound)));
    return out;
  }
#endif
  /// B's frame and centre moved into A's object frame: R B and R c + t (`splat` makes a V of a float).
  template <class V, class Splat>
  [[gnu::always_inline]] static Lane<V> place_lane(Lane<V> b, const PairContext& c, Splat splat) {
    const float* R = c.rotation.data();
    Lane<V> out = b;
    for (int r = 0; r < 3; ++r) {
      for (int i = 0; i < 3; ++i)
        out.axes[3 * r + i] = (splat(R[3 * r]) * b.axes[i] + splat(R[3 * r + 1]) * b.axes[3 + i]) +
                              splat(R[3 * r + 2]) * b.axes[6 + i];
      out.center[r] = ((splat(R[3 * r]) * b.center[0] + splat(R[3 * r + 1]) * b.center[1]) +
                       splat(R[3 * r + 2]) * b.center[2]) +
                      splat(c.translation[r]);
    }
    return out;
  }
  /// B's axes and centre offset in A's box frame, shared by the 15 axes.
  template <class V>
  struct Relative {
    V m[3][3], am[3][3], t[3];  ///< m = A^T B, am = |m| widened, t = A^T (c_b - c_a)
  };
  /// The largest gap over A's three face axes (> 0 where one separates), filling `r` for the other twelve.
  template <class V, class W>
  [[gnu::always_inline]] static V face_gap_a(const Lane<V>& a, const Lane<V>& b, W widen_by, Relative<V>& r) {
    using obb4_detail::abs;
    using obb4_detail::max;
    const V widen = V(widen_by);
    const V d[3] = {b.center[0] - a.center[0], b.center[1] - a.center[1], b.center[2] - a.center[2]};
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        r.m[i][j] = (a.axes[i] * b.axes[j] + a.axes[3 + i] * b.axes[3 + j]) + a.axes[6 + i] * b.axes[6 + j];
        r.am[i][j] = abs(r.m[i][j]) + widen;
      }
      r.t[i] = (a.axes[i] * d[0] + a.axes[3 + i] * d[1]) + a.axes[6 + i] * d[2];
    }
    const V* hb = b.half;
    V gap = abs(r.t[0]) - a.half[0] - ((r.am[0][0] * hb[0] + r.am[0][1] * hb[1]) + r.am[0][2] * hb[2]);
    for (int i = 1; i < 3; ++i)
      gap = max(gap,
                abs(r.t[i]) - a.half[i] - ((r.am[i][0] * hb[0] + r.am[i][1] * hb[1]) + r.am[i][2] * hb[2]));
    return gap;
  }
  /// `gap` (A's face axes) with B's three face axes and the nine edge pairs taken in.
  template <class V>
  [[gnu::always_inline]] static V other_gap(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r, V gap) {
    using obb4_detail::abs;
    using obb4_detail::max;
    const V* ha = a.half;
    const V* hb = b.half;
    for (int j = 0; j < 3; ++j)
      gap = max(gap, abs((r.t[0] * r.m[0][j] + r.t[1] * r.m[1][j]) + r.t[2] * r.m[2][j]) -
                         ((r.am[0][j] * ha[0] + r.am[1][j] * ha[1]) + r.am[2][j] * ha[2]) - hb[j]);
    return largest_edge_gap(a, b, r, gap, std::make_integer_sequence<int, 9>{});
  }
  // The nine edge axes written out, each with constant indices: as loops, the compiler kept the outer one,
  // its (i + 1) % 3 index arithmetic and m in memory (the pinion's wide distance query ran 13% more
  // instructions in these bounds). Axis 3 i + j is a_i x b_j, taken in that order, so the results are the
  // loops' to the bit.
  template <class V, int... axis>
  [[gnu::always_inline]] static V largest_edge_gap(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r,
                                                   V gap, std::integer_sequence<int, axis...>) {
    using obb4_detail::max;
    ((gap = max(gap, edge_gap<axis / 3, axis % 3>(a, b, r))), ...);
    return gap;
  }
  /// |T . L| - radius_a - radius_b on the edge axis a_i x b_j (not a unit vector).
  template <int i, int j, class V>
  [[gnu::always_inline]] static V edge_gap(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r) {
    constexpr int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    const V distance = obb4_detail::abs(r.t[i2] * r.m[i1][j] - r.t[i1] * r.m[i2][j]);
    const V radius_a = a.half[i1] * r.am[i2][j] + a.half[i2] * r.am[i1][j];
    const V radius_b = b.half[j1] * r.am[i][j2] + b.half[j2] * r.am[i][j1];
    return distance - radius_a - radius_b;
  }
  /// The square of the bound (before kBoundRounding): the face gaps (less `slack`, where positive) squared
  /// and summed over each box's three axes, the larger of the two sums, or a larger square of an edge-axis
  /// gap over its axis's length. The gaps are written as face_gap_a and other_gap write them, so that a
  /// positive bound implies a gap overlap_placed() counts.
  template <class V, class W>
  [[gnu::always_inline]] static V squared_bound(const Lane<V>& a, const Lane<V>& b, W widen_by, V slack) {
    using obb4_detail::abs;
    using obb4_detail::max;
    Relative<V> r;
    (void)face_gap_a(a, b, widen_by, r);
    const V zero = obb4_detail::zero_like(slack);
    V on_a = zero, on_b = zero;
    for (int i = 0; i < 3; ++i) {
      const V radius_b = (r.am[i][0] * b.half[0] + r.am[i][1] * b.half[1]) + r.am[i][2] * b.half[2];
      const V gap = max(zero, abs(r.t[i]) - a.half[i] - radius_b - slack);
      on_a = on_a + gap * gap;
    }
    for (int j = 0; j < 3; ++j) {
      const V distance = abs((r.t[0] * r.m[0][j] + r.t[1] * r.m[1][j]) + r.t[2] * r.m[2][j]);
      const V radius_a = (r.am[0][j] * a.half[0] + r.am[1][j] * a.half[1]) + r.am[2][j] * a.half[2];
      const V gap = max(zero, distance - radius_a - b.half[j] - slack);
      on_b = on_b + gap * gap;
    }
    return edge_axes(a, b, r, slack, max(on_a, on_b));
  }
  /// `best` raised by the nine edge axes a_i x b_j. An axis is not unit: its gap counts divided by its
  /// length, computed from m and lengthened by what m's rounding may hide (kWidenM an entry), and axes
  /// within about 6 degrees of parallel are left out, as in obb.hpp's bound.
  template <class V>
  [[gnu::always_inline]] static V edge_axes(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r, V slack,
                                            V best) {
    return edge_axes(a, b, r, slack, best, std::make_integer_sequence<int, 9>{});
  }
  template <class V, int... axis>
  [[gnu::always_inline]] static V edge_axes(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r, V slack,
                                            V best, std::integer_sequence<int, axis...>) {
    ((best = obb4_detail::max(best, edge_axis_square<axis / 3, axis % 3>(a, b, r, slack))), ...);
    return best;
  }
  /// The square of the edge axis a_i x b_j's gap (less `slack`) over its length, 0 for a short axis.
  template <int i, int j, class V>
  [[gnu::always_inline]] static V edge_axis_square(const Lane<V>& a, const Lane<V>& b, const Relative<V>& r,
                                                   V slack) {
    constexpr int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    const V zero = obb4_detail::zero_like(slack);
    const V shortest = obb4_detail::splat_like(slack, kMinEdgeAxisSquared);
    const V lengthen = obb4_detail::splat_like(slack, 6 * kWidenM);
    const V gap = obb4_detail::max(zero, edge_gap<i, j>(a, b, r) - slack);
    const V length = r.m[i1][j] * r.m[i1][j] + r.m[i2][j] * r.m[i2][j];
    return obb4_detail::where_at_least(length, shortest, gap * gap / (length + lengthen));
  }
  /// The largest gap over the 15 axes of A's box `a` and B's placed box `b` (obb.hpp's test; > 0 where an
  /// axis separates), |m| widened by `widen`.
  template <class V, class W>
  [[gnu::always_inline]] static V largest_gap(const Lane<V>& a, const Lane<V>& b, W widen_by) {
    Relative<V> r;
    const V gap = face_gap_a(a, b, widen_by, r);
    return other_gap(a, b, r, gap);
  }
};

}  // namespace bvhlab
