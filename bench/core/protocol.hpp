// Zachmann's benchmark protocol (adb/README.md, section 4): B tumbles a full turn at distance d from A.
#pragma once

#include "volumes/geometry.hpp"

#include <numbers>
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

/// All poses of one distance, in step order.
inline std::vector<RigidTransform> protocol_poses(double distance, int steps) {
  std::vector<RigidTransform> poses;
  poses.reserve(static_cast<std::size_t>(steps));
  for (int k = 0; k < steps; ++k) poses.push_back(protocol_pose(distance, k, steps));
  return poses;
}

}  // namespace bvhlab
