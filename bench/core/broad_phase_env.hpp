// FCL's broad-phase test environment, rebuilt with bvhlab's own generators so the broad-phase benchmark and
// the FCL agreement test run both libraries on the same objects and motions.
//
// The environment (FCL's generateEnvironmentsMesh): equal numbers of boxes with sides 5 x 10 x 20, spheres
// of radius 30 and cylinders of radius 10 and length 40, as triangle meshes, placed uniformly in
// [-extent, extent]^3 (FCL: extent 2000) with rotations from uniform Euler angles in [-pi, pi]. The
// motion per frame (FCL's update test): each object turns by dR = Rx(a) Ry(b) Rz(c) with a, b, c uniform
// in [-10, 10] degrees and moves by dT uniform in [-0.01, 0.01] * extent per axis. FCL applies
// (R, T) -> (dR R, dR T + dT), which also swings the object about the world origin (hundreds of units a
// frame at 2000); Motion::Local applies (dR R, T + dT), the coherent variant.
#pragma once

#include "bench/core/generators.hpp"
#include "volumes/geometry.hpp"

#include <cstdint>
#include <numbers>
#include <random>
#include <vector>

namespace bvhlab::broad_phase_env {

enum class Motion { Fcl, Local };

struct Environment {
  std::vector<Mesh> shapes;             ///< box, sphere, cylinder
  std::vector<std::uint32_t> shape_of;  ///< object -> index into shapes
  std::vector<RigidTransform> poses;    ///< the first frame
  double extent = 0;
};

inline Mat3 euler_rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Vec3::UnitX()) * Eigen::AngleAxisd(b, Vec3::UnitY()) *
          Eigen::AngleAxisd(c, Vec3::UnitZ()))
      .toRotationMatrix();
}

/// `objects` objects (FCL's n boxes, n spheres, n cylinders for objects = 3n; otherwise the first kinds get
/// the remainder), in blocks of one kind as FCL orders them. Deterministic for a seed.
inline Environment make_environment(std::size_t objects, double extent = 2000, std::uint64_t seed = 1) {
  Environment env;
  env.extent = extent;
  env.shapes = {generators::make_box(5, 10, 20), generators::make_sphere(30, 16, 16),
                generators::make_cylinder(10, 40, 16)};
  std::mt19937_64 rng(seed);
  for (std::uint32_t kind = 0; kind < 3; ++kind) {
    const std::size_t count = objects / 3 + (kind < objects % 3 ? 1 : 0);
    for (std::size_t i = 0; i < count; ++i) {
      RigidTransform pose;
      pose.translation = generators::uniform_point(rng, -extent, extent);
      const double a = generators::uniform(rng, -std::numbers::pi, std::numbers::pi);
      const double b = generators::uniform(rng, -std::numbers::pi, std::numbers::pi);
      const double c = generators::uniform(rng, -std::numbers::pi, std::numbers::pi);
      pose.rotation = euler_rotation(a, b, c);
      env.shape_of.push_back(kind);
      env.poses.push_back(pose);
    }
  }
  return env;
}

/// One frame of FCL's update motion applied to every pose, in place.
inline void move(std::vector<RigidTransform>& poses, double extent, std::mt19937_64& rng,
                 Motion motion = Motion::Fcl) {
  const double max_angle = 10.0 / 360.0 * 2 * std::numbers::pi, max_step = 0.01 * extent;
  for (RigidTransform& pose : poses) {
    const double ax = generators::uniform(rng, -max_angle, max_angle);
    const double tx = generators::uniform(rng, -max_step, max_step);
    const double ay = generators::uniform(rng, -max_angle, max_angle);
    const double ty = generators::uniform(rng, -max_step, max_step);
    const double az = generators::uniform(rng, -max_angle, max_angle);
    const double tz = generators::uniform(rng, -max_step, max_step);
    const Mat3 turn = euler_rotation(ax, ay, az);
    pose.rotation = turn * pose.rotation;
    pose.translation =
        (motion == Motion::Fcl ? Vec3(turn * pose.translation) : pose.translation) + Vec3(tx, ty, tz);
  }
}

/// `count` frames starting with the environment's poses, each moved from the one before.
inline std::vector<std::vector<RigidTransform>> make_frames(const Environment& env, std::size_t count,
                                                            Motion motion = Motion::Fcl,
                                                            std::uint64_t seed = 2) {
  std::mt19937_64 rng(seed);
  std::vector<std::vector<RigidTransform>> frames;
  frames.reserve(count);
  std::vector<RigidTransform> poses = env.poses;
  for (std::size_t f = 0; f < count; ++f) {
    frames.push_back(poses);
    move(poses, env.extent, rng, motion);
  }
  return frames;
}

}  // namespace bvhlab::broad_phase_env
