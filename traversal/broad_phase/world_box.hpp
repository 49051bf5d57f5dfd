// The world box of an object: the axis-aligned box, in the world frame, around its tree's root volume
// placed by the object's pose. The broad phases take these boxes; they contain every transformed vertex of
// the object, and are as tight as the root volume allows at O(1) cost:
//
//   Root volume            World box
//   axis-aligned (Aabb,    the rotated box's own AABB: centre R c + t, half-extents |R| h. Never the cube
//   RestrictedBox's root,  around a bounding sphere (what a box-like root gives under rotation when only
//   any other volume)      centre and radius are kept): for a long box that would be far looser.
//   Obb                    the same with the box's own axes: half-extents |R A| h (A: the OBB's axes),
//                          intersected with the rotated bounding_box().
//   k-DOP                  on each world axis, the smaller of two upper bounds of the DOP's support: the
//                          rotated bounding_box(), and the LP-duality bound the DOP overlap test uses
//                          (kdop.hpp: the direction R^T e written as a non-negative combination of three
//                          plane normals at the prototype's extremal vertex; support <= the same combination
//                          of the offsets). The second is exact for the prototype's shape and usually
//                          tighter for a rotated DOP; it costs one vertex search per world axis (three:
//                          the prototype's symmetry gives the opposite direction's bound with it).
//   Sphere                 centre R c + t, radius r.
//
// With the object's BoundingBall (the farthest vertex from the root box's centre, computed once per tree),
// the box is also cut to the cube around that ball: for a round object (a sphere meshed inside an Aabb
// tree) that cube is up to sqrt(3) times narrower than the rotated root box; for a box-like object the
// rotated root box stays the tighter, and the intersection keeps the better of the two on every axis.
//
// Every box is widened by a few ulps of the magnitudes involved, so rounding never loses a vertex.
#pragma once

#include "../../bvh/bvh.hpp"
#include "../../volumes/kdop.hpp"
#include "../../volumes/obb.hpp"
#include "../../volumes/sphere.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bvhlab {

namespace world_box_detail {

inline constexpr double kUlps = 64 * std::numeric_limits<double>::epsilon();

// Written out on three scalars: Eigen's reductions over a Vec3 were left as calls, a third of the time of a
// world box (one is taken per object and frame).
inline double max_of(const Vec3& v) {
  return std::max(std::max(v.x(), v.y()), v.z());
}
inline double max_abs(const Vec3& v) {
  return std::max(std::max(std::abs(v.x()), std::abs(v.y())), std::abs(v.z()));
}

/// The box with centre c and half-extents h, widened by the rounding of computing them.
inline Box around(const Vec3& c, const Vec3& h, double magnitude) {
  const Vec3 reach = h.array() + kUlps * (magnitude + max_abs(c) + max_of(h));
  return {c - reach, c + reach};
}

inline Box intersection(const Box& a, const Box& b) {
  return {a.min.cwiseMax(b.min), a.max.cwiseMin(b.max)};
}

/// The world AABB of a box given in the object's frame.
inline Box rotated_box(const Box& local, const RigidTransform& pose) {
  if (local.empty()) return {};
  const Vec3 c = local.center(), h = local.extent() * 0.5;
  return around(pose.rotation * c + pose.translation, pose.rotation.cwiseAbs() * h,
                max_abs(c) + max_abs(pose.translation));
}

}  // namespace world_box_detail

/// Any volume: its bounding_box() placed by the pose (exact for axis-aligned volumes).
template <BoundingVolume V>
Box world_box(const V& volume, const RigidTransform& pose) {
  return world_box_detail::rotated_box(volume.bounding_box(), pose);
}

inline Box world_box(const Sphere& sphere, const RigidTransform& pose) {
  if (sphere.empty()) return {};
  const Vec3 c = to_vec(sphere.center);
  return world_box_detail::around(pose.rotation * c + pose.translation, Vec3::Constant(sphere.radius),
                                  c.cwiseAbs().maxCoeff() + pose.translation.cwiseAbs().maxCoeff());
}

inline Box world_box(const Obb& obb, const RigidTransform& pose) {
  if (obb.empty()) return {};
  const Vec3 c = to_vec(obb.center), h = to_vec(obb.half);
  const Mat3 axes = pose.rotation * Obb::axes_of(obb.orientation);
  // The stored axes are orthonormal to a few ulps only: widen by 2^-20 of the box's reach, more than
  // Obb::bounding_box() allows for the same rounding.
  const double frame_slack = 0x1p-20 * (c.cwiseAbs().maxCoeff() + h.sum());
  const Box own = world_box_detail::around(pose.rotation * c + pose.translation,
                                           axes.cwiseAbs() * h + Vec3::Constant(frame_slack),
                                           c.cwiseAbs().maxCoeff() + pose.translation.cwiseAbs().maxCoeff());
  return world_box_detail::intersection(own, world_box_detail::rotated_box(obb.bounding_box(), pose));
}

