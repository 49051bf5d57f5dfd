// Random point clouds and poses for the distance bound tests, tests/volumes/test_distance_bound.cpp and
// tests/volumes/test_rss.cpp, with the draws they are built from. Each test draws its pairs from its own
// fixed seeds, so changing what a helper draws changes the pairs of both.
//
// Templates on the generator, as random_draws.hpp: triangle_families.hpp has the same log_uniform for
// std::mt19937_64, and a test may include both (the non-template is chosen; it draws the same).
#pragma once

#include "random_draws.hpp"
#include "volumes/geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace bvhlab::testing {

/// Uniform in [lo, hi).
template <class Rng>
double uniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// 10^u with u uniform in [lo, hi].
template <class Rng>
double log_uniform(Rng& rng, double lo, double hi) {
  return std::pow(10.0, uniform(rng, lo, hi));
}

/// A uniformly random rotation (a normalised Gaussian quaternion).
template <class Rng>
Mat3 random_rotation(Rng& rng) {
  std::normal_distribution<double> normal;
  return draw_quaternion(normal, rng).normalized().toRotationMatrix();
}

/// A uniformly random unit vector.
template <class Rng>
Vec3 random_direction(Rng& rng) {
  std::normal_distribution<double> normal;
  for (;;) {
    const Vec3 v = draw_vec3(normal, rng);
    if (v.norm() > 1e-3) return v.normalized();
  }
}

/// 1 to 30 points of extent about `scale` around `center`: random shape (stretched, one in ten flat) and
/// orientation.
template <class Rng>
std::vector<Vec3> random_cloud(Rng& rng, const Vec3& center, double scale) {
  std::normal_distribution<double> normal;
  const int count = 1 + int(rng() % 30);
  // The two stretches are drawn in the order the compiler evaluates the arguments (g++ the last first, clang
  // the first first), as the tests were written: a fixed order would change one compiler's pairs.
  Vec3 spread(1, log_uniform(rng, -2, 0), log_uniform(rng, -2, 0));
  if (uniform(rng, 0, 1) < 0.1) spread[2] = 0;  // flat
  const Mat3 shape = random_rotation(rng);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i)
    points.push_back(center + scale * (shape * draw_vec3(normal, rng).cwiseProduct(spread)));
  return points;
}

inline Vec3 mean_of(const std::vector<Vec3>& points) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& p : points) sum += p;
  return sum / double(points.size());
}

inline double diameter_of(const std::vector<Vec3>& points) {
  double d = 0;
  for (const Vec3& p : points)
    for (const Vec3& q : points) d = std::max(d, (p - q).norm());
  return d;
}

/// A rotation: random, or (one time in five) one that keeps the coordinate axes, where the boxes' and DOPs'
/// bounds are tight and a missing slack would show.
template <class Rng>
Mat3 random_pose_rotation(Rng& rng) {
  if (uniform(rng, 0, 1) >= 0.2) return random_rotation(rng);
  Mat3 r = Mat3::Zero();
  const int shift = int(rng() % 3);
  for (int k = 0; k < 3; ++k) r((k + shift) % 3, k) = rng() % 2 ? 1 : -1;
  if (r.determinant() < 0) r.col(0) = -r.col(0);
  return r;
}

/// min over point pairs of |p - (R q + t)|, p of `a` and q of `b` (B's frame, placed by `pose`): the distance
/// a volumes' bound must not exceed (the points are contained in the fitted volumes). In long double, whose
/// rounding is far below the bounds' slack, so even a bound that left out its slack can show (on x86-64 a
/// 64-bit mantissa; elsewhere at least double's). The inputs are doubles, exact in long double. `magnitude`
/// receives the largest coordinate involved.
inline double point_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b,
                             const RigidTransform& pose, double* magnitude = nullptr) {
  using Long = long double;
  const Mat3& r = pose.rotation;
  const Vec3& t = pose.translation;
  std::vector<std::array<Long, 3>> placed;
  double largest = t.cwiseAbs().maxCoeff();
  for (const Vec3& q : b) {
    std::array<Long, 3> x;
    for (int i = 0; i < 3; ++i)
      x[i] = Long(r(i, 0)) * q[0] + Long(r(i, 1)) * q[1] + Long(r(i, 2)) * q[2] + Long(t[i]);
    placed.push_back(x);
    largest = std::max(largest, q.cwiseAbs().maxCoeff());
  }
  Long best = std::numeric_limits<Long>::infinity();
  for (const Vec3& p : a) {
    largest = std::max(largest, p.cwiseAbs().maxCoeff());
    for (const auto& x : placed) {
      const Long dx = p[0] - x[0], dy = p[1] - x[1], dz = p[2] - x[2];
      best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
  }
  if (magnitude) *magnitude = largest;
  return double(best);
}

}  // namespace bvhlab::testing
