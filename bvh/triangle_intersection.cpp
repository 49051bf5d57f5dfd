#include "bvh/triangle_intersection.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

namespace bvhlab {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
K::Point_3 to_cgal(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
}  // namespace

bool triangles_intersect_exact(const TrianglePoints& p, const TrianglePoints& q) {
  // Placeholder: non-degenerate only; the full version handles segments and points.
  const K::Triangle_3 a(to_cgal(p[0]), to_cgal(p[1]), to_cgal(p[2]));
  const K::Triangle_3 b(to_cgal(q[0]), to_cgal(q[1]), to_cgal(q[2]));
  return CGAL::do_intersect(a, b);
}
bool triangles_intersect(const TrianglePoints& p, const TrianglePoints& q) { return triangles_intersect_exact(p, q); }
}  // namespace bvhlab
