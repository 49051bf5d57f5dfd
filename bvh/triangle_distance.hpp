// Triangle-triangle distance with closest points (closed triangles: touching means distance 0).
#pragma once

#include "../volumes/geometry.hpp"

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

}  // namespace bvhlab
