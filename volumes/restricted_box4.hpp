// The wide layout of a restricted boxtree: four children's boxes stored relative to the box around them, as
// the restricted boxtree stores a child relative to its parent, here as 8-bit steps on each axis (56 bytes
// for four boxes, against the 112 of Aabb4). A test unpacks a node into Aabb4 lanes (centre, half-extent)
// and runs Aabb4's test: the unpacking adds a pad to every half-extent that covers its own float rounding,
// so an unpacked lane contains the stored box, which contains the decoded restricted box it was packed from.
#pragma once

#include "aabb4.hpp"
#include "restricted_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>

namespace bvhlab {

struct alignas(16) RestrictedBox4 {
  using Volume = RestrictedBox;
  using PairContext = Aabb4::PairContext;
  /// Placed, broadcast and tested as Aabb4 lanes.
  using Placed = Aabb4;
  static constexpr int kLanes = 4;
  static constexpr int kSteps = 255;
  static constexpr bool kKeepsPlaced = false;
  static constexpr bool kBatchesLeafPairs = true;

  /// Per axis the lower corner and the step of the grid the four boxes are stored on (relative to the
  /// tree's origin); the fourth entries hold the pad (base) and a bound on every lane's Aabb4 `mag` (step).
  std::array<float, 4> base{};
  std::array<float, 4> step{};
  /// Per axis and lane the box's interval in steps: [base + lo step, base + hi step]. lo > hi: an empty
  /// lane (the steps are compared, not the ends: far from the origin a tiny step may round away).
  std::array<std::array<std::uint8_t, 4>, 3> lo{};
  std::array<std::array<std::uint8_t, 4>, 3> hi{};

  RestrictedBox4() {
    for (auto& axis : lo) axis.fill(kSteps);  // four empty lanes: lo > hi
  }

  static PairContext make_context(const RigidTransform& pose, const Vec3& origin_a = Vec3::Zero(),
                                  const Vec3& origin_b = Vec3::Zero()) {
    return Aabb4::make_context(pose, origin_a, origin_b);
  }

  /// Up to four boxes (a node's children, decoded) less `origin`, on a grid over the box around them: each
  /// interval rounded outwards to whole steps. Throws std::invalid_argument for none, more than four, an
  /// empty or a non-finite box.
  static RestrictedBox4 pack(std::span<const Box> boxes, const Vec3& origin = Vec3::Zero());

  /// The lanes as Aabb4 lanes (centre, half-extent plus the pad; empty lanes stay empty): in the vector
  /// unit where there is SSE2, the float operations of unpack_scalar in the same order.
  [[gnu::always_inline]] static Aabb4 unpack(const RestrictedBox4& n);
  /// The reference: lane by lane in scalar float.
  static Aabb4 unpack_scalar(const RestrictedBox4& n) {
    Aabb4 out;
    std::array<float, 4>* centers[3] = {&out.cx, &out.cy, &out.cz};
    std::array<float, 4>* halves[3] = {&out.hx, &out.hy, &out.hz};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < kLanes; ++k) {
        const float low = n.base[r] + float(n.lo[r][k]) * n.step[r];
        const float high = n.base[r] + float(n.hi[r][k]) * n.step[r];
        (*centers[r])[k] = (low + high) * 0.5f;
        (*halves[r])[k] = n.lo[r][k] > n.hi[r][k] ? Aabb4::kEmptyHalf : (high - low) * 0.5f + n.base[3];
      }
    out.mag.fill(n.step[3]);
    return out;
  }

  static Aabb4 place(const RestrictedBox4& b, const PairContext& c) { return Aabb4::place(unpack(b), c); }
  static Aabb4 place(const Aabb4& b, const PairContext& c) { return Aabb4::place(b, c); }
  /// Four lanes holding lane `lane`, unpacked.
  static Aabb4 broadcast(const RestrictedBox4& from, int lane) {
    return Aabb4::broadcast(unpack(from), lane);
  }
  static Aabb4 broadcast_placed(const Aabb4& from, int lane) { return Aabb4::broadcast(from, lane); }
  [[gnu::always_inline]] static unsigned overlap_placed(const RestrictedBox4& a, const Aabb4& placed,
                                                        const PairContext& c) {
    return Aabb4::overlap_placed(unpack(a), placed, c);
  }
  [[gnu::always_inline]] static unsigned overlap_placed(const Aabb4& a, const Aabb4& placed,
                                                        const PairContext& c) {
    return Aabb4::overlap_placed(a, placed, c);
  }
  static unsigned overlap(const RestrictedBox4& a, const RestrictedBox4& b, const PairContext& c) {
    return overlap_placed(a, place(b, c), c);
  }
  static std::array<float, 4> center_distances(const RestrictedBox4& a, const Aabb4& b) {
    return Aabb4::center_distances(unpack(a), b);
  }
  static std::array<float, 4> center_distances(const Aabb4& a, const Aabb4& b) {
    return Aabb4::center_distances(a, b);
  }

