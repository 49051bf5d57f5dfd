// Tree<BV, Density>: a hierarchy plus an optional per-node density annotation stored beside the nodes.
// A tree without density pays nothing: NoDensity's storage is an empty member.
#pragma once

#include "bvh/bvh.hpp"

#include <cstdint>
#include <type_traits>
#include <vector>

namespace bvhlab {

/// No annotation: no preprocessing, zero bytes per node.
struct NoDensity {
  static constexpr bool annotated = false;
  struct Storage {};
};
static_assert(std::is_empty_v<NoDensity::Storage>);

/// ADB annotation: per node, pc = the number of the node's g^3 grid cells (laid on the node's bounding box)
/// that hold at least `tau` times the cell's mean face area of polygon area (adb/README.md, section 1).
template <int G>
struct AdbDensity {
  static_assert(G >= 2 && G <= 6, "grid must be 2..6 cells per axis (pc fits a byte)");
  static constexpr bool annotated = true;
  static constexpr int grid = G;
  static constexpr int cells = G * G * G;
  struct Storage {
    std::vector<std::uint8_t> possible_collision_cells;  ///< pc(V) per node, same index as the nodes
    double tau = 0;                                      ///< the threshold it was computed with
  };
};

template <class D>
concept DensityPolicy = requires {
  { D::annotated } -> std::convertible_to<bool>;
  typename D::Storage;
};

template <TreeVolume BV, DensityPolicy Density = NoDensity>
struct Tree {
  using Volume = BV;
  using DensityType = Density;
  Bvh<BV> bvh;
  [[no_unique_address]] typename Density::Storage density;
};

/// True when Tree<BV, NoDensity> is exactly as large as the bare Bvh<BV> (checked per BV where used).
template <TreeVolume BV>
inline constexpr bool no_density_is_free = sizeof(Tree<BV, NoDensity>) == sizeof(Bvh<BV>);

}  // namespace bvhlab
