// Small procedural meshes for tests that must not depend on files.
#pragma once

#include "bvh/mesh.hpp"

#include <cmath>
#include <numbers>
#include <random>

namespace bvhlab::testing {

/// Closed torus around the z axis: 2 * nu * nv triangles.
inline Mesh make_torus(double major, double minor, int nu, int nv) {
  Mesh m;
  m.name = "torus";
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = 2 * std::numbers::pi * i / nu, v = 2 * std::numbers::pi * j / nv;
      m.vertices.emplace_back((major + minor * std::cos(v)) * std::cos(u),
                              (major + minor * std::cos(v)) * std::sin(u), minor * std::sin(v));
    }
  auto id = [&](int i, int j) { return static_cast<std::uint32_t>((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// `count` random triangles of edge length about `size` inside [-1, 1]^3.
inline Mesh make_random_soup(int count, double size, std::uint64_t seed) {
  Mesh m;
  m.name = "soup";
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int t = 0; t < count; ++t) {
    const Vec3 c(unit(rng), unit(rng), unit(rng));
    for (int k = 0; k < 3; ++k) m.vertices.push_back(c + size * Vec3(unit(rng), unit(rng), unit(rng)));
    const auto b = static_cast<std::uint32_t>(3 * t);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

/// A uniformly random rotation (from a random unit quaternion) and a translation in [-r, r]^3.
inline RigidTransform random_pose(std::mt19937_64& rng, double r) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(-r, r);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  RigidTransform pose;
  pose.rotation = q.toRotationMatrix();
  pose.translation = Vec3(unit(rng), unit(rng), unit(rng));
  return pose;
}

}  // namespace bvhlab::testing
