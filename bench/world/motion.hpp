// Deterministic motion of a world scene's instances over frames: random placement in a region and a random
// walk (moves and turns per frame, in the manner of FCL's broad-phase update benchmark). The same seed gives
// the same frames on every machine (see random_poses in protocol.hpp).
#pragma once

#include "engine/protocol.hpp"
#include "volumes/geometry.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <span>
#include <vector>

namespace bvhlab {

/// x folded back into [lo, hi] as if reflected at both ends (a walk that leaves the region bounces back).
inline double reflect_into(double x, double lo, double hi) {
  const double length = hi - lo;
  double d = std::fmod(x - lo, 2 * length);
  if (d < 0) d += 2 * length;
  return lo + (d <= length ? d : 2 * length - d);
}

/// poses[f][i] for frames f = 0 .. frames-1. Frame 0: instance i at placements[i], or, where that is empty,
/// at a uniformly random position in `region` and a uniformly random rotation. Every later frame moves each
/// instance by a uniform amount in [-step, step] along each axis (reflected into `region`) and turns it by
/// uniform angles in [-turn_deg, turn_deg] about x, then y, then z (world axes, about its own centre).
inline std::vector<std::vector<RigidTransform>> random_walk(
    std::span<const std::optional<RigidTransform>> placements, const Box& region, std::uint64_t seed,
    int frames, double step, double turn_deg) {
  const auto n = static_cast<int>(placements.size());
  const std::vector<RigidTransform> random_start = random_poses(seed, n, region.min, region.max);
  std::vector<std::vector<RigidTransform>> poses(static_cast<std::size_t>(frames));
  for (int i = 0; i < n; ++i) {
    const auto at = static_cast<std::size_t>(i);
    poses[0].push_back(placements[at] ? *placements[at] : random_start[at]);
  }
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  auto symmetric = [&rng](double amount) {
    return amount * (2 * (static_cast<double>(rng() >> 11) * 0x1.0p-53) - 1);
  };
  const double turn = turn_deg * std::numbers::pi / 180;
  for (std::size_t f = 1; f < poses.size(); ++f) {
    poses[f] = poses[f - 1];
    for (RigidTransform& pose : poses[f]) {
      for (int axis = 0; axis < 3; ++axis) {
        const double moved = pose.translation[axis] + symmetric(step);
        pose.translation[axis] = step > 0 ? reflect_into(moved, region.min[axis], region.max[axis]) : moved;
      }
      const double ax = symmetric(turn), ay = symmetric(turn), az = symmetric(turn);
      const Eigen::Quaterniond q = Eigen::AngleAxisd(az, Vec3::UnitZ()) *
                                   Eigen::AngleAxisd(ay, Vec3::UnitY()) *
                                   Eigen::AngleAxisd(ax, Vec3::UnitX()) * Eigen::Quaterniond(pose.rotation);
      pose.rotation = q.normalized().toRotationMatrix();  // renormalised: no drift over many frames
    }
  }
  return poses;
}

}  // namespace bvhlab
