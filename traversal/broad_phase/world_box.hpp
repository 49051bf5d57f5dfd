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
//   k-DOP                  with the tree's RootBounds (root_bounds, once per tree): the exact support of
//                          the rotated DOP on each world axis, max and min of row_k(R) . x over the root
//                          polytope's vertices (about 40 for a 24-DOP; dop_vertices). Without them, or when
//                          they cannot be trusted, the smaller of two upper bounds of that support: the
//                          rotated bounding_box(), and the LP-duality bound the DOP overlap test uses
//                          (kdop.hpp: the direction R^T e written as a non-negative combination of three
//                          plane normals at the prototype's extremal vertex; support <= the same combination
//                          of the offsets), exact for the prototype's shape only, at one vertex search per
//                          world axis. On world_dense.json's 75 instances the vertices take 4.7 µs per frame
//                          against the LP bound's 16.3 (1,250 instructions a box against 2,800, callgrind).
//   Sphere                 centre R c + t, radius r.
//
// With the object's BoundingBall (the farthest vertex from the root box's centre, computed once per tree;
// RootBounds holds it), the box is also cut to the cube around that ball: for a round object (a sphere
// meshed inside an Aabb tree) that cube is up to sqrt(3) times narrower than the rotated root box; for a
// box-like object the rotated root box stays the tighter, and the intersection keeps the better of the two
// on every axis.
//
// Every box is widened by a few ulps of the magnitudes involved, so rounding never loses a vertex (the DOP
// vertices' box by a few 1e-9 of the DOP's size more, their computation's error bound).
#pragma once

#include "../../bvh/bvh.hpp"
#include "../../volumes/kdop.hpp"
#include "../../volumes/obb.hpp"
#include "../../volumes/sphere.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

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

namespace world_box_detail {

/// The box cut to the cube around the ball (none: radius < 0).
inline Box cut_to_ball(const Box& box, const RigidTransform& pose, const BoundingBall& ball) {
  if (ball.radius < 0 || box.empty()) return box;
  const Box cube = around(pose.rotation * ball.centre + pose.translation, Vec3::Constant(ball.radius),
                          max_abs(ball.centre) + max_abs(pose.translation));
  return intersection(box, cube);
}

}  // namespace world_box_detail

/// The tree's world box, intersected with the cube around its bounding ball: the tighter of the two on
/// every axis (the ball wins for round objects, the root volume for long or flat ones).
template <TreeVolume BV>
Box world_box(const Bvh<BV>& tree, const RigidTransform& pose, const BoundingBall& ball) {
  return world_box_detail::cut_to_ball(world_box(tree, pose), pose, ball);
}

/// The vertices of a k-DOP's polytope {x : n_m . x <= d_m}, in its own frame, stored by rows (all x, all y,
/// all z) so that placing them by a rotation is three multiply-adds per row over contiguous memory; the
/// columns are padded to a multiple of kChunk with copies of the first vertex.
struct DopVertices {
  static constexpr Eigen::Index kChunk = 4;
  Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> points;
  double reach = 0;  ///< bound on every coordinate of the polytope (per-frame rounding)
  double slack = 0;  ///< bound on the computed vertices' error along any unit direction
  [[nodiscard]] bool empty() const { return points.cols() == 0; }
};

namespace world_box_detail {

/// Feasibility and merging tolerance of the vertex search, relative to the largest offset: far above the
/// rounding of a 3x3 solve of determinant >= kSmallestDeterminant (~1e-14), far below the float rounding
/// of the offsets (~1e-7).
inline constexpr double kVertexTolerance = 1e-9;
inline constexpr double kSmallestDeterminant = 0.1;  // unit normals of directions in {-1, 0, 1}^3: >= 0.19

}  // namespace world_box_detail

