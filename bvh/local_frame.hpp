// Internal to bvh/: the exact-scaling local frame and the accurate cross product that the triangle distance
// and the triangle contact share, so that pairs far from the origin, tiny or huge, keep their precision.
#pragma once

#include "../volumes/geometry.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

namespace bvhlab::local_frame {

/// a * b - c * d within about one rounding (Kahan's scheme with fma). The plain difference cancels for nearly
/// parallel vectors, and a sliver's normal would tilt by eps / angle: its plane distances would be wrong.
inline double difference_of_products(double a, double b, double c, double d) {
  const double cd = c * d;
  const double cd_error = std::fma(-c, d, cd);  // cd - c * d, exactly
  return std::fma(a, b, -cd) + cd_error;
}

inline Vec3 accurate_cross(const Vec3& u, const Vec3& v) {
  return {difference_of_products(u.y(), v.z(), u.z(), v.y()),
          difference_of_products(u.z(), v.x(), u.x(), v.z()),
          difference_of_products(u.x(), v.y(), u.y(), v.x())};
}

/// 2^exponent for |exponent| <= 1000, built from its bits: std::ldexp is a library call, and the triangle
/// distance makes a dozen of them per pair.
inline double power_of_two(int exponent) {
  return std::bit_cast<double>(static_cast<std::uint64_t>(exponent + 1023) << 52);
}

/// v 2^exponent, exact (barring underflow); ldexp per coordinate only where 2^exponent is out of range.
inline Vec3 times_power_of_two(const Vec3& v, int exponent) {
  if (exponent == 0) return v;
  if (std::abs(exponent) <= 1000) return v * power_of_two(exponent);
  return {std::ldexp(v.x(), exponent), std::ldexp(v.y(), exponent), std::ldexp(v.z(), exponent)};
}

/// The smallest e with magnitude < 2^e (0 for 0). From the bits for normal numbers (std::ilogb is a library
/// call), from ilogb for subnormal ones.
inline int exponent_above(double magnitude) {
  if (!(magnitude > 0)) return 0;
  if (magnitude < std::numeric_limits<double>::min()) return std::ilogb(magnitude) + 1;
  return static_cast<int>((std::bit_cast<std::uint64_t>(magnitude) >> 52) & 0x7ff) - 1023 + 1;
}

/// Throws std::invalid_argument naming `function`, the triangle and the vertex with a NaN or infinite
/// coordinate.
inline void require_finite(const TrianglePoints& t, const char* function, const char* name) {
  for (int i = 0; i < 3; ++i)
    if (!t[i].allFinite())
      throw std::invalid_argument(std::string(function) + ": triangle " + name + " vertex " +
                                  std::to_string(i) + " has a NaN or infinite coordinate");
}

/// Local coordinates y = (x 2^-pre - origin) 2^-exponent, all of magnitude below 1. Translating to p[0] keeps
/// the digits of a small pair far from the origin; the power-of-two scales are exact and keep the squares
/// and cross products of tiny or huge pairs clear of underflow and overflow. `pre` is non-zero only near
/// overflow, where the translation itself could overflow.
struct Frame {
  int pre = 0;
  Vec3 origin = Vec3::Zero();
  int exponent = 0;

  /// Sets the frame for the pair and returns the pair in it.
  std::array<TrianglePoints, 2> enter(const TrianglePoints& p, const TrianglePoints& q) {
    std::array<TrianglePoints, 2> local = {p, q};
    double largest = 0;
    for (const TrianglePoints& t : local)
      for (const Vec3& v : t) largest = std::max(largest, v.cwiseAbs().maxCoeff());
    if (largest > 0x1p1000) pre = exponent_above(largest);
    origin = times_power_of_two(p[0], -pre);
    double extent = 0;
    for (TrianglePoints& t : local)
      for (Vec3& v : t) {
        v = times_power_of_two(v, -pre) - origin;
        extent = std::max(extent, v.cwiseAbs().maxCoeff());
      }
    exponent = exponent_above(extent);
    for (TrianglePoints& t : local)
      for (Vec3& v : t) v = times_power_of_two(v, -exponent);
    return local;
  }
  [[nodiscard]] Vec3 world(const Vec3& y) const {
    return times_power_of_two(times_power_of_two(y, exponent) + origin, pre);
  }
  [[nodiscard]] double world_length(double d) const {
    const int e = exponent + pre;
    return std::abs(e) <= 1000 ? d * power_of_two(e) : std::ldexp(d, e);
  }
};

}  // namespace bvhlab::local_frame
