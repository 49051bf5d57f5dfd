// Four k-DOPs side by side (structure of arrays: each plane's offset for four lanes together), tested in
// one pass of the vector unit against four others: the children of a wide node (bvh/wide_bvh.hpp) against
// one DOP of the other tree, broadcast. The test is KDop's re-alignment (kdop.hpp): on each of A's axes,
// B's support bounded by three of B's planes with the query's coefficients, plus the shift of the
// translation; here in float, four lanes at a time, with a slack that covers the rounding (below), so it
// stays conservative. Offsets are stored relative to an origin (the wide tree's root box centre).
#pragma once

#include "float_pose.hpp"
#include "kdop.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#if defined(__SSE2__) && !defined(BVHLAB_KDOP4_SCALAR)
#define BVHLAB_KDOP4_SSE2 1
#include <emmintrin.h>
#else
#define BVHLAB_KDOP4_SSE2 0
#endif

namespace bvhlab {

template <class Set>
struct alignas(16) KDop4 {
  using Volume = KDop<Set>;
  static constexpr int kLanes = 4;
  static constexpr std::size_t kAxes = Volume::kAxes;
  static constexpr std::size_t kPlanes = Volume::kPlanes;
  /// An unused lane: offsets far below any support, so its slabs are empty and it overlaps nothing.
  static constexpr float kEmptyOffset = -1e30f;

  using Row = std::array<float, 4>;  // one plane's offset in the four lanes
  std::array<Row, kPlanes> offsets = filled(kEmptyOffset);
  Row mag{};  ///< per lane, the largest |offset|: the slack's scale

  /// One of A's axes: B's three bounding planes for +n (upper) and -n (lower), their coefficients, and the
  /// translation's share n . t' (t' = R o_b + t - o_a).
  struct Axis {
    std::array<float, 3> coefficient;
    std::array<std::uint8_t, 3> upper, lower;
    float shift;
  };
  struct PairContext {
    std::array<Axis, kAxes> axes;
    float coefficient_sum;        ///< >= the largest sum of |coefficients| over the axes
    float translation_magnitude;  ///< >= the largest |shift|, plus the double rounding of t'
  };

  /// Rounding bound of the float test: B's support on an axis, sum c_k d_k + s, rounds within about 4u of
  /// sum |c_k d_k| + |s| (u = 2^-24), the coefficients' and the shift's own rounding to float add u each,
  /// and adding A's offset u of the operands: less than 6u (C mag_b + |s|) + u mag_a, C the coefficient
  /// sum. The slack 16 FLT_EPSILON (C mag_b + |s| + 2 mag_a) = 32u (...) is five times that.
  static constexpr float kSlackFactor = 16 * std::numeric_limits<float>::epsilon();

  /// The pose's context for lanes stored relative to origin_a (A's) and origin_b (B's): KDop's
  /// re-alignment for the pose with translation t' = R o_b + t - o_a (in double), rounded to float.
  static PairContext make_context(const RigidTransform& pose, const Vec3& origin_a = Vec3::Zero(),
                                  const Vec3& origin_b = Vec3::Zero()) {
    const ShiftedPose shifted = ShiftedPose::of(pose, origin_a, origin_b);
    const typename Volume::PairContext exact = Volume::make_context(shifted.pose);
    PairContext c{};
    double coefficient_sum = 0, largest_shift = 0;
    for (std::size_t a = 0; a < kAxes; ++a) {
      Axis& axis = c.axes[a];
      double sum = 0;
      for (int k = 0; k < 3; ++k) {
        axis.coefficient[k] = static_cast<float>(exact.coefficient(a, k));
        axis.upper[k] = exact.plane(a, k);
        axis.lower[k] = exact.plane(a + kAxes, k);
        sum += std::abs(exact.coefficient(a, k));
      }
      axis.shift = static_cast<float>(exact.shift(a));
      coefficient_sum = std::max(coefficient_sum, sum);
      largest_shift = std::max(largest_shift, std::abs(exact.shift(a)));
    }
    c.coefficient_sum = widened(static_cast<float>(coefficient_sum));
    c.translation_magnitude = shifted.magnitude(largest_shift);
    return c;
  }

