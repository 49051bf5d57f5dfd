// The pose as the four-lane tests (Aabb4, Sphere4, Obb4, KDop4) take it: lanes are stored relative to an
// origin per tree, so the pose's translation becomes t' = R o_b + t - o_a, computed in double (two near
// objects keep small numbers wherever they lie), then rounded to float with the rotation.
#pragma once

#include "geometry.hpp"

#include <array>
#include <limits>

namespace bvhlab {

/// A float above x's real value when x was rounded once (within u = 2^-24 of it): x (1 + 2^-20), rounded,
/// is at least x (1 + 2^-21). Arithmetic instead of nextafter: contexts are made per query. Where a value
/// underflowed to 0 (below 1e-38), what it leaves out is far inside the tests' slacks; adding FLT_MIN
/// instead made products subnormal, and the box walk 11% slower.
inline float widened(float x) {
  return x * (1 + 1.0f / (1 << 20));
}

/// The margin a lane's value (of size `scale`, a centre's |c|_1 or a plane offset) needs for being taken
/// less `origin` in double before its rounding to float: the subtraction or dot product rounds a few times
/// within DBL_EPSILON of (scale + |origin|_1); 8 of them cover it. Every layout's set() grows by it.
inline double origin_shift_rounding(double scale, const Vec3& origin) {
  return 8 * std::numeric_limits<double>::epsilon() * (scale + origin.cwiseAbs().sum());
}

/// The pose with its translation moved by the two origins (in double), and the scale of the terms that
/// went into it, for the slack: t' rounds in double within a few DBL_EPSILON of that scale, far below
/// 1e-8 of it, which times the tests' slack factors (16 FLT_EPSILON and more) covers that rounding.
struct ShiftedPose {
  RigidTransform pose;
  double terms;

  static ShiftedPose of(const RigidTransform& pose, const Vec3& origin_a, const Vec3& origin_b) {
    const Vec3 moved_origin = pose.rotation * origin_b;
    ShiftedPose out{pose, moved_origin.cwiseAbs().maxCoeff() + pose.translation.cwiseAbs().maxCoeff() +
                              origin_a.cwiseAbs().maxCoeff()};
    out.pose.translation = moved_origin + pose.translation - origin_a;
    return out;
  }
  /// A float bound on a translation term as large as `largest`, its double rounding included.
  [[nodiscard]] float magnitude(double largest) const {
    return widened(static_cast<float>(largest + 1e-8 * terms));
  }
};

/// R (row-major) and t' rounded to nearest float, and a bound on |t'|: what Aabb4, Sphere4 and Obb4 place
/// B's lanes with.
struct FloatPose {
  std::array<float, 9> rotation;
  std::array<float, 3> translation;
  float translation_magnitude;  ///< >= max |t'_i|, the double rounding of t' included

  static FloatPose of(const RigidTransform& pose, const Vec3& origin_a, const Vec3& origin_b) {
    const ShiftedPose shifted = ShiftedPose::of(pose, origin_a, origin_b);
    FloatPose out{};
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) out.rotation[3 * r + k] = static_cast<float>(pose.rotation(r, k));
      out.translation[r] = static_cast<float>(shifted.pose.translation[r]);
    }
    out.translation_magnitude = shifted.magnitude(shifted.pose.translation.cwiseAbs().maxCoeff());
    return out;
  }
};

/// Per lane, the squared distance between the centres of four lanes stored as coordinate rows `cx`, `cy`,
/// `cz` (Aabb4, Sphere4): their center_distances.
template <class Lanes>
std::array<float, 4> squared_center_distances(const Lanes& a, const Lanes& b) {
  std::array<float, 4> out{};
  for (int k = 0; k < 4; ++k) {
    const float dx = a.cx[k] - b.cx[k], dy = a.cy[k] - b.cy[k], dz = a.cz[k] - b.cz[k];
    out[k] = dx * dx + dy * dy + dz * dz;
  }
  return out;
}

}  // namespace bvhlab
