// The bounding-volume models every typed volume test runs over, and point sets to fit them to.
#pragma once

#include "support/random_draws.hpp"
#include "support/test_volumes.hpp"
#include "support/volume_lists.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace bvhlab::volume_tests {

using testing::draw_quaternion;
using testing::draw_vec3;

/// Every shipped self-contained model, and the capsule that exists only under tests/.
using AllModels =
    testing::ConcatTypes<testing::ShippedBoundingVolumes, ::testing::Types<testing::Capsule>>::type;

struct ModelName {
  template <class BV>
  static std::string GetName(int) {
    return std::string(BV::name());
  }
};

inline Mat3 random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q = draw_quaternion(normal, rng);
  return q.normalized().toRotationMatrix();
}

inline Vec3 gaussian_vec(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return {normal(rng), normal(rng), normal(rng)};
}

struct PointSet {
  std::string label;
  std::vector<Vec3> points;
};

/// Random clouds of several shapes, sizes and offsets, and the degenerate sets every fit must survive.
inline std::vector<PointSet> sample_point_sets(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<PointSet> sets;
  auto cloud = [&](int n, const Vec3& spread, double offset) {
    const Mat3 r = random_rotation(rng);
    const Vec3 center = offset * gaussian_vec(rng);
    std::vector<Vec3> pts;
    for (int i = 0; i < n; ++i) pts.push_back(center + r * gaussian_vec(rng).cwiseProduct(spread));
    return pts;
  };
  for (int k = 0; k < 4; ++k) {
    sets.push_back({"cloud", cloud(4 + 20 * k, Vec3(1, 0.6, 0.3), 1)});
    sets.push_back({"needle", cloud(30, Vec3(1, 0.01, 0.01), 2)});
    sets.push_back({"offset cloud", cloud(25, Vec3(1e-3, 2e-3, 5e-4), 1e3)});
    sets.push_back({"tiny cloud", cloud(12, Vec3(1e-7, 1e-7, 1e-7), 1e-6)});
    sets.push_back({"triangle", cloud(3, Vec3(1, 1, 1), 1)});
  }
  // Uniform cube and sphere-surface clouds: extreme points everywhere.
  std::vector<Vec3> cube, shell;
  for (int i = 0; i < 200; ++i) {
    cube.push_back(draw_vec3(unit, rng));
    shell.push_back(gaussian_vec(rng).normalized());
  }
  sets.push_back({"cube", cube});
  sets.push_back({"shell", shell});
  // Degenerate sets.
  sets.push_back({"flat random plane", cloud(40, Vec3(1, 0.7, 0), 1)});
  std::vector<Vec3> flat_axis, collinear_axis;
  for (int i = 0; i < 20; ++i) {
    const double y = unit(rng);
    flat_axis.emplace_back(unit(rng), y, 0.25);
    collinear_axis.emplace_back(unit(rng), -0.5, 0.125);
  }
  sets.push_back({"flat z = const", flat_axis});
  sets.push_back({"collinear random line", cloud(15, Vec3(1, 0, 0), 1)});
  sets.push_back({"collinear x line", collinear_axis});
  sets.push_back({"single point", {Vec3(0.3, -0.2, 0.7)}});
  sets.push_back({"origin", {Vec3::Zero()}});
  sets.push_back({"repeated point", std::vector<Vec3>(5, Vec3(-1.5, 2.25, 1e-3))});
  sets.push_back({"two points", {Vec3(1, 2, 3), Vec3(-1, 0.5, 2)}});
  return sets;
}

/// A random non-degenerate triangle of size about `size` around `center`.
inline TrianglePoints random_triangle(std::mt19937_64& rng, const Vec3& center, double size) {
  for (;;) {
    TrianglePoints t = {center + size * gaussian_vec(rng), center + size * gaussian_vec(rng),
                        center + size * gaussian_vec(rng)};
    const double area = (t[1] - t[0]).cross(t[2] - t[0]).norm();
    const double longest = std::max({(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()});
    if (area > 0.05 * longest * longest) return t;
  }
}

inline std::vector<Vec3> vertices_of(std::span<const TrianglePoints> triangles) {
  std::vector<Vec3> out;
  for (const auto& t : triangles) out.insert(out.end(), t.begin(), t.end());
  return out;
}

inline TrianglePoints transformed(const RigidTransform& pose, const TrianglePoints& t) {
  return {pose.apply(t[0]), pose.apply(t[1]), pose.apply(t[2])};
}

}  // namespace bvhlab::volume_tests
