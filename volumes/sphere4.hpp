// Four bounding spheres side by side (structure of arrays: centres, radii and a magnitude per lane, in
// float), tested against four others in one pass of the vector unit: the children of a wide node
// (bvh/wide_bvh.hpp) against one sphere of the other tree, broadcast. The centres are stored relative to an
// origin; the slack covers the float rounding (below), so the test stays conservative.
#pragma once

#include "float_pose.hpp"
#include "sphere.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#if defined(__SSE2__) && !defined(BVHLAB_SPHERE4_SCALAR)
#define BVHLAB_SPHERE4_SSE2 1
#include <emmintrin.h>
#else
#define BVHLAB_SPHERE4_SSE2 0
#endif

namespace bvhlab {

struct alignas(16) Sphere4 {
  using Volume = Sphere;
  static constexpr int kLanes = 4;
  /// An unused lane: a radius so negative that no distance comes within it.
  static constexpr float kEmptyRadius = -1e30f;

  std::array<float, 4> cx{}, cy{}, cz{};
  std::array<float, 4> radius{kEmptyRadius, kEmptyRadius, kEmptyRadius, kEmptyRadius};
  std::array<float, 4> mag{};  ///< per lane, max |centre| + radius: the slack's scale

  using PairContext = FloatPose;

  /// Rounding bound: the centre offset R c_b + t' - c_a rounds per coordinate as the AABB's centre does
  /// (Aabb4: under 14u max|c_b| + 8u |t| + 3u max|c_a|, u = 2^-24), its length at most sqrt(3) times that,
  /// and squaring both sides of |offset| <= r_a + r_b + slack costs a few u of each. The slack
  /// 16 FLT_EPSILON (|t| + 2 mag_a + 2 mag_b) = 32u (...) covers all of it with room to spare.
  static constexpr float kSlackFactor = 16 * std::numeric_limits<float>::epsilon();

  /// The pose for lanes stored relative to origin_a (A's) and origin_b (B's): float_pose.hpp.
  static PairContext make_context(const RigidTransform& pose, const Vec3& origin_a = Vec3::Zero(),
                                  const Vec3& origin_b = Vec3::Zero()) {
    return FloatPose::of(pose, origin_a, origin_b);
  }

  /// Lane `lane` holds `sphere` (not empty) less `origin`: the centre rounded to nearest, the radius grown by
  /// the centre's move and rounded up, so that the lane's sphere contains the stored one.
  void set(int lane, const Sphere& sphere, const Vec3& origin = Vec3::Zero()) {
    const Vec3 exact = to_vec(sphere.center) - origin;
    std::array<float, 3> c{};
    double moved = 0;
    for (int k = 0; k < 3; ++k) {
      c[k] = rounded_to_float(exact[k]);
      moved += (exact[k] - c[k]) * (exact[k] - c[k]);
    }
    const double rounding = origin_shift_rounding(to_vec(sphere.center).cwiseAbs().sum(), origin);
    cx[lane] = c[0], cy[lane] = c[1], cz[lane] = c[2];
    radius[lane] = float_up(double(sphere.radius) + std::sqrt(moved) + rounding);
    mag[lane] = float_up(std::max({std::abs(double(c[0])), std::abs(double(c[1])), std::abs(double(c[2]))}) +
                         double(radius[lane]));
  }
  static Sphere4 broadcast(const Sphere4& from, int lane) {
    Sphere4 out;
    out.cx.fill(from.cx[lane]), out.cy.fill(from.cy[lane]), out.cz.fill(from.cz[lane]);
    out.radius.fill(from.radius[lane]), out.mag.fill(from.mag[lane]);
    return out;
  }
  /// The volume of a lane's bounding cube (the descent splits the larger of two nodes).
  [[nodiscard]] float volume(int lane) const { return radius[lane] * radius[lane] * radius[lane]; }
  [[nodiscard]] bool empty(int lane) const { return radius[lane] < 0; }

  /// B's spheres placed in A's frame are Sphere4s too; placing again is cheaper than keeping them.
  using Placed = Sphere4;
  static constexpr bool kKeepsPlaced = false;
  /// A wide walk meets many leaf pairs whose triangles' planes part them: it tests their planes four pairs at
  /// once (traversal/wide_exact.hpp; layouts without this member test pair by pair).
  static constexpr bool kBatchesLeafPairs = true;
  static Placed broadcast_placed(const Placed& from, int lane) { return broadcast(from, lane); }
  /// Per lane, the squared distance between the centres of `a`'s lane and `b`'s (placed in A's frame): the
  /// wide walk takes the nearest of the overlapping pairs first (traversal/wide_exact.hpp).
  static std::array<float, 4> center_distances(const Sphere4& a, const Placed& b) {
    return squared_center_distances(a, b);
  }

