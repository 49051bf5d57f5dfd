// A crude stand-in for ADB's annotation, independent of adb/annotate: each node's count is the number of
// triangles below it, capped at g^3 = 8 (grid 2, tau 0.5). The traversal tests run ADB's rule on it without
// paying for the clipping.
#pragma once

#include "adb/adb_density.hpp"
#include "adb/tree.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace bvhlab::testing {

template <class BV>
Tree<BV, AdbDensity> crude_adb_tree(const Mesh& mesh) {
  Bvh<BV> bvh = Bvh<BV>::build(mesh);
  std::vector<std::uint8_t> counts;
  for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
    counts.push_back(static_cast<std::uint8_t>(std::min<std::uint32_t>(8, end - begin)));
  return {std::move(bvh), AdbDensity::make_storage({2, 0.5}, std::move(counts))};
}

}  // namespace bvhlab::testing
