// Strategies accept a bare Bvh<BV> or any annotated tree exposing `.bvh`.
#pragma once

#include "bvh/bvh.hpp"

namespace bvhlab {

template <BoundingVolume BV>
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

}  // namespace bvhlab
