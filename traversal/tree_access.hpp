// How strategies reach trees and their volumes, whatever the BV model.
//   bvh_of(tree)      a bare Bvh<BV>, or any annotated tree exposing `.bvh`;
//   VolumeWalker<BV>  the per-side traversal state of a node and the overlap test on it. Self-contained
//                     volumes carry no state (the node index is enough); hierarchical ones (restricted
//                     boxtree) carry their decoded volume down the tree. Both compile to the direct code.
#pragma once

#include "../bvh/bvh.hpp"

#include <type_traits>

namespace bvhlab {

template <TreeVolume BV>
const Bvh<BV>& bvh_of(const Bvh<BV>& tree) {
  return tree;
}
template <class Tree>
requires requires(const Tree& t) {
  t.bvh;
}
const auto& bvh_of(const Tree& tree) {
  return tree.bvh;
}

template <TreeVolume BV>
struct VolumeWalker;

/// Whether a node index alone gives a node's volume and box: the walker carries no state down the tree
/// (every volume but the hierarchical ones). Only then may a walk start below the root pair (a remembered
/// pair) or reach a node without its ancestors (a wide tree's lane).
template <class BV>
concept StatelessWalk = std::is_empty_v<typename VolumeWalker<BV>::Working>;

template <BoundingVolume BV>
struct VolumeWalker<BV> {
  struct Working {};
  using Context = typename BV::PairContext;

  static Context make_context(const RigidTransform& b_to_a) { return BV::make_context(b_to_a); }
  static Working root_a(const Bvh<BV>&, const Context&) { return {}; }
  static Working root_b(const Bvh<BV>&, const Context&) { return {}; }
  static Working child_a(const Bvh<BV>&, const Working&, std::uint32_t, const Context&) { return {}; }
  static Working child_b(const Bvh<BV>&, const Working&, std::uint32_t, const Context&) { return {}; }
  // always_inline: the walker adds nothing to the volume's test, so the traversal calls BV::overlap
  // directly; whether that test is inlined is the volume's own choice (see Obb::overlap).
  [[gnu::always_inline]] static bool overlap(const Bvh<BV>& a, std::uint32_t i, const Working&,
                                             const Bvh<BV>& b, std::uint32_t j, const Working&,
                                             const Context& c) {
    return BV::overlap(a.tested_volume(i), b.tested_volume(j), c);
  }
  static Box box(const Bvh<BV>& tree, std::uint32_t i, const Working&) {
    return tree.volume(i).bounding_box();
  }
};

template <HierarchicalVolume BV>
struct VolumeWalker<BV> {
  using Working = typename BV::Working;
  struct Context {
    typename BV::Frame a;  // identity: A's frame is the test frame
    typename BV::Frame b;  // B's frame into A's
  };

  static Context make_context(const RigidTransform& b_to_a) {
    return {BV::make_frame(RigidTransform::identity()), BV::make_frame(b_to_a)};
  }
  static Working root_a(const Bvh<BV>& t, const Context& c) { return BV::start(t.root_volume(), c.a); }
  static Working root_b(const Bvh<BV>& t, const Context& c) { return BV::start(t.root_volume(), c.b); }
  static Working child_a(const Bvh<BV>& t, const Working& parent, std::uint32_t child, const Context& c) {
    return BV::descend(parent, t.volume(child), c.a);
  }
  static Working child_b(const Bvh<BV>& t, const Working& parent, std::uint32_t child, const Context& c) {
    return BV::descend(parent, t.volume(child), c.b);
  }
  static bool overlap(const Bvh<BV>&, std::uint32_t, const Working& wa, const Bvh<BV>&, std::uint32_t,
                      const Working& wb, const Context&) {
    return BV::overlap(wa, wb);
  }
  static Box box(const Bvh<BV>&, std::uint32_t, const Working& w) { return BV::decoded(w).bounding_box(); }
};

}  // namespace bvhlab
