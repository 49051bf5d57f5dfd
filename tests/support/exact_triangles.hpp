// The exact kernel as the triangle-pair suites use it: CGAL's Epeck points and triangles from bvhlab's, its
// lazy numbers refined to a chosen precision, and the sizes the suites' tolerances scale with.
#pragma once

#include "volumes/geometry.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>

#include <algorithm>
#include <cstddef>
#include <initializer_list>

namespace bvhlab::testing {

// Full counts in optimised builds; a tenth where assertions are on (Debug: CGAL checks everything).
#ifdef NDEBUG
inline constexpr std::size_t kFamilyScale = 1;
#else
inline constexpr std::size_t kFamilyScale = 10;
#endif

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using ExactPoint = K::Point_3;

inline ExactPoint exact_point(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}
inline K::Triangle_3 exact_triangle(const TrianglePoints& t) {
  return {exact_point(t[0]), exact_point(t[1]), exact_point(t[2])};
}

/// CGAL refines a lazy number (exactly, in rationals) only where its interval is wider than the relative
/// precision asked for (1e-5 unless asked).
inline double to_double(const K::FT& x, double relative_precision) {
  K::FT::set_relative_precision_of_to_double(relative_precision);
  return CGAL::to_double(x);
}

inline double longest_edge(const TrianglePoints& t) {
  return std::max({(t[1] - t[0]).stableNorm(), (t[2] - t[1]).stableNorm(), (t[0] - t[2]).stableNorm()});
}
inline double largest_coordinate(std::initializer_list<Vec3> points) {
  double m = 0;
  for (const Vec3& v : points) m = std::max(m, v.cwiseAbs().maxCoeff());
  return m;
}

}  // namespace bvhlab::testing