template <class Set>
Box world_box(const KDop<Set>& dop, const RigidTransform& pose) {
  using D = KDop<Set>;
  if (dop.empty()) return {};
  const auto& tables = D::tables();
  double scale = 0;  // largest |x|, |y|, |z| offset: every point of the DOP is within sqrt(3) * scale
  for (std::size_t a = 0; a < 3; ++a)
    scale = std::max({scale, std::abs(double(dop.offsets[a])), std::abs(double(dop.offsets[a + D::kAxes]))});
  // support(v) = max over the DOP of v . x, bounded by sum lambda_m d_m (kdop.hpp); v in the object frame.
  // The prototype is symmetric: v = sum lambda_k n_(m_k) gives -v = sum lambda_k n_(opposite m_k) with the
  // same lambda, so one vertex search bounds the support in both directions.
  struct SupportPair {
    double plus, minus;  // bounds of support(v) and support(-v)
  };
  auto supports = [&](const Vec3& v) {
    std::array<std::uint8_t, 3> planes{};
    std::array<double, 3> lambda{};
    tables.realign(v, planes, lambda);
    SupportPair bound{0, 0};
    double weight = 0;
    for (int k = 0; k < 3; ++k) {
      bound.plus += lambda[k] * double(dop.offsets[planes[k]]);
      bound.minus += lambda[k] * double(dop.offsets[tables.opposite(planes[k])]);
      weight += std::abs(lambda[k]);
    }
    // Rounding of lambda (and a lambda a hair below zero) moves the bound by ulps of weight * |x|.
    const double slack = 1024 * std::numeric_limits<double>::epsilon() * (weight + 1) * 2 * scale;
    return SupportPair{bound.plus + slack, bound.minus + slack};
  };
  Box own;
  for (int k = 0; k < 3; ++k) {
    const Vec3 v = pose.rotation.row(k).transpose();  // world axis k in the object frame
    const double t = pose.translation[k];
    const SupportPair s = supports(v);
    own.max[k] = s.plus + t + world_box_detail::kUlps * std::abs(t);
    own.min[k] = -s.minus + t - world_box_detail::kUlps * std::abs(t);
  }
  return world_box_detail::intersection(own, world_box_detail::rotated_box(dop.bounding_box(), pose));
}

/// The world box of a whole tree: its root's volume (decoded, for hierarchical volumes) under the pose.
/// Empty for an empty tree.
template <TreeVolume BV>
Box world_box(const Bvh<BV>& tree, const RigidTransform& pose) {
  if (tree.empty()) return {};
  return world_box(tree.root_volume(), pose);
}

/// A ball around every vertex of an object, in its own frame: the centre of its root's bounding box and
/// the distance to the farthest vertex. Derived once per tree (bounding_ball); a round object's rotated
/// root box is up to sqrt(3) times wider than the cube around this ball.
struct BoundingBall {
  Vec3 centre = Vec3::Zero();
  double radius = -1;  ///< negative: no ball known (the root volume alone bounds the object)
};

/// The tree's bounding ball from its polygons; no ball (radius -1) for a tree loaded without them.
template <TreeVolume BV>
BoundingBall bounding_ball(const Bvh<BV>& tree) {
  BoundingBall ball;
  if (tree.empty() || !tree.has_polygons()) return ball;
  ball.centre = tree.root_volume().bounding_box().center();
  double farthest = 0;
  for (const TrianglePoints& t : tree.triangles())
    for (const Vec3& v : t) farthest = std::max(farthest, (v - ball.centre).squaredNorm());
  ball.radius = std::sqrt(farthest) * (1 + world_box_detail::kUlps);
  return ball;
}

/// The tree's world box, intersected with the cube around its bounding ball: the tighter of the two on
/// every axis (the ball wins for round objects, the root volume for long or flat ones).
template <TreeVolume BV>
Box world_box(const Bvh<BV>& tree, const RigidTransform& pose, const BoundingBall& ball) {
  const Box box = world_box(tree, pose);
  if (ball.radius < 0 || box.empty()) return box;
  const Box cube = world_box_detail::around(
      pose.rotation * ball.centre + pose.translation, Vec3::Constant(ball.radius),
      world_box_detail::max_abs(ball.centre) + world_box_detail::max_abs(pose.translation));
  return world_box_detail::intersection(box, cube);
}

}  // namespace bvhlab
