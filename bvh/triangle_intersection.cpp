#include "bvh/triangle_intersection.hpp"

#include "bvh/triangle_intersection_fast.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <tuple>

namespace bvhlab {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = K::Point_3;

K::Point_3 to_cgal(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

// A closed triangle as the point set it really is: CGAL's triangle tests require non-degenerate input.
// Under Epick, CGAL::do_intersect is one filtered predicate: the whole test runs in interval arithmetic and
// is redone exactly when that is inconclusive, so it is exact for every combination used below, even where
// it constructs intermediate objects (the supporting lines of Segment_3/Segment_3).
struct Shape {
  enum class Kind { point, segment, triangle } kind;
  Point a, b, c;  // the used prefix: 1, 2 or 3 points
};

Shape classify(const TrianglePoints& t, const char* name) {
  for (int i = 0; i < 3; ++i) {
    if (!t[i].allFinite())
      throw std::invalid_argument(std::string("triangles_intersect: triangle ") + name + " vertex " +
                                  std::to_string(i) + " has a NaN or infinite coordinate");
  }
  const Point a = to_cgal(t[0]), b = to_cgal(t[1]), c = to_cgal(t[2]);
  if (!CGAL::collinear(a, b, c)) return {Shape::Kind::triangle, a, b, c};
  // Collinear (repeated vertices included): the point set is the segment between the two extreme
  // points. Along a line, lexicographic (x, y, z) order is monotone, so the extremes are the
  // lexicographic minimum and maximum -- an exact choice, unlike comparing rounded edge lengths.
  const auto lex_less = [](const Vec3& u, const Vec3& v) {
    return std::tie(u.x(), u.y(), u.z()) < std::tie(v.x(), v.y(), v.z());
  };
  const auto [lo, hi] = std::minmax_element(t.begin(), t.end(), lex_less);
  if (!lex_less(*lo, *hi)) return {Shape::Kind::point, a, a, a};
  return {Shape::Kind::segment, to_cgal(*lo), to_cgal(*hi), to_cgal(*hi)};
}

bool shapes_intersect(const Shape& s, const Shape& t) {
  using Kind = Shape::Kind;
  if (s.kind < t.kind) return shapes_intersect(t, s);  // now s is the higher-dimensional one
  switch (s.kind) {
    case Kind::triangle: {
      const K::Triangle_3 tri(s.a, s.b, s.c);
      if (t.kind == Kind::triangle) return CGAL::do_intersect(tri, K::Triangle_3(t.a, t.b, t.c));
      if (t.kind == Kind::segment) return CGAL::do_intersect(tri, K::Segment_3(t.a, t.b));
      return CGAL::do_intersect(tri, t.a);
    }
    case Kind::segment: {
      const K::Segment_3 segment(s.a, s.b);
      if (t.kind == Kind::segment) return CGAL::do_intersect(segment, K::Segment_3(t.a, t.b));
      return CGAL::do_intersect(segment, t.a);
    }
    case Kind::point:
      return CGAL::do_intersect(s.a, t.a);
  }
  return false;
}
}  // namespace

bool triangles_intersect_exact(const TrianglePoints& p, const TrianglePoints& q) {
  return shapes_intersect(classify(p, "P"), classify(q, "Q"));
}

bool triangles_intersect(const TrianglePoints& p, const TrianglePoints& q) {
  return triangles_intersect_fast(p, q);
}

bool exactly_collinear(const Vec3& a, const Vec3& b, const Vec3& c) {
  return CGAL::collinear(to_cgal(a), to_cgal(b), to_cgal(c));
}

}  // namespace bvhlab