  /// Lane `lane` holds `dop` (not empty) less `origin`: offset m becomes d_m - n_m . origin, rounded up with
  /// a margin for the double arithmetic, so that the lane's DOP contains the stored one.
  void set(int lane, const Volume& dop, const Vec3& origin = Vec3::Zero()) {
    const auto& normals = Volume::tables().normals;
    double largest = 0;
    for (std::size_t m = 0; m < kPlanes; ++m) {
      const double along = normals[m].dot(origin);
      const double d = double(dop.offsets[m]) - along;
      const double rounding = origin_shift_rounding(std::abs(double(dop.offsets[m])), origin);
      offsets[m][lane] = float_up(d + rounding);
      largest = std::max(largest, std::abs(double(offsets[m][lane])));
    }
    mag[lane] = float_up(largest);
  }
  /// Four lanes holding lane `lane` of `from`.
  static KDop4 broadcast(const KDop4& from, int lane) {
    KDop4 out;
    for (std::size_t m = 0; m < kPlanes; ++m) out.offsets[m].fill(from.offsets[m][lane]);
    out.mag.fill(from.mag[lane]);
    return out;
  }
  /// The volume of a lane's bounding box (the descent splits the larger of two nodes).
  [[nodiscard]] float volume(int lane) const {
    float v = 1;
    for (std::size_t a = 0; a < 3; ++a) v *= offsets[a][lane] + offsets[a + kAxes][lane];
    return v;
  }
  [[nodiscard]] bool empty(int lane) const { return offsets[0][lane] + offsets[kAxes][lane] < 0; }

  /// B's four DOPs placed against A's axes: per axis, B's upper support on +n and on -n (lanes side by side).
  struct alignas(16) Placed {
    std::array<Row, kAxes> upper, neg_lower;
    Row mag;
  };
  /// A wide walk keeps the placed block of B's children rather than place a volume again: a lane's
  /// supports cost six products per axis.
  static constexpr bool kKeepsPlaced = true;
  /// Four lanes holding lane `lane` of a placed block.
  static Placed broadcast_placed(const Placed& from, int lane) {
    Placed out;
    for (std::size_t m = 0; m < kAxes; ++m) {
      out.upper[m].fill(from.upper[m][lane]);
      out.neg_lower[m].fill(from.neg_lower[m][lane]);
    }
    out.mag.fill(from.mag[lane]);
    return out;
  }
  /// Per lane, four times the squared distance between the centres of the bounding boxes of `a`'s lane
  /// and `b`'s (placed on A's axes; the first three are the coordinate axes, as in volume()): the wide walk
  /// takes the nearest of the overlapping pairs first (traversal/wide_exact.hpp).
  static Row center_distances(const KDop4& a, const Placed& b) {
    Row out{};
    for (int k = 0; k < kLanes; ++k)
      for (std::size_t m = 0; m < 3; ++m) {
        const float d = (a.offsets[m][k] - a.offsets[m + kAxes][k]) - (b.upper[m][k] - b.neg_lower[m][k]);
        out[k] += d * d;
      }
    return out;
  }

  /// Bit k set: lane k of `a` (A's frame) and lane k of `b` (B's, placed by the pose) may overlap. Lanes of
  /// an empty DOP never do. place() then overlap_placed(), in the vector unit where there is SSE2: the float
  /// operations of overlap_scalar in the same order, so both answer alike (tests/volumes/test_lanes.cpp).
  static unsigned overlap(const KDop4& a, const KDop4& b, const PairContext& c) {
    return overlap_placed(a, place(b, c), c);
  }

