// Wide trees (bvh/wide_bvh.hpp): the collapsed topology keeps every binary leaf exactly once and fills its
// nodes, and the box layout's lanes contain the binary boxes they stand for.
#include "bvh/wide_bvh.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>

namespace bvhlab {
namespace {

std::vector<float> sizes_of(const Bvh<Aabb>& tree) {
  std::vector<float> sizes(tree.nodes().size());
  for (std::uint32_t i = 0; i < sizes.size(); ++i) sizes[i] = tree.size(i);
  return sizes;
}

TEST(WideTopology, KeepsEveryLeafOnceAndFillsItsNodes) {
  for (std::uint32_t leaf_size : {1u, 4u}) {
    BuildOptions options;
    options.max_leaf_triangles = leaf_size;
    const auto tree = Bvh<Aabb>::build(testing::make_random_soup(1500, 0.05, 7), options);
    const WideTopology wide = collapse_topology(tree.nodes(), sizes_of(tree));
    std::vector<int> seen(tree.nodes().size(), 0);
    std::size_t children = 0;
    for (const WideTopology::Node& n : wide.nodes) {
      ASSERT_GE(n.count, 2u);
      ASSERT_LE(n.count, 4u);
      children += n.count;
      for (std::uint32_t k = 0; k < n.count; ++k) {
        const std::uint32_t c = n.child[k];
        ++seen[c];
        if (!tree.node(c).is_leaf()) {
          ASSERT_NE(wide.wide_of[c], WideTopology::kNone);
        }
      }
      // Fewer than four children only when none of them can be opened.
      if (n.count < 4) {
        for (std::uint32_t k = 0; k < n.count; ++k) ASSERT_TRUE(tree.node(n.child[k]).is_leaf());
      }
    }
    std::size_t leaves = 0;
    for (std::uint32_t i = 0; i < tree.nodes().size(); ++i)
      if (tree.node(i).is_leaf()) {
        ++leaves;
        ASSERT_EQ(seen[i], 1) << "leaf " << i;
      }
    EXPECT_EQ(leaves, tree.stats().leaves);
    // Mostly full: only nodes of two or three leaves have fewer than four children.
    EXPECT_GT(double(children) / double(wide.nodes.size()), 2.7) << leaf_size;
  }
}

TEST(WideTopology, ChildrenKeepTheBinaryOrder) {
  const auto tree = Bvh<Aabb>::build(testing::make_torus(0.7, 0.25, 20, 10));
  const WideTopology wide = collapse_topology(tree.nodes(), sizes_of(tree));
  // The leaves in the wide tree's depth-first order are the binary tree's leaves in its depth-first order.
  std::vector<std::uint32_t> binary_order, wide_order;
  std::function<void(std::uint32_t)> walk_binary = [&](std::uint32_t i) {
    if (tree.node(i).is_leaf()) return binary_order.push_back(i);
    walk_binary(tree.node(i).left());
    walk_binary(tree.node(i).right());
  };
  std::function<void(std::uint32_t)> walk_wide = [&](std::uint32_t w) {
    for (std::uint32_t k = 0; k < wide.nodes[w].count; ++k) {
      const std::uint32_t c = wide.nodes[w].child[k];
      tree.node(c).is_leaf() ? wide_order.push_back(c) : walk_wide(wide.wide_of[c]);
    }
  };
  walk_binary(0);
  walk_wide(0);
  EXPECT_EQ(wide_order, binary_order);
}

TEST(WideTopology, RefusesSizesOfAnotherLength) {
  const auto tree = Bvh<Aabb>::build(testing::make_random_soup(20, 0.1, 3));
  EXPECT_THROW(collapse_topology(tree.nodes(), std::vector<float>(3, 1.0f)), std::invalid_argument);
  EXPECT_THROW(collapse_topology(tree.nodes(), std::vector<float>()), std::invalid_argument);
  EXPECT_TRUE(collapse_topology({}, {}).nodes.empty());
}

TEST(WideAabbTree, LanesContainTheBinaryBoxesTheyStandFor) {
  const auto tree = Bvh<Aabb>::build(testing::make_random_soup(800, 0.05, 9));
  const WideAabbTree wide = WideAabbTree::build(tree);
  std::size_t leaves = 0, checked = 0;
  // Walk the wide tree from the root lane, matching each lane to the binary node below it by containment
  // of that node's box: the leaves reached must be the binary tree's.
  std::function<void(std::uint32_t, int)> walk = [&](std::uint32_t n, int lane) {
    const WideAabbTree::Node& node = wide.node(n);
    const std::uint32_t child = node.child[lane];
    if (child & WideAabbTree::kLeaf) {
      const Aabb& box = tree.volume(child & ~WideAabbTree::kLeaf);
      ASSERT_TRUE(tree.node(child & ~WideAabbTree::kLeaf).is_leaf());
      const float c[3] = {node.boxes.cx[lane], node.boxes.cy[lane], node.boxes.cz[lane]};
      const float h[3] = {node.boxes.hx[lane], node.boxes.hy[lane], node.boxes.hz[lane]};
      for (int r = 0; r < 3; ++r) {  // lanes are stored less the tree's origin
        ASSERT_LE((long double)c[r] - h[r], (long double)box.lo[r] - wide.origin()[r]);
        ASSERT_GE((long double)c[r] + h[r], (long double)box.hi[r] - wide.origin()[r]);
      }
      ++leaves;
      return;
    }
    for (int k = 0; k < 4; ++k)
      if (!wide.node(child).boxes.empty(k)) {
        ++checked;
        walk(child, k);
      }
  };
  walk(0, 0);
  EXPECT_EQ(leaves, tree.stats().leaves);
  EXPECT_GT(checked, leaves);
  EXPECT_EQ(wide.binary_identity(), tree.identity());
}

}  // namespace
}  // namespace bvhlab
