// Random vectors and rotations drawn in one fixed order on every compiler.
// The arguments of a call are evaluated in an unspecified order (g++ right to left, clang left to right), so
// Vec3(u(rng), u(rng), u(rng)) gives each compiler other points, and a test's poses would depend on it. These
// draw the last coordinate first, the order g++ has always used, so the tests keep the poses they were
// written with.
#pragma once

#include "volumes/geometry.hpp"

#include <Eigen/Geometry>

namespace bvhlab::testing {

template <class Distribution, class Rng>
Vec3 draw_vec3(Distribution& distribution, Rng& rng) {
  const double z = distribution(rng);
  const double y = distribution(rng);
  const double x = distribution(rng);
  return {x, y, z};
}

/// An unnormalised quaternion (w, x, y, z) with each part drawn from `distribution`.
template <class Distribution, class Rng>
Eigen::Quaterniond draw_quaternion(Distribution& distribution, Rng& rng) {
  const double z = distribution(rng);
  const double y = distribution(rng);
  const double x = distribution(rng);
  const double w = distribution(rng);
  return {w, x, y, z};
}

}  // namespace bvhlab::testing