  /// The reference: lane by lane in scalar float.
  static unsigned overlap_scalar(const KDop4& a, const KDop4& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float slack =
          kSlackFactor * ((c.coefficient_sum * b.mag[k] + c.translation_magnitude) + 2 * a.mag[k]);
      bool apart = false;
      for (std::size_t m = 0; m < kAxes; ++m) {
        const Axis& x = c.axes[m];
        const float upper = lane_support(b, x, x.upper, k) + x.shift;
        const float neg_lower = lane_support(b, x, x.lower, k) - x.shift;
        const float o = std::min(upper + a.offsets[m + kAxes][k], neg_lower + a.offsets[m][k]);
        apart = apart || o < -slack;
      }
      if (!apart) mask |= 1u << k;
    }
    return mask;
  }

#if BVHLAB_KDOP4_SSE2
  [[gnu::always_inline]] static Placed place(const KDop4& b, const PairContext& c) {
    Placed out;
    for (std::size_t m = 0; m < kAxes; ++m) {
      const Axis& x = c.axes[m];
      const __m128 c0 = _mm_set1_ps(x.coefficient[0]), c1 = _mm_set1_ps(x.coefficient[1]),
                   c2 = _mm_set1_ps(x.coefficient[2]), shift = _mm_set1_ps(x.shift);
      const auto support = [&](const std::array<std::uint8_t, 3>& planes) {
        return _mm_add_ps(_mm_add_ps(_mm_mul_ps(c0, _mm_load_ps(b.offsets[planes[0]].data())),
                                     _mm_mul_ps(c1, _mm_load_ps(b.offsets[planes[1]].data()))),
                          _mm_mul_ps(c2, _mm_load_ps(b.offsets[planes[2]].data())));
      };
      _mm_store_ps(out.upper[m].data(), _mm_add_ps(support(x.upper), shift));
      _mm_store_ps(out.neg_lower[m].data(), _mm_sub_ps(support(x.lower), shift));
    }
    out.mag = b.mag;
    return out;
  }
  [[gnu::always_inline]] static unsigned overlap_placed(const KDop4& a, const Placed& b,
                                                        const PairContext& c) {
    const __m128 neg_slack = _mm_sub_ps(
        _mm_setzero_ps(),
        _mm_mul_ps(
            _mm_set1_ps(kSlackFactor),
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(c.coefficient_sum), _mm_load_ps(b.mag.data())),
                                  _mm_set1_ps(c.translation_magnitude)),
                       _mm_mul_ps(_mm_set1_ps(2), _mm_load_ps(a.mag.data())))));
    __m128 apart = _mm_setzero_ps();
    for (std::size_t m = 0; m < kAxes; ++m) {
      const __m128 o =
          _mm_min_ps(_mm_add_ps(_mm_load_ps(b.upper[m].data()), _mm_load_ps(a.offsets[m + kAxes].data())),
                     _mm_add_ps(_mm_load_ps(b.neg_lower[m].data()), _mm_load_ps(a.offsets[m].data())));
      apart = _mm_or_ps(apart, _mm_cmplt_ps(o, neg_slack));
    }
    return static_cast<unsigned>(_mm_movemask_ps(apart)) ^ 0xFu;
  }
#else
  static Placed place(const KDop4& b, const PairContext& c) {
    Placed out;
    for (std::size_t m = 0; m < kAxes; ++m) {
      const Axis& x = c.axes[m];
      for (int k = 0; k < kLanes; ++k) {
        out.upper[m][k] = lane_support(b, x, x.upper, k) + x.shift;
        out.neg_lower[m][k] = lane_support(b, x, x.lower, k) - x.shift;
      }
    }
    out.mag = b.mag;
    return out;
  }
  static unsigned overlap_placed(const KDop4& a, const Placed& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float slack =
          kSlackFactor * ((c.coefficient_sum * b.mag[k] + c.translation_magnitude) + 2 * a.mag[k]);
      bool apart = false;
      for (std::size_t m = 0; m < kAxes; ++m)
        apart = apart || std::min(b.upper[m][k] + a.offsets[m + kAxes][k],
                                  b.neg_lower[m][k] + a.offsets[m][k]) < -slack;
      if (!apart) mask |= 1u << k;
    }
    return mask;
  }
#endif

 private:
  /// Lane k of B's support bound on axis x from three of its planes, in the vector path's order.
  static float lane_support(const KDop4& b, const Axis& x, const std::array<std::uint8_t, 3>& planes, int k) {
    return (x.coefficient[0] * b.offsets[planes[0]][k] + x.coefficient[1] * b.offsets[planes[1]][k]) +
           x.coefficient[2] * b.offsets[planes[2]][k];
  }
  static constexpr std::array<Row, kPlanes> filled(float value) {
    std::array<Row, kPlanes> out{};
    for (auto& row : out) row = {value, value, value, value};
    return out;
  }
};

}  // namespace bvhlab
