// Procedural geometry shared by the benchmarks and the tests: a closed torus, box, sphere and cylinder, and
// random well-shaped triangles. Deterministic for a given std::mt19937_64 state (the benchmarks and the tests
// fix their seeds).
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

/// Closed axis-aligned box centred on the origin with sides (x, y, z): 8 vertices, 12 triangles.
inline Mesh make_box(double x, double y, double z) {
  Mesh m;
  m.name = "box";
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back(k & 1 ? x / 2 : -x / 2, k & 2 ? y / 2 : -y / 2, k & 4 ? z / 2 : -z / 2);
  // Two triangles per face, wound outwards; faces as corner quadruples in cyclic order.
  const std::uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

/// Closed UV sphere of radius r around the origin: `rings` latitude bands of `segments` quads (the bands at
/// the poles as triangle fans), 2 * segments * (rings - 1) triangles. Vertices lie on the sphere.
inline Mesh make_sphere(double r, int segments, int rings) {
  Mesh m;
  m.name = "sphere";
  m.vertices.emplace_back(0, 0, r);
  for (int i = 1; i < rings; ++i) {
    const double theta = std::numbers::pi * i / rings;
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      m.vertices.emplace_back(r * std::sin(theta) * std::cos(phi), r * std::sin(theta) * std::sin(phi),
                              r * std::cos(theta));
    }
  }
  m.vertices.emplace_back(0, 0, -r);
  const auto south = static_cast<std::uint32_t>(m.vertices.size() - 1);
  auto id = [&](int ring, int j) {
    return static_cast<std::uint32_t>(1 + (ring - 1) * segments + j % segments);
  };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({0, id(1, j), id(1, j + 1)});
    m.triangles.push_back({south, id(rings - 1, j + 1), id(rings - 1, j)});
  }
  for (int i = 1; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// Closed cylinder of radius r and length `length` along z, centred on the origin, its circles as
/// `segments`-gons: 4 * segments triangles.
inline Mesh make_cylinder(double r, double length, int segments) {
  Mesh m;
  m.name = "cylinder";
  for (int side = 0; side < 2; ++side)
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      m.vertices.emplace_back(r * std::cos(phi), r * std::sin(phi), side ? length / 2 : -length / 2);
    }
  m.vertices.emplace_back(0, 0, -length / 2);
  m.vertices.emplace_back(0, 0, length / 2);
  const auto bottom = static_cast<std::uint32_t>(2 * segments), top = bottom + 1;
  auto id = [&](int side, int j) { return static_cast<std::uint32_t>(side * segments + j % segments); };
  for (int j = 0; j < segments; ++j) {
    m.triangles.push_back({bottom, id(0, j + 1), id(0, j)});
    m.triangles.push_back({top, id(1, j), id(1, j + 1)});
    m.triangles.push_back({id(0, j), id(0, j + 1), id(1, j + 1)});
    m.triangles.push_back({id(0, j), id(1, j + 1), id(1, j)});
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
