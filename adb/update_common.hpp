// What the density-update policies (adb/update.hpp) share: checks that a state belongs to the tree it is
// applied to, and the exact recount of a chosen set of nodes with the annotation's own clipping.
#pragma once

#include "adb_density.hpp"

#include <chrono>
#include <cstdint>
#include <span>
#include <string_view>
#include <utility>

namespace bvhlab::density_update {

using NodeRanges = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

/// Throws std::invalid_argument naming `policy` unless the tree has `state_nodes` nodes and the storage one
/// count per node: a state is valid only for the tree (and its refits) it was started on.
void check_tree(std::string_view policy, std::size_t state_nodes, std::size_t tree_nodes,
                std::size_t storage_counts);

/// Counts the nodes `selected` anew, exactly as the annotation does (adb/annotate.hpp), into
/// storage.possible_collision_cells; the other nodes keep their counts. Returns the recount's statistics.
/// `frames`: when not empty, the nodes' own frames, where the default density counts an OBB's cells
/// (annotate_counts_in_frames); `boxes` then only size the recount.
AnnotateStats recount(std::span<const Box> boxes, const NodeRanges& ranges,
                      std::span<const TrianglePoints> triangles, std::span<const std::uint32_t> selected,
                      AdbStorage& storage, const AnnotationContext& context,
                      std::span<const OrientedBox> frames = {});

/// The nodes' own frames when "adb" counts BV's cells there (adb/pair_geometry.hpp), else none.
template <TreeVolume BV>
std::vector<OrientedBox> count_frames(const Bvh<BV>& bvh) {
  if constexpr (estimates_in_node_frames<AdbDensity, BV>)
    return node_frames(bvh);
  else
    return {};
}

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The part of a policy without parameters whose state is only the tree it belongs to (CRTP: Policy
/// provides name() and update()).
template <class Policy>
struct StatelessPolicy {
  struct Params {
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct State {
    std::size_t nodes = 0;
  };

  static std::span<const ParamSpec> parameters() { return {}; }
  static Params make_params(const ParamValues&) { return {}; }

  template <TreeVolume BV>
  static State start(const Bvh<BV>& bvh, const AdbStorage& rest, const Params&) {
    check_tree(Policy::name(), bvh.nodes().size(), bvh.nodes().size(), rest.possible_collision_cells.size());
    return {bvh.nodes().size()};
  }
};

}  // namespace bvhlab::density_update
