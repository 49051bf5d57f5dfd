// Volume of the convex hull of a point set (CGAL), kept out of the test headers for compile time.
#pragma once

#include "volumes/geometry.hpp"

#include <span>

namespace bvhlab::volume_tests {

/// 0 for fewer than four points or a flat set.
double convex_hull_volume(std::span<const Vec3> points);

}  // namespace bvhlab::volume_tests
