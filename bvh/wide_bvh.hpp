// Wide trees: a binary tree's topology collapsed to four children a node (after Embree: the topology first,
// then a node layout for it), and the layout of the volumes for it, four children's volumes side by side
// (volumes/aabb4.hpp, volumes/kdop4.hpp, volumes/sphere4.hpp, volumes/obb4.hpp), so that one node's children
// are tested against a volume of the other tree at once.
//
// A wide tree is built from a binary Bvh and refers to it for the leaves: a child that is a leaf names the
// binary leaf, whose triangles the binary tree holds. The queries take both trees and refuse a wide tree
// built from another binary one (binary_identity()), or from this one before a refit moved its volumes
// (binary_revision()): build the wide tree again after a refit.
#pragma once

#include "../volumes/aabb4.hpp"
#include "../volumes/kdop4.hpp"
#include "../volumes/obb4.hpp"
#include "../volumes/restricted_box4.hpp"
#include "../volumes/sphere4.hpp"
#include "bvh.hpp"

#include <array>
#include <concepts>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

namespace bvhlab {

/// A binary topology collapsed to `kWidth` children a node. Each wide node stands for a binary inner node
/// and lists as children the binary nodes below it that it does not absorb: starting from its two children,
/// the one with the largest size (bounding-box volume) is replaced by its own two until there are kWidth or
/// only leaves. Every binary leaf is the child of exactly one wide node (a tree that is one leaf has no wide
/// node). Children keep the binary order (left before right), so a depth-first walk in lane order meets
/// them as the binary walk would (the all-contacts walk does; a first-contact walk takes the nearest first).
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

/// The volumes of a wide topology, laid out by `Lanes` (a block of four volumes side by side: Aabb4 for
/// AABB trees, KDop4 for k-DOP trees): per wide node its children's volumes, one lane each, and what each
/// child is, another wide node or a binary leaf. A pseudo-node at index 0 holds the root's own volume in
/// lane 0, so every volume the walk needs sits in some node's lane: a walk starts at (0, lane 0). Lanes are
/// stored relative to origin(), the centre of the root's bounding box.
///
/// (Aabb4 for boxes, KDop4 for k-DOPs, Sphere4 for spheres, Obb4 for oriented boxes, RestrictedBox4 for
/// restricted boxes.) Lanes provides: `Volume` (the binary tree's volume type), `set(lane, volume, origin)`
/// (a default Lanes is four empty lanes) or `pack(boxes, origin)` (a node's children's decoded boxes at
/// once), `volume(lane)` (its bounding box's volume, for the descent), and the test used by
/// traversal/wide_exact.hpp: `PairContext`, `make_context(pose, origin_a, origin_b)`, `broadcast`, `place`,
/// `overlap_placed`.
template <class Lanes>
class WideBvh {
 public:
  using Volume = typename Lanes::Volume;
  /// Child reference: a wide node index, or kLeaf | binary leaf index.
  static constexpr std::uint32_t kLeaf = 0x8000'0000u;
  struct Node {
    Lanes boxes;
    std::array<std::uint32_t, 4> child{};
  };

  /// From a built (or loaded) binary tree; throws std::invalid_argument for an empty tree or one of 2^31
  /// nodes or more.
  static WideBvh build(const Bvh<Volume>& tree) {
    if (tree.empty()) throw std::invalid_argument("wide tree: the binary tree is empty");
    if (tree.nodes().size() >= kLeaf) throw std::invalid_argument("wide tree: too many nodes");
    std::vector<float> sizes(tree.nodes().size());
    for (std::uint32_t i = 0; i < sizes.size(); ++i) sizes[i] = tree.size(i);
    const WideTopology topology = collapse_topology(tree.nodes(), sizes);
    WideBvh out;
    out.binary_identity_ = tree.identity();
    out.binary_revision_ = tree.volumes_revision();
    // Layouts that pack a node's children together (RestrictedBox4) take their boxes, decoded; the others
    // set each lane from the volume as stored.
    constexpr bool packs = requires(std::span<const Box> boxes) {
      Lanes::pack(boxes, Vec3::Zero());
    };
    std::vector<Box> boxes;
    if constexpr (packs) {
      boxes = tree.node_boxes();
      out.origin_ = boxes[0].center();
    } else {
      out.origin_ = tree.volume(0).bounding_box().center();
    }
    // Node 0: the root's own volume in lane 0; the wide nodes follow, shifted by one.
    out.nodes_.resize(topology.nodes.size() + 1);
    out.binary_.resize(topology.nodes.size() + 1);
    for (std::size_t w = 0; w < topology.nodes.size(); ++w) out.binary_[w + 1] = topology.nodes[w].binary;
    const auto fill = [&](Node& to, std::span<const std::uint32_t> children) {
      std::array<Box, 4> packed;
      for (std::size_t k = 0; k < children.size(); ++k) {
        const std::uint32_t c = children[k];
        if constexpr (packs)
          packed[k] = boxes[c];
        else
          to.boxes.set(static_cast<int>(k), tree.volume(c), out.origin_);
        to.child[k] = tree.node(c).is_leaf() ? (kLeaf | c) : topology.wide_of[c] + 1;
      }
      if constexpr (packs) to.boxes = Lanes::pack(std::span(packed).first(children.size()), out.origin_);
    };
    const std::uint32_t root = 0;
    fill(out.nodes_[0], std::span(&root, 1));  // an inner root is wide node 0, here 1
    for (std::size_t w = 0; w < topology.nodes.size(); ++w) {
      const WideTopology::Node& from = topology.nodes[w];
      fill(out.nodes_[w + 1], std::span(from.child).first(from.count));
    }
    return out;
  }

