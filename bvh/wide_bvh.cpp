#include "wide_bvh.hpp"

#include <algorithm>
#include <string>

namespace bvhlab {

namespace {

// The binary nodes one wide node keeps as children: from `inner`'s two, the largest inner child is
// replaced by its two, in place, until kWidth or only leaves remain.
std::vector<std::uint32_t> gather_children(std::span<const TreeNode> nodes, std::span<const float> sizes,
                                           std::uint32_t inner) {
  std::vector<std::uint32_t> children{nodes[inner].left(), nodes[inner].right()};
  while (children.size() < WideTopology::kWidth) {
    auto largest = children.end();
    for (auto it = children.begin(); it != children.end(); ++it)
      if (!nodes[*it].is_leaf() && (largest == children.end() || sizes[*it] > sizes[*largest])) largest = it;
    if (largest == children.end()) break;
    const TreeNode opened = nodes[*largest];
    *largest = opened.left();
    children.insert(largest + 1, opened.right());
  }
  return children;
}

}  // namespace

WideTopology collapse_topology(std::span<const TreeNode> nodes, std::span<const float> sizes) {
  if (nodes.size() != sizes.size())
    throw std::invalid_argument("collapse_topology: " + std::to_string(nodes.size()) + " nodes but " +
                                std::to_string(sizes.size()) + " sizes");
  WideTopology out;
  out.wide_of.assign(nodes.size(), WideTopology::kNone);
  if (nodes.empty() || nodes[0].is_leaf()) return out;
  // Breadth-first over the wide nodes: each is appended before its children's wide nodes.
  out.wide_of[0] = 0;
  out.nodes.push_back({0, {}, 0});
  for (std::size_t w = 0; w < out.nodes.size(); ++w) {
    const std::vector<std::uint32_t> children = gather_children(nodes, sizes, out.nodes[w].binary);
    out.nodes[w].count = static_cast<std::uint32_t>(children.size());
    for (std::size_t k = 0; k < children.size(); ++k) {
      const std::uint32_t c = children[k];
      out.nodes[w].child[k] = c;
      if (nodes[c].is_leaf()) continue;
      out.wide_of[c] = static_cast<std::uint32_t>(out.nodes.size());
      out.nodes.push_back({c, {}, 0});
    }
  }
  return out;
}

}  // namespace bvhlab
