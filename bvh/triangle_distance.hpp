// Triangle-triangle distance with closest points (closed triangles: touching means distance 0).
#pragma once

#include "../volumes/geometry.hpp"

#include <algorithm>

namespace bvhlab {

/// The distance between P and Q and a pair of points realising it: on_p in P, on_q in Q,
/// |on_p - on_q| == distance up to rounding. When the triangles intersect, distance is exactly 0 and
/// on_p == on_q is a point common to both.
struct TriangleDistance {
  double distance;
  Vec3 on_p;
  Vec3 on_q;
};

/// Zero exactly when triangles_intersect (exact) says the triangles meet, positive otherwise; elsewhere
/// within a few ulps of the pair's size (computed relative to p[0], so pairs far from the origin keep their
/// precision). Degenerate triangles count as the segment or point they are.
/// Throws std::invalid_argument for NaN or infinite coordinates.
TriangleDistance triangle_distance(const TrianglePoints& p, const TrianglePoints& q);

/// The gap between two vertex sets along direction w (either way), where it exceeds `margin` |w|: the
/// points are then farther apart than `margin`. Coordinates relative to a common point.
inline bool apart_along(const Vec3& w, const Vec3& p1, const Vec3& p2, const Vec3& q0, const Vec3& q1,
                        const Vec3& q2, double margin) {
  const double a1 = w.dot(p1), a2 = w.dot(p2), b0 = w.dot(q0), b1 = w.dot(q1), b2 = w.dot(q2);
  const double gap = std::max(std::min({b0, b1, b2}) - std::max({0.0, a1, a2}),
                              std::min({0.0, a1, a2}) - std::max({b0, b1, b2}));
  return gap > 0 && gap * gap > margin * margin * w.squaredNorm();
}

/// Whether triangle_distance(p, q) surely exceeds `distance`: a certificate for a search that skips pairs no
/// nearer than its best, at a few dozen instructions against triangle_distance's few thousand. It looks at
/// the gap between the triangles' bounding boxes, then at their gaps along the line between their centroids
/// and along either triangle's normal (facing surfaces, e.g. gear teeth, are parted there), relative to
/// p[0], so far from the origin it keeps the digits of the pair, and asks each to exceed the distance by
/// 1e-12 of the pair's extent, far more than triangle_distance's rounding (the directions need not be
/// exact: any direction's gap bounds the distance). False is always a valid answer (for NaN, overflow and
/// underflow it is the answer).
inline bool triangles_farther_than(const TrianglePoints& p, const TrianglePoints& q, double distance) {
  const Vec3 p_min = p[0].cwiseMin(p[1]).cwiseMin(p[2]), p_max = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
  const Vec3 q_min = q[0].cwiseMin(q[1]).cwiseMin(q[2]), q_max = q[0].cwiseMax(q[1]).cwiseMax(q[2]);
  const double extent = (p_max.cwiseMax(q_max) - p_min.cwiseMin(q_min)).maxCoeff();
  const double margin = distance + 1e-12 * (distance + extent);
  const Vec3 box_gap = (q_min - p_max).cwiseMax(p_min - q_max).cwiseMax(0.0);
  if (box_gap.squaredNorm() > margin * margin) return true;
  const Vec3 q0 = q[0] - p[0], q1 = q[1] - p[0], q2 = q[2] - p[0];
  const Vec3 p1 = p[1] - p[0], p2 = p[2] - p[0];
  const Vec3 w = (q0 + q1 + q2) - (p1 + p2);  // three times the centroids' difference
  return apart_along(w, p1, p2, q0, q1, q2, margin) ||
         apart_along(p1.cross(p2), p1, p2, q0, q1, q2, margin) ||
         apart_along((q1 - q0).cross(q2 - q0), p1, p2, q0, q1, q2, margin);
}

}  // namespace bvhlab
