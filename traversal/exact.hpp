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
template <TreeVolume BV>
Result query_exact(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                   ContactMode mode = ContactMode::First) {
  using Walker = VolumeWalker<BV>;
  using Working = typename Walker::Working;
  b_to_a.validate();
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  if (!a.has_polygons() || !b.has_polygons())
    throw std::invalid_argument("exact query: a tree was loaded without polygons; exact mode needs them");

  const typename Walker::Context context = Walker::make_context(b_to_a);
  Counters& counters = result.counters;
  struct Entry {
    std::uint32_t i, j;
    [[no_unique_address]] Working wa;
    [[no_unique_address]] Working wb;
  };
  auto overlap = [&](const Entry& e) {
    ++counters.bv_tests;
    return Walker::overlap(a, e.i, e.wa, b, e.j, e.wb, context);
  };

  std::vector<Entry> stack;
  stack.reserve(64);
  if (const Entry root{0, 0, Walker::root_a(a, context), Walker::root_b(b, context)}; overlap(root))
    stack.push_back(root);

  const auto& tri_a = a.triangles();
  const auto& tri_b = b.triangles();
  while (!stack.empty()) {
    const Entry top = stack.back();
    stack.pop_back();
    ++counters.nodes_visited;
    const TreeNode& na = a.node(top.i);
    const TreeNode& nb = b.node(top.j);

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
    const bool split_a = nb.is_leaf() || (!na.is_leaf() && a.size(top.i) >= b.size(top.j));
    if (split_a) {
      for (std::uint32_t child : {na.right(), na.left()})
        if (const Entry e{child, top.j, Walker::child_a(a, top.wa, child, context), top.wb}; overlap(e))
          stack.push_back(e);
    } else {
      for (std::uint32_t child : {nb.right(), nb.left()})
        if (const Entry e{top.i, child, top.wa, Walker::child_b(b, top.wb, child, context)}; overlap(e))
          stack.push_back(e);
    }
  }
  return result;
}

}  // namespace bvhlab