  /// Bit k set: lane k of `a` and lane k of `b` (placed by the pose) may overlap; empty lanes never do.
  static unsigned overlap(const Sphere4& a, const Sphere4& b, const PairContext& c) {
    return overlap_placed(a, place(b, c), c);
  }

  /// The reference: lane by lane in scalar float, the operations of place and overlap_placed in order.
  static unsigned overlap_scalar(const Sphere4& a, const Sphere4& b, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float bc[3] = {b.cx[k], b.cy[k], b.cz[k]}, ac[3] = {a.cx[k], a.cy[k], a.cz[k]};
      float squared = 0;
      for (int r = 0; r < 3; ++r) {
        const float* R = &c.rotation[3 * r];
        const float center = ((R[0] * bc[0] + R[1] * bc[1]) + R[2] * bc[2]) + c.translation[r];
        const float offset = center - ac[r];
        squared = squared + offset * offset;
      }
      const float slack = kSlackFactor * (c.translation_magnitude + 2 * (a.mag[k] + b.mag[k]));
      const float reach = (a.radius[k] + b.radius[k]) + slack;
      if (reach >= 0 && squared <= reach * reach) mask |= 1u << k;
    }
    return mask;
  }

#if BVHLAB_SPHERE4_SSE2
  [[gnu::always_inline]] static Sphere4 place(const Sphere4& b, const PairContext& c) {
    const __m128 bcx = _mm_load_ps(b.cx.data()), bcy = _mm_load_ps(b.cy.data()),
                 bcz = _mm_load_ps(b.cz.data());
    Sphere4 out;
    float* centers[3] = {out.cx.data(), out.cy.data(), out.cz.data()};
    for (int r = 0; r < 3; ++r) {
      const float* R = &c.rotation[3 * r];
      _mm_store_ps(centers[r], _mm_add_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(R[0]), bcx),
                                                                _mm_mul_ps(_mm_set1_ps(R[1]), bcy)),
                                                     _mm_mul_ps(_mm_set1_ps(R[2]), bcz)),
                                          _mm_set1_ps(c.translation[r])));
    }
    out.radius = b.radius;
    out.mag = b.mag;
    return out;
  }
  [[gnu::always_inline]] static unsigned overlap_placed(const Sphere4& a, const Sphere4& placed,
                                                        const PairContext& c) {
    const __m128 ox = _mm_sub_ps(_mm_load_ps(placed.cx.data()), _mm_load_ps(a.cx.data()));
    const __m128 oy = _mm_sub_ps(_mm_load_ps(placed.cy.data()), _mm_load_ps(a.cy.data()));
    const __m128 oz = _mm_sub_ps(_mm_load_ps(placed.cz.data()), _mm_load_ps(a.cz.data()));
    const __m128 squared = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ox, ox), _mm_mul_ps(oy, oy)), _mm_mul_ps(oz, oz));
    const __m128 slack = _mm_mul_ps(
        _mm_set1_ps(kSlackFactor),
        _mm_add_ps(_mm_set1_ps(c.translation_magnitude),
                   _mm_mul_ps(_mm_set1_ps(2),
                              _mm_add_ps(_mm_load_ps(a.mag.data()), _mm_load_ps(placed.mag.data())))));
    const __m128 reach =
        _mm_add_ps(_mm_add_ps(_mm_load_ps(a.radius.data()), _mm_load_ps(placed.radius.data())), slack);
    const __m128 near =
        _mm_and_ps(_mm_cmpge_ps(reach, _mm_setzero_ps()), _mm_cmple_ps(squared, _mm_mul_ps(reach, reach)));
    return static_cast<unsigned>(_mm_movemask_ps(near));
  }
#else
  static Sphere4 place(const Sphere4& b, const PairContext& c) {
    Sphere4 out = b;
    for (int k = 0; k < kLanes; ++k) {
      const float bc[3] = {b.cx[k], b.cy[k], b.cz[k]};
      float* centers[3] = {&out.cx[k], &out.cy[k], &out.cz[k]};
      for (int r = 0; r < 3; ++r) {
        const float* R = &c.rotation[3 * r];
        *centers[r] = ((R[0] * bc[0] + R[1] * bc[1]) + R[2] * bc[2]) + c.translation[r];
      }
    }
    return out;
  }
  static unsigned overlap_placed(const Sphere4& a, const Sphere4& placed, const PairContext& c) {
    unsigned mask = 0;
    for (int k = 0; k < kLanes; ++k) {
      const float ox = placed.cx[k] - a.cx[k], oy = placed.cy[k] - a.cy[k], oz = placed.cz[k] - a.cz[k];
      const float squared = (ox * ox + oy * oy) + oz * oz;
      const float slack = kSlackFactor * (c.translation_magnitude + 2 * (a.mag[k] + placed.mag[k]));
      const float reach = (a.radius[k] + placed.radius[k]) + slack;
      if (reach >= 0 && squared <= reach * reach) mask |= 1u << k;
    }
    return mask;
  }
#endif
};

}  // namespace bvhlab
