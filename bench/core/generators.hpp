// Procedural geometry shared by the benchmarks and the tests: a closed torus, and random well-shaped
// triangles. Deterministic for a given std::mt19937_64 state (the benchmarks and the tests fix their seeds).
#pragma once

#include "bvh/mesh.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>

namespace bvhlab::generators {

/// Closed torus around the z axis: 2 * nu * nv triangles, major radius `major`, tube radius `minor`.
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

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline Vec3 uniform_point(std::mt19937_64& rng, double lo, double hi) {
  return {uniform(rng, lo, hi), uniform(rng, lo, hi), uniform(rng, lo, hi)};
}

inline Vec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Vec3 v{normal(rng), normal(rng), normal(rng)};
  return v / v.norm();
}

/// A well-shaped triangle around `centre`: random plane orientation, circumradius 0.3..0.6, angles perturbed.
inline TrianglePoints random_triangle(std::mt19937_64& rng, const Vec3& centre) {
  const Vec3 a = random_unit(rng);
  const Vec3 b = a.cross(random_unit(rng)).normalized();
  const Vec3 c = a.cross(b);
  const double radius = uniform(rng, 0.3, 0.6), phase = uniform(rng, 0, 2 * std::numbers::pi);
  TrianglePoints t;
  for (int k = 0; k < 3; ++k) {
    const double angle = phase + 2 * std::numbers::pi * k / 3 + uniform(rng, -0.6, 0.6);
    t[k] = centre + radius * (std::cos(angle) * b + std::sin(angle) * c);
  }
  return t;
}

}  // namespace bvhlab::generators
