// The paths the coherent queries' tests share (tests/traversal/coherent_suite.hpp, test_coherent_adb.cpp):
// a torus against a triangle soup, B approaching through contact and out again, and CGAL's answers on it.
#pragma once

#include "bench/core/ground_truth.hpp"
#include "bvh/triangle_intersection.hpp"
#include "support/generated_meshes.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <vector>

namespace bvhlab::coherent_tests {

inline const Mesh& torus() {
  static const Mesh mesh = testing::make_torus(0.7, 0.25, 40, 20);
  return mesh;
}
inline const Mesh& soup() {
  static const Mesh mesh = testing::make_random_soup(600, 0.08, 11);
  return mesh;
}

/// B approaches A along x, through contact and out again, turning a little each step: `steps` poses.
inline std::vector<RigidTransform> path(int steps, double turn_per_step = 0.004) {
  std::vector<RigidTransform> poses;
  for (int k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) / (steps - 1);
    RigidTransform pose;
    pose.rotation = Eigen::AngleAxisd(turn_per_step * k, Vec3(1, 2, 3).normalized()).matrix();
    pose.translation = Vec3(3.0 - 1.7 * std::sin(3.14159265358979 * t), 0.1, 0.05);
    poses.push_back(pose);
  }
  return poses;
}

inline const std::vector<bool>& path_truth() {
  static const std::vector<bool> truth = [] {
    const CgalGroundTruth cgal(torus(), soup());
    std::vector<bool> out;
    for (const RigidTransform& pose : path(240)) out.push_back(cgal.collides(pose));
    return out;
  }();
  return truth;
}

inline bool witness_intersects(const Result& r, const RigidTransform& pose) {
  const auto ta = torus().triangle(r.witness->a), tb = soup().triangle(r.witness->b);
  return triangles_intersect_exact(ta, {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])});
}

}  // namespace bvhlab::coherent_tests
