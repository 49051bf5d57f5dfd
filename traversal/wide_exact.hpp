// Exact first-contact (or all-contacts) query on wide trees (bvh/wide_bvh.hpp): depth-first, like
// query_exact on the binary trees, but one step tests a volume of one tree against all four children of a
// node of the other at once (the Lanes' place and overlap_placed), and a first-contact walk takes the
// overlapping children nearest first (Lanes::center_distances). The same answers as query_exact on the
// binary trees the wide ones were built from (the witness may be another intersecting pair): the triangle
// tests are the same, the volume tests conservative.
//
// Counters: bv_tests counts four a step (each lane is a volume test, occupied or not: a node of fewer than
// four children pays for four), nodes_visited the pairs taken off the stack, triangle_tests as usual.
#pragma once

#include "../bvh/wide_bvh.hpp"
#include "exact.hpp"
#include "inline_stack.hpp"

#include <array>
#include <bit>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

namespace wide_detail {

/// A pair on the walk's stack: lane a_lane of A's wide node a_node, lane b_lane of B's b_node, whose volume,
/// placed in A's frame, is lane b_lane of the walk's placed block `placed` (where the walk keeps them).
struct WidePair {
  std::uint32_t a_node, a_lane, b_node, b_lane, placed;
};

/// The leaf pair (child_a, child_b) just taken and the leaf pairs next on the stack, up to four in all, in
/// the order they would be taken (each taken one counts a visited pair): their triangle pairs' plane tests
/// run at once (TreePair::intersecting_triangles4). True when on_hit stopped the walk.
template <class Trees, class Tree, class Stack, class OnHit>
[[gnu::always_inline]] bool test_leaf_pairs(const Trees& trees, const Tree& wide_a, const Tree& wide_b,
                                            std::uint32_t child_a, std::uint32_t child_b, Stack& stack,
                                            const OnHit& on_hit) {
  std::uint32_t leaves_a[4] = {child_a & ~Tree::kLeaf}, leaves_b[4] = {child_b & ~Tree::kLeaf};
  int n = 1;
  for (; n < 4 && !stack.empty(); ++n) {
    const WidePair& next = stack.back();
    const std::uint32_t next_a = wide_a.node(next.a_node).child[next.a_lane];
    const std::uint32_t next_b = wide_b.node(next.b_node).child[next.b_lane];
    if (!(next_a & next_b & Tree::kLeaf)) break;
    leaves_a[n] = next_a & ~Tree::kLeaf;
    leaves_b[n] = next_b & ~Tree::kLeaf;
    stack.pop_back();
  }
  return trees.intersecting_triangles4(leaves_a, leaves_b, n, on_hit,
                                       [&trees](int k) { trees.counters.nodes_visited += k > 0; });
}

/// A's lanes in the form the tests read, made once for both the test and the order of the pairs it leaves:
/// a packing layout's lanes unpacked (RestrictedBox4), any other layout's as stored.
template <class Lanes>
[[gnu::always_inline]] decltype(auto) tested_lanes(const Lanes& lanes) {
  if constexpr (requires { Lanes::unpack(lanes); })
    return Lanes::unpack(lanes);
  else
    return (lanes);
}

/// Pushes the pairs of the lanes `hits` marks (`base` with the lane set on the split side). With
/// `nearest_first`, the one whose centres are nearest is taken first: looking for a first contact, that pair
/// is the likeliest to hold one (the distances are computed only where two lanes or more overlap).
/// Otherwise in the lanes' order. Inlined into the walk's three calls: as one function called from there,
/// the calls and the copies they needed made the OBB walk about a tenth slower (bench/RESULTS.md, "The push
/// inlined").
template <class Lanes, class Stack, class AVolumes, class BPlaced>
[[gnu::always_inline]] inline void push_hits(Stack& stack, unsigned hits, bool nearest_first,
                                             const AVolumes& a_volumes, const BPlaced& b_placed,
                                             const WidePair& base, bool split_b) {
  // A step that hits no lane or one needs no order: no loop, no sort.
  if (hits == 0) return;
  if ((hits & (hits - 1)) == 0) {
    WidePair child = base;
    (split_b ? child.b_lane : child.a_lane) = static_cast<std::uint32_t>(std::countr_zero(hits));
    stack.push_back(child);
    return;
  }
  std::array<float, 4> distance{};
  if (nearest_first) distance = Lanes::center_distances(a_volumes, b_placed);
  std::array<std::uint32_t, 4> order;  // the lanes hit, in the order they are to be taken
  int n = 0;
  for (std::uint32_t k = 0; k < 4; ++k) {
    if (!(hits & (1u << k))) continue;
    int i = n++;
    for (; i > 0 && distance[k] < distance[order[i - 1]]; --i) order[i] = order[i - 1];
    order[i] = k;
  }
  while (n-- > 0) {
    WidePair child = base;
    (split_b ? child.b_lane : child.a_lane) = order[n];
    stack.push_back(child);
  }
}

/// Refuses wide trees that were not built from these binary trees, or before a refit; `who` names the query.
template <class Lanes>
void require_pair(const Bvh<typename Lanes::Volume>& a, const WideBvh<Lanes>& wide_a,
                  const Bvh<typename Lanes::Volume>& b, const WideBvh<Lanes>& wide_b,
                  const char* who = "wide exact query") {
  const auto check = [who](const auto& tree, const auto& wide, const char* side) {
    if (wide.binary_identity() != tree.identity())
      throw std::invalid_argument(std::string(who) + ": wide tree " + side +
                                  " was not built from binary tree " + side);
    if (wide.binary_revision() != tree.volumes_revision())
      throw std::invalid_argument(std::string(who) + ": binary tree " + side +
                                  " was refitted after wide tree " + side + " was built; build it again");
  };
  check(a, wide_a, "A");
  check(b, wide_b, "B");
}

/// A pair taken from a walk's stack or queue, opened: the two nodes, the children their lanes hold, and
/// which of those are leaves. Both wide walks (exact and distance) start each step so.
template <class Tree>
struct OpenedPair {
  const typename Tree::Node& node_a;
  const typename Tree::Node& node_b;
  std::uint32_t child_a, child_b;
  bool leaf_a, leaf_b;

