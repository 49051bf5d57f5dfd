// Contact geometry of two intersecting triangles: where they meet and which way to push them apart.
#pragma once

#include "../volumes/geometry.hpp"

#include <optional>

namespace bvhlab {

/// Where two intersecting triangles meet.
struct TriangleContact {
  /// The segment P ∩ Q by its end points (one point twice, up to rounding, where they touch at a point).
  /// Coplanar triangles overlapping in a polygon: its two vertices farthest apart, the contact's extent.
  Vec3 from, to;
  /// Unit, from P into Q: normalize(n_p - n_q) of the face normals (vertex order, (v1 - v0) x (v2 - v0)),
  /// which points out of P and into Q for closed meshes with outward normals and is perpendicular to the
  /// segment. n_p when the faces are (nearly) parallel with the same orientation, the other triangle's
  /// (n_p or -n_q) when one is degenerate, zero only when both are.
  Vec3 normal;
  /// The planes coincide (within rounding) where the triangles meet: the contact is the polygon P ∩ Q (an
  /// edge or a point where they only touch).
  bool coplanar;
};

/// nullopt exactly when triangles_intersect(p, q) is false (the exact predicate decides). The end points lie
/// on both triangles up to a few 1e-14 of the pair's size; near-parallel planes blur the segment along
/// itself but not off the triangles. Degenerate triangles count as the segments or points they are.
/// Throws std::invalid_argument for NaN or infinite coordinates.
std::optional<TriangleContact> triangle_contact(const TrianglePoints& p, const TrianglePoints& q);

}  // namespace bvhlab
