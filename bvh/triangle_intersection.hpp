// Exact triangle-triangle intersection (closed triangles: touching counts as intersecting).
#pragma once

#include "../volumes/geometry.hpp"

namespace bvhlab {

/// Fast test; agrees with triangles_intersect_exact on every input, degenerate triangles included.
/// Out-of-line wrapper of triangles_intersect_fast (bvh/triangle_intersection_fast.hpp, inlineable).
/// Throws std::invalid_argument for NaN or infinite coordinates.
bool triangles_intersect(const TrianglePoints& p, const TrianglePoints& q);

/// Ground truth: CGAL's exact predicates (Epick); degenerate triangles become segments or points.
/// Throws std::invalid_argument for NaN or infinite coordinates.
bool triangles_intersect_exact(const TrianglePoints& p, const TrianglePoints& q);

/// Whether the three points lie exactly on one line (repeated points included): CGAL's exact predicate.
/// Here so that callers such as the mesh loader need not parse CGAL themselves (8 s of each file's build).
bool exactly_collinear(const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace bvhlab