  /// Whether the step splits B's lane: the larger of the two volumes is split, and a leaf cannot be.
  [[nodiscard]] bool splits_b(std::uint32_t a_lane, std::uint32_t b_lane) const {
    return leaf_a || (!leaf_b && node_b.boxes.volume(int(b_lane)) > node_a.boxes.volume(int(a_lane)));
  }
};

template <class Tree, class Pair>
[[gnu::always_inline]] inline OpenedPair<Tree> open_pair(const Tree& wide_a, const Tree& wide_b,
                                                         const Pair& p) {
  const typename Tree::Node& node_a = wide_a.node(p.a_node);
  const typename Tree::Node& node_b = wide_b.node(p.b_node);
  const std::uint32_t child_a = node_a.child[p.a_lane], child_b = node_b.child[p.b_lane];
  return {node_a, node_b, child_a, child_b, (child_a & Tree::kLeaf) != 0, (child_b & Tree::kLeaf) != 0};
}

}  // namespace wide_detail

/// Exact query on the wide trees of two binary trees (same contract as query_exact; throws
/// std::invalid_argument for a non-rigid pose or wide trees of other binary trees). Const and thread-safe on
/// shared trees.
template <class Lanes>
Result query_exact_wide(const Bvh<typename Lanes::Volume>& a, const WideBvh<Lanes>& wide_a,
                        const Bvh<typename Lanes::Volume>& b, const WideBvh<Lanes>& wide_b,
                        const RigidTransform& b_to_a, ContactMode mode = ContactMode::First) {
  using BV = typename Lanes::Volume;
  using Tree = WideBvh<Lanes>;
  check_exact_query<TriangleLeaves>(b_to_a, mode);
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  wide_detail::require_pair(a, wide_a, b, wide_b);
  TriangleLeaves::require(a, b, "wide exact query");
  // The binary trees' leaf test (TreePair::intersecting_triangles) reads no volume context: an empty one
  // stands in for it, so the walk does not pay for a context it never reads (a k-DOP's re-alignment costs
  // about 5,100 instructions).
  const typename VolumeWalker<BV>::Context unused_context{};
  const TreePair<BV> trees(a, b, b_to_a, unused_context, result.counters);
  const typename Lanes::PairContext lanes = Lanes::make_context(b_to_a, wide_a.origin(), wide_b.origin());
  Counters& counters = result.counters;

  // Where placing costs more than keeping the result (Lanes::kKeepsPlaced: the k-DOPs' twelve or so
  // supports a lane), B's volumes are placed in A's frame once, four at a time, when their node is split,
  // and a pair keeps the block its B volume sits in: splitting A then compares against it without placing
  // it again. A box is cheaper to place again than to keep (bench/RESULTS.md, "Wide trees").
  constexpr bool keep = Lanes::kKeepsPlaced;
  // Boxes and spheres meet many leaf pairs that their triangles' planes part: those layouts test up to four
  // at once (Lanes::kBatchesLeafPairs). Around oriented boxes and k-DOPs leaf pairs are few and close, and
  // the batch cost more than it saved (bench/RESULTS.md, "Four triangle pairs at once").
  constexpr bool batches_leaf_pairs = requires {
    requires Lanes::kBatchesLeafPairs;
  };
  // Placed blocks are large (256 bytes for oriented boxes, 400 for the 24-DOP) and kept by few layouts: on
  // the heap. The stack of 20-byte pairs stays in the walk's own frame (traversal/inline_stack.hpp).
  std::vector<typename Lanes::Placed> placed;
  if constexpr (keep) placed.reserve(32);
  InlineStack<wide_detail::WidePair, 64> stack;
  // First contacts take the pair whose centres are nearest first (push_hits); all contacts need every pair,
  // so that walk keeps the lanes' order (the binary walk's).
  const bool nearest_first = mode == ContactMode::First;
  // The roots, as any pair (B's root placed in block 0 where the walk keeps blocks).
  counters.bv_tests += 1;
  const typename Lanes::Placed root_b = Lanes::place(wide_b.node(0).boxes, lanes);
  if constexpr (keep) placed.push_back(root_b);
  const auto& root_a = wide_detail::tested_lanes(wide_a.node(0).boxes);
  wide_detail::push_hits<Lanes>(stack, Lanes::overlap_placed(root_a, root_b, lanes) & 1u, nearest_first,
                                root_a, root_b, {0, 0, 0, 0, 0}, false);
  while (!stack.empty()) {
    const wide_detail::WidePair p = stack.back();
    stack.pop_back();
    ++counters.nodes_visited;
    const wide_detail::OpenedPair<Tree> q = wide_detail::open_pair(wide_a, wide_b, p);
    if (q.leaf_a && q.leaf_b) {
      const auto on_hit = [&](const TrianglePair& hit) {
        result.collides = true;
        result.probability = 1;
        if (!result.witness) result.witness = hit;
        if (mode == ContactMode::First) return true;
        result.contacts.push_back(hit);
        return false;
      };
      bool done = false;
      if constexpr (batches_leaf_pairs)
        done = test_leaf_pairs(trees, wide_a, wide_b, q.child_a, q.child_b, stack, on_hit);
      else
        done = trees.intersecting_triangles(q.child_a & ~Tree::kLeaf, q.child_b & ~Tree::kLeaf, on_hit);
      if (done) return result;
      continue;
    }
    // Split the larger of the two (a leaf cannot be split): its four children against the other's volume.
    counters.bv_tests += 4;
    if (q.splits_b(p.a_lane, p.b_lane)) {
      const typename Lanes::Placed children = Lanes::place(wide_b.node(q.child_b).boxes, lanes);
      // A's volume unpacked, where a layout packs its lanes.
      const auto a_volume = Lanes::broadcast(q.node_a.boxes, int(p.a_lane));
      const unsigned hits = Lanes::overlap_placed(a_volume, children, lanes);
      const auto block = static_cast<std::uint32_t>(placed.size());
      if constexpr (keep) placed.push_back(children);
      wide_detail::push_hits<Lanes>(stack, hits, nearest_first, a_volume, children,
                                    {p.a_node, p.a_lane, q.child_b, 0, block}, true);
    } else {
      const auto placed_b = [&] {
        if constexpr (keep)
          return Lanes::broadcast_placed(placed[p.placed], int(p.b_lane));
        else
          return Lanes::place(Lanes::broadcast(q.node_b.boxes, int(p.b_lane)), lanes);
      };
      const typename Lanes::Placed b_volume = placed_b();
      const auto& a_children = wide_detail::tested_lanes(wide_a.node(q.child_a).boxes);
      const unsigned hits = Lanes::overlap_placed(a_children, b_volume, lanes);
      wide_detail::push_hits<Lanes>(stack, hits, nearest_first, a_children, b_volume,
                                    {q.child_a, 0, p.b_node, p.b_lane, p.placed}, false);
    }
  }
  return result;
}

}  // namespace bvhlab
