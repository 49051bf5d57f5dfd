// Zachmann's benchmark protocol (adb/README.md, section 4): B tumbles a full turn at distance d from A.
#pragma once

#include "volumes/geometry.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

namespace bvhlab {

struct ProtocolOptions {
  std::vector<double> distances{0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0};
  int steps = 5000;  ///< poses per distance: one full turn
};

/// Pose of B in A's frame at step k of `steps`: R = R_z(theta) R_x(theta), theta = 2 pi k / steps,
/// B's (normalised) centre at (d, 0, 0).
inline RigidTransform protocol_pose(double distance, int step, int steps) {
  const double theta = 2.0 * std::numbers::pi * static_cast<double>(step) / static_cast<double>(steps);
  RigidTransform pose;
  pose.rotation =
      (Eigen::AngleAxisd(theta, Vec3::UnitZ()) * Eigen::AngleAxisd(theta, Vec3::UnitX())).matrix();
  pose.translation = Vec3(distance, 0, 0);
  return pose;
}

/// All poses of one distance, in step order; with `stride`, only steps 0, stride, 2 stride, ...
inline std::vector<RigidTransform> protocol_poses(double distance, int steps, int stride = 1) {
  std::vector<RigidTransform> poses;
  poses.reserve(static_cast<std::size_t>(steps / stride + 1));
  for (int k = 0; k < steps; k += stride) poses.push_back(protocol_pose(distance, k, steps));
  return poses;
}

/// `count` poses of B in A's frame, drawn from `seed`: translation uniform in the box [lo, hi], rotation
/// uniform over all rotations (a uniform unit quaternion, Shoemake's method). The same seed gives the same
/// poses on every machine: the generator is std::mt19937_64 (its output is fixed by the standard) and the
/// conversion to [0, 1) is written out here rather than left to a library's distribution.
inline std::vector<RigidTransform> random_poses(std::uint64_t seed, int count, const Vec3& lo,
                                                const Vec3& hi) {
  std::mt19937_64 rng(seed);
  auto unit = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  std::vector<RigidTransform> poses;
  poses.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    RigidTransform pose;
    for (int axis = 0; axis < 3; ++axis) pose.translation[axis] = lo[axis] + (hi[axis] - lo[axis]) * unit();
    const double u = unit(), turn_1 = 2 * std::numbers::pi * unit(), turn_2 = 2 * std::numbers::pi * unit();
    const double r1 = std::sqrt(1 - u), r2 = std::sqrt(u);
    const Eigen::Quaterniond q(r2 * std::cos(turn_2), r1 * std::sin(turn_1), r1 * std::cos(turn_1),
                               r2 * std::sin(turn_2));
    pose.rotation = q.normalized().toRotationMatrix();
    poses.push_back(pose);
  }
  return poses;
}

}  // namespace bvhlab
