// The reference a distance query is checked against: every triangle pair, tested one by one.
#pragma once

#include "bvh/mesh.hpp"
#include "bvh/triangle_distance.hpp"
#include "volumes/geometry.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace bvhlab::testing {

/// The smallest triangle_distance over every triangle pair, B moved by the pose: what the query must find.
inline double brute_force_distance(const Mesh& a, const Mesh& b, const RigidTransform& pose) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < b.triangles.size(); ++j) {
    const TrianglePoints t = b.triangle(static_cast<std::uint32_t>(j));
    const TrianglePoints moved = {pose.apply(t[0]), pose.apply(t[1]), pose.apply(t[2])};
    for (std::size_t i = 0; i < a.triangles.size(); ++i)
      best = std::min(best, triangle_distance(a.triangle(static_cast<std::uint32_t>(i)), moved).distance);
  }
  return best;
}

}  // namespace bvhlab::testing
