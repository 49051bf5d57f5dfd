// Binding a CoherentState (traversal/coherent_state.hpp) to the two trees it serves: what every coherent
// query (exact, ADB, distance) does first. Apart from coherent.hpp so that the coherent ADB and distance
// queries do not include the exact walk, and a change to it does not recompile them.
#pragma once

#include "../bvh/bvh.hpp"
#include "coherent_state.hpp"

namespace bvhlab::coherent_detail {

/// What a state is bound to of `tree`: its address, identity and node count.
template <TreeVolume BV>
CoherentState::TreeKey key_of(const Bvh<BV>& tree) {
  return {&tree, tree.identity(), tree.nodes().size()};
}

/// Binds a new state to its trees (and B's root box: what a pose jump is measured against, in B's frame);
/// throws std::invalid_argument for a state bound to other trees.
template <TreeVolume BV>
void attach(CoherentState& state, const Bvh<BV>& a, const Bvh<BV>& b) {
  if (!state.bound() && !b.empty()) {
    const Box box = b.root_volume().bounding_box();
    state.bind(key_of(a), key_of(b), box.center(), box.extent().norm() / 2);
  }
  state.check_trees(key_of(a), key_of(b));
}

}  // namespace bvhlab::coherent_detail
