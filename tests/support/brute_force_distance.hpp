// The reference a distance query is checked against: every triangle pair, tested one by one.
#pragma once

#include "bvh/mesh.hpp"
#include "bvh/triangle_distance.hpp"
#include "volumes/geometry.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace bvhlab::testing {

/// A triangle's centroid, the radius of the ball about it that holds the triangle, and the centroid's largest
/// coordinate (the scale of its rounding).
struct TriangleBall {
  Vec3 center;
  double radius = 0;
  double magnitude = 0;
};

inline TriangleBall ball_around(const TrianglePoints& t) {
  const Vec3 c = (t[0] + t[1] + t[2]) / 3.0;
  return {c, std::max({(t[0] - c).norm(), (t[1] - c).norm(), (t[2] - c).norm()}),
          c.lpNorm<Eigen::Infinity>()};
}

/// The smallest triangle_distance over every triangle pair, B moved by the pose: what the query must find.
/// A pair is skipped only when the balls around its triangles are farther apart than the best distance so
/// far by a margin well above rounding (it cannot hold the minimum): the sanitizer build spent 10 s a test
/// without it. No hierarchy takes part.
inline double brute_force_distance(const Mesh& a, const Mesh& b, const RigidTransform& pose) {
  std::vector<TrianglePoints> moved(b.triangles.size());
  std::vector<TriangleBall> balls_b(b.triangles.size());
  for (std::size_t j = 0; j < moved.size(); ++j) {
    const TrianglePoints t = b.triangle(static_cast<std::uint32_t>(j));
    moved[j] = {pose.apply(t[0]), pose.apply(t[1]), pose.apply(t[2])};
    balls_b[j] = ball_around(moved[j]);
  }
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < a.triangles.size(); ++i) {
    const TrianglePoints ta = a.triangle(static_cast<std::uint32_t>(i));
    const TriangleBall ball_a = ball_around(ta);
    for (std::size_t j = 0; j < moved.size(); ++j) {
      const double centers = (ball_a.center - balls_b[j].center).norm();
      const double gap = centers - ball_a.radius - balls_b[j].radius;
      const double scale = 1 + centers + ball_a.magnitude + balls_b[j].magnitude;
      if (gap > best + 1e-9 * scale) continue;
      best = std::min(best, triangle_distance(ta, moved[j]).distance);
    }
  }
  return best;
}

}  // namespace bvhlab::testing
