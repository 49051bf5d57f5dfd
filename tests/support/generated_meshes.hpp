// Small procedural meshes for tests that must not depend on files.
#pragma once

#include "bench/core/generators.hpp"
#include "bvh/mesh.hpp"
#include "random_draws.hpp"

#include <random>
#include <vector>

namespace bvhlab::testing {

using generators::make_torus;  // bench/core/generators.hpp: one torus for benchmarks and tests

/// `count` random triangles of edge length about `size` inside [-1, 1]^3.
inline Mesh make_random_soup(int count, double size, std::uint64_t seed) {
  Mesh m;
  m.name = "soup";
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int t = 0; t < count; ++t) {
    const Vec3 c = draw_vec3(unit, rng);
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c + size * draw_vec3(unit, rng));
    const auto b = static_cast<std::uint32_t>(3 * t);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

/// A uniformly random rotation (from a random unit quaternion) and a translation in [-r, r]^3.
inline RigidTransform random_pose(std::mt19937_64& rng, double r) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(-r, r);
  Eigen::Quaterniond q = draw_quaternion(normal, rng);
  q.normalize();
  RigidTransform pose;
  pose.rotation = q.toRotationMatrix();
  pose.translation = draw_vec3(unit, rng);
  return pose;
}

/// 40 translations from the origin to (1.95, 0.39, 0): a copy of make_torus(0.7, 0.25, ...) moved along them
/// goes from overlapping its fixed twin to clear of it.
inline std::vector<RigidTransform> poses_along_x() {
  std::vector<RigidTransform> poses;
  for (int i = 0; i < 40; ++i) poses.push_back(RigidTransform::translate(Vec3(0.05 * i, 0.01 * i, 0)));
  return poses;
}

}  // namespace bvhlab::testing