  [[nodiscard]] const Node& node(std::uint32_t i) const { return nodes_[i]; }
  /// The binary node that lane `lane` of wide node `i` holds: a binary leaf, or the binary inner node a wide
  /// child stands for. What a walk reads the binary tree's annotations with (ADB's counts: wide_adb.hpp).
  [[nodiscard]] std::uint32_t binary_node(std::uint32_t i, std::uint32_t lane) const {
    const std::uint32_t c = nodes_[i].child[lane];
    return (c & kLeaf) ? c & ~kLeaf : binary_[c];
  }
  [[nodiscard]] std::size_t size() const { return nodes_.size(); }
  [[nodiscard]] std::uint64_t binary_identity() const { return binary_identity_; }
  /// The binary tree's volumes_revision() when this was built: a refit of the binary tree leaves this
  /// wide tree behind, and the queries refuse it.
  [[nodiscard]] std::uint64_t binary_revision() const { return binary_revision_; }
  /// The lanes' volumes are stored less this point (the root box's centre): a tree far from its frame's
  /// origin keeps small numbers, and so does the pose between two near trees (Lanes::make_context).
  [[nodiscard]] const Vec3& origin() const { return origin_; }
  [[nodiscard]] std::size_t bytes() const {
    return nodes_.size() * sizeof(Node) + binary_.size() * sizeof(std::uint32_t);
  }

 private:
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> binary_;  ///< per wide node, the binary inner node it stands for (0 at node 0)
  std::uint64_t binary_identity_ = 0;
  std::uint64_t binary_revision_ = 0;
  Vec3 origin_ = Vec3::Zero();
};

using WideAabbTree = WideBvh<Aabb4>;
template <class Set>
using WideDopTree = WideBvh<KDop4<Set>>;

/// The four-lane layout of a binary tree's volume, where it has one: WideLanes<Aabb>::type is Aabb4,
/// WideLanes<KDop<Set>>::type KDop4<Set>, WideLanes<Sphere>::type Sphere4, WideLanes<Obb>::type Obb4,
/// WideLanes<RestrictedBox>::type RestrictedBox4.
/// `HasWideLayout<BV>` says whether a volume has one.
template <class BV>
struct WideLanes {};
template <>
struct WideLanes<Aabb> {
  using type = Aabb4;
};
template <class Set>
struct WideLanes<KDop<Set>> {
  using type = KDop4<Set>;
};
template <>
struct WideLanes<Sphere> {
  using type = Sphere4;
};
template <>
struct WideLanes<Obb> {
  using type = Obb4;
};
template <>
struct WideLanes<RestrictedBox> {
  using type = RestrictedBox4;
};
template <class BV>
concept HasWideLayout = requires {
  typename WideLanes<BV>::type;
};
template <HasWideLayout BV>
using WideTreeOf = WideBvh<typename WideLanes<BV>::type>;

/// Lanes whose four volumes bound their distance to a volume of the other tree: one lane of A's node against
/// B's four children placed by the pose, and A's four children against one lane of B's node
/// (Obb4::distance_bounds_to_b, _to_a). The wide distance walk (traversal/wide_distance.hpp) runs on them.
template <class Lanes>
concept WideDistanceLanes = requires(const Lanes& a, const Lanes& b, int lane,
                                     const typename Lanes::PairContext& c) {
  { Lanes::distance_bounds_to_b(a, lane, b, c) } -> std::same_as<std::array<float, 4>>;
  { Lanes::distance_bounds_to_a(a, b, lane, c) } -> std::same_as<std::array<float, 4>>;
};
/// Whether trees of volume BV have a wide layout that the distance walk runs on.
template <class BV>
concept HasWideDistance = HasWideLayout<BV> && WideDistanceLanes<typename WideLanes<BV>::type>;

}  // namespace bvhlab
