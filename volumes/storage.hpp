// Plain-data storage for volumes. Eigen's fixed-size types are not trivially copyable, so node arrays hold
// std::array and the hot path views them through Eigen::Map at no cost. Volumes may store float with
// outward rounding: half the memory traffic, still conservative.
#pragma once

#include "geometry.hpp"

#include <array>
#include <cmath>

namespace bvhlab {

using Float3 = std::array<float, 3>;
using Double3 = std::array<double, 3>;

// GCC 12's SLP vectoriser can fold double(float(x)) back to x (reproduced with GCC 12.2 -O2), which
// would hide the rounding these functions correct. Reading the rounded value back through a volatile
// keeps it observable; everything else is left to the optimiser.
inline float rounded_to_float(double x) {
  volatile float rounded = static_cast<float>(x);
  return rounded;
}
/// Largest float <= x (x finite).
inline float float_down(double x) {
  const float f = rounded_to_float(x);
  return static_cast<double>(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
/// Smallest float >= x (x finite).
inline float float_up(double x) {
  const float f = rounded_to_float(x);
  return static_cast<double>(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}
inline Float3 float3_down(const Vec3& v) {
  return {float_down(v.x()), float_down(v.y()), float_down(v.z())};
}
inline Float3 float3_up(const Vec3& v) {
  return {float_up(v.x()), float_up(v.y()), float_up(v.z())};
}
inline Vec3 to_vec(const Float3& a) {
  return Eigen::Map<const Eigen::Vector3f>(a.data()).cast<Scalar>();
}
inline Vec3 to_vec(const Double3& a) {
  return Eigen::Map<const Vec3>(a.data());
}
inline Double3 to_double3(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

/// Mat3 as plain data (row-major), for PairContexts that must be trivially copyable.
struct PlainMat3 {
  std::array<double, 9> m{};
  static PlainMat3 from(const Mat3& r) {
    PlainMat3 out;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(out.m.data()) = r;
    return out;
  }
  [[nodiscard]] auto map() const {
    return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m.data());
  }
};

}  // namespace bvhlab
