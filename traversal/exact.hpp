// Exact traversal: one simultaneous-descent loop, generic over the bounding volume.
// Stops at the first intersecting triangle pair, or lists all of them.
#pragma once

#include "bvh/bvh.hpp"
#include "bvh/triangle_intersection.hpp"
#include "traversal/result.hpp"
#include "traversal/tree_access.hpp"

#include <utility>
#include <vector>

namespace bvhlab {

enum class ContactMode { First, All };

/// Exact first-contact (or all-contacts) query. `b_to_a` maps B's local frame into A's.
/// Const and thread-safe on shared trees: all traversal state lives on this call's stack.
template <BoundingVolume BV>
Result query_exact(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                   ContactMode mode = ContactMode::First) {
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  if (!a.has_polygons() || !b.has_polygons())
    throw std::invalid_argument("exact query: a tree was loaded without polygons; exact mode needs them");

  const typename BV::PairContext context = BV::make_context(b_to_a);
  Counters& counters = result.counters;
  auto overlap = [&](std::uint32_t i, std::uint32_t j) {
    ++counters.bv_tests;
    return BV::overlap(a.volume(i), b.volume(j), context);
  };

  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack;
  stack.reserve(64);
  if (overlap(0, 0)) stack.emplace_back(0, 0);

  const auto& tri_a = a.triangles();
  const auto& tri_b = b.triangles();
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    ++counters.nodes_visited;
    const TreeNode& na = a.node(i);
    const TreeNode& nb = b.node(j);

    if (na.is_leaf() && nb.is_leaf()) {
      for (std::uint32_t tb = nb.first; tb < nb.first + nb.count; ++tb) {
        const TrianglePoints moved = {b_to_a.apply(tri_b[tb][0]), b_to_a.apply(tri_b[tb][1]),
                                      b_to_a.apply(tri_b[tb][2])};
        for (std::uint32_t ta = na.first; ta < na.first + na.count; ++ta) {
          ++counters.triangle_tests;
          if (!triangles_intersect(tri_a[ta], moved)) continue;
          const TrianglePair hit{a.triangle_ids()[ta], b.triangle_ids()[tb]};
          result.collides = true;
          result.probability = 1;
          if (mode == ContactMode::First) {
            result.witness = hit;
            return result;
          }
          if (!result.witness) result.witness = hit;
          result.contacts.push_back(hit);
        }
      }
      continue;
    }
    // Descend into the larger node (a leaf cannot be split), testing children before pushing them.
    const bool split_a = nb.is_leaf() || (!na.is_leaf() && a.size(i) >= b.size(j));
    if (split_a) {
      if (overlap(na.right(), j)) stack.emplace_back(na.right(), j);
      if (overlap(na.left(), j)) stack.emplace_back(na.left(), j);
    } else {
      if (overlap(i, nb.right())) stack.emplace_back(i, nb.right());
      if (overlap(i, nb.left())) stack.emplace_back(i, nb.left());
    }
  }
  return result;
}

/// Strategy object: exact first contact or all contacts, over any tree that carries a Bvh.
struct ExactStrategy {
  ContactMode mode = ContactMode::First;

  template <class TreeA, class TreeB>
  Result query(const TreeA& a, const TreeB& b, const RigidTransform& b_to_a) const {
    return query_exact(bvh_of(a), bvh_of(b), b_to_a, mode);
  }
};

}  // namespace bvhlab
