// The answer of a distance query (traversal/distance.hpp), apart from its loops: the proximity strategies'
// declarations (traversal/distance_strategies.hpp) convert it without compiling them.
#pragma once

#include "../bvh/bvh.hpp"
#include "budget.hpp"
#include "result.hpp"

#include <cmath>

#include <limits>
#include <optional>
#include <stdexcept>

namespace bvhlab {

/// What a distance query answers. `distance` is the nearest pair found, `lower_bound` what is proven: they
/// are equal (and `exact`) unless a budget stopped the query, and the exact distance lies between them.
/// Points are in A's frame (on_b is B's point moved by the pose); `triangles` are source-mesh indices.
struct DistanceResult {
  double distance = std::numeric_limits<double>::infinity();
  double lower_bound = 0;
  Vec3 on_a = Vec3::Zero(), on_b = Vec3::Zero();
  std::optional<TrianglePair> triangles;  ///< empty only for an empty tree, or when stopped before a leaf
  bool exact = true;
  bool budget_exhausted = false;
  Counters counters;
};

namespace distance_detail {

/// Refuses a deadline that is negative, NaN or infinite, and a budget that allows nothing.
inline void check_anytime_budget(const Budget& budget) {
  if (!(budget.deadline_us >= 0) || std::isinf(budget.deadline_us))
    throw std::invalid_argument(
        "anytime distance: the deadline must be a finite number of microseconds >= 0");
  if (budget.unlimited())
    throw std::invalid_argument(
        "anytime distance: the budget is 0 (no BV-test cap and no deadline); give one, or ask for the full "
        "distance query");
}

}  // namespace distance_detail

}  // namespace bvhlab