/// The DOP's vertices: each independent triple of planes meets in one point; the points inside every
/// half-space (to the tolerance) are kept once. Every vertex of the polytope, flat or a single point
/// included, is such a point. Empty (the LP bound then serves) for an empty or invalid DOP, and for a
/// direction set with an ill-conditioned triple, whose solve the tolerance would not cover.
template <class Set>
DopVertices dop_vertices(const KDop<Set>& dop) {
  constexpr std::size_t kPlanes = KDop<Set>::kPlanes;
  if (dop.empty() || !dop.valid()) return {};
  const auto& normals = KDop<Set>::tables().normals;
  double scale = 0;
  for (const float d : dop.offsets) scale = std::max(scale, std::abs(double(d)));
  const double tol = world_box_detail::kVertexTolerance * scale;
  auto inside = [&](const Vec3& x) {
    for (std::size_t m = 0; m < kPlanes; ++m)
      if (normals[m].dot(x) > double(dop.offsets[m]) + tol) return false;
    return true;
  };
  std::vector<Vec3> found;
  for (std::size_t i = 0; i < kPlanes; ++i)
    for (std::size_t j = i + 1; j < kPlanes; ++j)
      for (std::size_t l = j + 1; l < kPlanes; ++l) {
        Mat3 m;
        m << normals[i].transpose(), normals[j].transpose(), normals[l].transpose();
        const double det = std::abs(m.determinant());
        if (det <= 1e-6) continue;  // two parallel normals, or three in one plane: no vertex
        if (det < world_box_detail::kSmallestDeterminant) return {};
        const Vec3 x = m.inverse() * Vec3(dop.offsets[i], dop.offsets[j], dop.offsets[l]);
        const bool known = std::any_of(found.begin(), found.end(),
                                       [&](const Vec3& p) { return (p - x).cwiseAbs().maxCoeff() <= tol; });
        if (!known && inside(x)) found.push_back(x);
      }
  if (found.empty()) return {};
  DopVertices out;
  const auto count = Eigen::Index(found.size());
  out.points.resize(3, (count + DopVertices::kChunk - 1) / DopVertices::kChunk * DopVertices::kChunk);
  for (Eigen::Index k = 0; k < out.points.cols(); ++k)
    out.points.col(k) = found[std::size_t(k < count ? k : 0)];
  out.reach = scale;
  // Why 4 tol: a true vertex's solve is within ~1e-14 scale of it, so passes `inside`, and the point kept
  // for it is within tol of that solve per coordinate: 2 sqrt(3) tol along a unit direction at most.
  out.slack = 4 * tol;
  return out;
}

/// The world box of a DOP from its vertices: on each world axis k the exact support of the rotated
/// polytope, max and min of row_k(R) . x over the vertices, plus t_k; widened by the vertices' error and
/// the rounding of the products (a few ulps of the reach, as the rows of R are unit vectors).
inline Box world_box(const DopVertices& vertices, const RigidTransform& pose) {
  if (vertices.empty()) return {};
  using Chunk = Eigen::Array<double, DopVertices::kChunk, 1>;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const auto& p = vertices.points;
  Box out;
  for (int k = 0; k < 3; ++k) {
    const Vec3 row = pose.rotation.row(k).transpose();
    // kChunk vertices at a time in fixed-size arrays (vector registers); one axis per pass, so that the
    // accumulators and the row stay in registers.
    Chunk hi = Chunk::Constant(-kInf), lo = Chunk::Constant(kInf);
    for (Eigen::Index j = 0; j < p.cols(); j += DopVertices::kChunk) {
      const Chunk along = row.x() * p.row(0).segment<DopVertices::kChunk>(j).transpose().array() +
                          row.y() * p.row(1).segment<DopVertices::kChunk>(j).transpose().array() +
                          row.z() * p.row(2).segment<DopVertices::kChunk>(j).transpose().array();
      hi = hi.max(along);
      lo = lo.min(along);
    }
    const double t = pose.translation[k];
    const double widen = vertices.slack + world_box_detail::kUlps * (vertices.reach + std::abs(t));
    out.max[k] = hi.maxCoeff() + t + widen;
    out.min[k] = lo.minCoeff() + t - widen;
  }
  return out;
}

/// What a tree's world box uses beyond its root volume, derived once per tree (root_bounds): the bounding
/// ball and, for a k-DOP root, the root polytope's vertices.
struct RootBounds {
  BoundingBall ball;
  DopVertices dop;  ///< empty unless the root is a k-DOP whose vertices could be trusted
};

namespace world_box_detail {
template <class V>
struct IsKDop : std::false_type {};
template <class Set>
struct IsKDop<KDop<Set>> : std::true_type {};
}  // namespace world_box_detail

template <TreeVolume BV>
RootBounds root_bounds(const Bvh<BV>& tree) {
  RootBounds out{bounding_ball(tree), {}};
  if constexpr (world_box_detail::IsKDop<BV>::value)
    if (!tree.empty()) out.dop = dop_vertices(tree.root_volume());
  return out;
}

/// The tree's world box with its root bounds (root_bounds(tree)): a k-DOP root's vertices when known (the
/// exact support of the rotated root, no looser than the LP bound), else the root volume's box; then cut
/// to the bounding ball's cube.
template <TreeVolume BV>
Box world_box(const Bvh<BV>& tree, const RigidTransform& pose, const RootBounds& bounds) {
  if (bounds.dop.empty() || tree.empty()) return world_box(tree, pose, bounds.ball);
  return world_box_detail::cut_to_ball(world_box(bounds.dop, pose), pose, bounds.ball);
}

}  // namespace bvhlab