  /// The product of a lane's half-extents, as Aabb4::volume (the descent splits the larger of two nodes).
  [[nodiscard]] float volume(int lane) const {
    float v = 1;
    for (int r = 0; r < 3; ++r) v *= (float(hi[r][lane]) - float(lo[r][lane])) * 0.5f * step[r];
    return v;
  }
  [[nodiscard]] bool empty(int lane) const { return lo[0][lane] > hi[0][lane]; }
};

inline RestrictedBox4 RestrictedBox4::pack(std::span<const Box> boxes, const Vec3& origin) {
  if (boxes.empty() || boxes.size() > kLanes)
    throw std::invalid_argument("RestrictedBox4::pack: one to four boxes, not " +
                                std::to_string(boxes.size()));
  Box around;
  for (const Box& b : boxes) {
    if (b.empty() || !b.min.allFinite() || !b.max.allFinite())
      throw std::invalid_argument("RestrictedBox4::pack: an empty or non-finite box");
    around.extend(b);
  }
  RestrictedBox4 out;
  double reach = 0;  // the largest |base| + kSteps step: what the unpacking rounds relative to
  for (int r = 0; r < 3; ++r) {
    // Taking `origin` off in double rounds within a few DBL_EPSILON: each end moves out by that much first.
    const double shift = origin_shift_rounding(std::abs(around.min[r]) + std::abs(around.max[r]), origin);
    const double low = around.min[r] - origin[r] - shift, high = around.max[r] - origin[r] + shift;
    out.base[r] = float_down(low);
    float step = std::max(float_up((high - double(out.base[r])) / kSteps), std::numeric_limits<float>::min());
    while (double(out.base[r]) + kSteps * double(step) < high)
      step = std::nextafter(step, std::numeric_limits<float>::infinity());
    out.step[r] = step;
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      const double box_low = boxes[k].min[r] - origin[r] - shift,
                   box_high = boxes[k].max[r] - origin[r] + shift;
      double q_low = std::clamp(std::floor((box_low - out.base[r]) / step), 0.0, double(kSteps));
      while (q_low > 0 && out.base[r] + q_low * step > box_low) --q_low;
      double q_high = std::clamp(std::ceil((box_high - out.base[r]) / step), 0.0, double(kSteps));
      while (q_high < kSteps && out.base[r] + q_high * step < box_high) ++q_high;
      out.lo[r][k] = static_cast<std::uint8_t>(q_low);
      out.hi[r][k] = static_cast<std::uint8_t>(q_high);
    }
    reach = std::max(reach, std::abs(double(out.base[r])) + kSteps * double(step));
  }
  // The unpacking rounds each end within 2u reach (u = FLT_EPSILON / 2), the centre and half-extent within
  // 3u reach, the pad's sum within u (reach + pad): 8u reach covers them; 16u is taken.
  out.base[3] = float_up(8 * double(std::numeric_limits<float>::epsilon()) * reach);
  // Every lane's centre and half-extent are at most reach (plus the pad): Aabb4's slack reads this bound.
  out.step[3] = float_up(2 * reach + double(out.base[3]));
  return out;
}

#if BVHLAB_AABB4_SSE2
inline Aabb4 RestrictedBox4::unpack(const RestrictedBox4& n) {
  const __m128i zero = _mm_setzero_si128();
  const auto steps = [&zero](const std::array<std::uint8_t, 4>& q) {  // four bytes, widened to int32
    std::int32_t bytes;
    std::memcpy(&bytes, q.data(), sizeof bytes);
    return _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(bytes), zero), zero);
  };
  Aabb4 out;
  float* centers[3] = {out.cx.data(), out.cy.data(), out.cz.data()};
  float* halves[3] = {out.hx.data(), out.hy.data(), out.hz.data()};
  const __m128 pad = _mm_set1_ps(n.base[3]), empty = _mm_set1_ps(Aabb4::kEmptyHalf), half = _mm_set1_ps(0.5f);
  for (int r = 0; r < 3; ++r) {
    const __m128 base = _mm_set1_ps(n.base[r]), step = _mm_set1_ps(n.step[r]);
    const __m128i q_low = steps(n.lo[r]), q_high = steps(n.hi[r]);
    const __m128 low = _mm_add_ps(base, _mm_mul_ps(_mm_cvtepi32_ps(q_low), step));
    const __m128 high = _mm_add_ps(base, _mm_mul_ps(_mm_cvtepi32_ps(q_high), step));
    _mm_store_ps(centers[r], _mm_mul_ps(_mm_add_ps(low, high), half));
    const __m128 extent = _mm_add_ps(_mm_mul_ps(_mm_sub_ps(high, low), half), pad);
    const __m128 is_empty = _mm_castsi128_ps(_mm_cmpgt_epi32(q_low, q_high));
    _mm_store_ps(halves[r], _mm_or_ps(_mm_and_ps(is_empty, empty), _mm_andnot_ps(is_empty, extent)));
  }
  out.mag.fill(n.step[3]);
  return out;
}
#else
inline Aabb4 RestrictedBox4::unpack(const RestrictedBox4& n) {
  return unpack_scalar(n);
}
#endif

}  // namespace bvhlab
