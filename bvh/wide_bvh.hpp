// Wide trees: a binary tree's topology collapsed to four children a node (after Embree: the topology first,
// then a node layout for it), and the layout of axis-aligned boxes for it, four children's boxes side by
// side (volumes/aabb4.hpp), so that one node's children are tested against a box of the other tree at once.
//
// A wide tree is built from a Bvh<Aabb> and refers to it for the leaves: a child that is a leaf names the
// binary leaf, whose triangles the binary tree holds. The queries take both trees and refuse a wide tree
// built from another binary one (binary_identity()).
#pragma once

#include "../volumes/aabb4.hpp"
#include "bvh.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

namespace bvhlab {

/// A binary topology collapsed to `kWidth` children a node. Each wide node stands for a binary inner node
/// and lists as children the binary nodes below it that it does not absorb: starting from its two children,
/// the one with the largest size (bounding-box volume) is replaced by its own two until there are kWidth or
/// only leaves. Every binary leaf is the child of exactly one wide node (a tree that is one leaf has no wide
/// node). Children keep the binary order (left before right), so a depth-first walk meets them as the
/// binary walk would.
struct WideTopology {
  static constexpr int kWidth = 4;
  struct Node {
    std::uint32_t binary = 0;                   ///< the binary inner node this node stands for
    std::array<std::uint32_t, kWidth> child{};  ///< binary node indices, `count` of them
    std::uint32_t count = 0;
  };
  std::vector<Node> nodes;  ///< root (the binary root) at 0, each node before its descendants
  /// The binary root's children collapse into node 0; an inner binary child c of a node is the wide node
  /// wide_of[c].
  std::vector<std::uint32_t> wide_of;  ///< binary node index -> wide node index (kNone: absorbed or leaf)
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};
};

/// Collapses `nodes` (children after parents, as build_topology stores them) using `sizes` (one per node) to
/// choose what to absorb. Throws std::invalid_argument when the two differ in length.
WideTopology collapse_topology(std::span<const TreeNode> nodes, std::span<const float> sizes);

/// The axis-aligned boxes of a wide topology: per wide node, its children's boxes (Aabb4, one lane each)
/// and what each child is: another wide node, or a binary leaf. A pseudo-node at index 0 holds the root's
/// own box in lane 0, so every box the walk needs sits in some node's lane: a walk starts at (0, lane 0).
class WideAabbTree {
 public:
  /// Child reference: a wide node index, or kLeaf | binary leaf index.
  static constexpr std::uint32_t kLeaf = 0x8000'0000u;
  struct Node {
    Aabb4 boxes;
    std::array<std::uint32_t, 4> child{};
  };

  /// From a built (or loaded) binary tree; throws std::invalid_argument for an empty tree.
  static WideAabbTree build(const Bvh<Aabb>& tree);

  [[nodiscard]] const Node& node(std::uint32_t i) const { return nodes_[i]; }
  [[nodiscard]] std::size_t size() const { return nodes_.size(); }
  [[nodiscard]] std::uint64_t binary_identity() const { return binary_identity_; }
  /// The lanes' boxes are stored less this point (the root box's centre): a tree far from its frame's
  /// origin keeps small numbers, and so does the pose between two near trees (Aabb4::make_context).
  [[nodiscard]] const Vec3& origin() const { return origin_; }
  [[nodiscard]] std::size_t bytes() const { return nodes_.size() * sizeof(Node); }

 private:
  std::vector<Node> nodes_;
  std::uint64_t binary_identity_ = 0;
  Vec3 origin_ = Vec3::Zero();
};

}  // namespace bvhlab
