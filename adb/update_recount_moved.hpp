// Density update "recount_moved": exact recount (the annotation's own clipping) of the nodes whose bounding
// box moved by more than `fraction` of one of the node's cells since that node was last counted; the other
// nodes keep their counts.
//
// Per axis a, with c_a = (hi_a - lo_a) / g the cell side of the box at the node's last count, a node is
// recounted when a corner coordinate moved by more than fraction * c_a. With `ignore_translation`, the box's
// motion as a whole does not count: only how far its corners moved relative to its centre (half the change
// of its extent), since a count depends only on the triangles relative to their box. fraction = 0 recounts
// every node, the exact recount: a node's triangles can move inside a box that stays put. Blind spot, for
// fraction > 0: such a node is never recounted while its box stays within the limits.
#pragma once

#include "update_common.hpp"

#include <vector>

namespace bvhlab {

struct RecountMovedUpdate {
  struct Params {
    double fraction = 0.25;
    bool ignore_translation = false;
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct State {
    Params params;
    std::vector<Box> counted;  ///< per node, its box when it was last counted
    density_update::NodeRanges ranges;
  };

  static constexpr std::string_view name() { return "recount_moved"; }
  static std::span<const ParamSpec> parameters();
  static Params make_params(const ParamValues& values);

  template <TreeVolume BV>
  static State start(const Bvh<BV>& bvh, const AdbStorage& rest, const Params& params) {
    density_update::check_tree(name(), bvh.nodes().size(), bvh.nodes().size(),
                               rest.possible_collision_cells.size());
    return {params, bvh.node_boxes(), node_triangle_ranges(bvh.nodes())};
  }

  template <TreeVolume BV>
  static void update(const Bvh<BV>& bvh, AdbStorage& storage, State& state, const AnnotationContext& context,
                     DensityUpdateStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    density_update::check_tree(name(), state.counted.size(), bvh.nodes().size(),
                               storage.possible_collision_cells.size());
    if (!bvh.has_polygons())
      throw std::invalid_argument("density update 'recount_moved': the tree holds no polygons");
    const std::vector<Box> boxes = bvh.node_boxes();
    const std::vector<std::uint32_t> selected = moved_nodes(state, boxes, storage.params.grid);
    const AnnotateStats counted = density_update::recount(
        boxes, state.ranges, bvh.triangles(), selected, storage, context, density_update::count_frames(bvh));
    for (const std::uint32_t node : selected) state.counted[node] = boxes[node];
    if (stats)
      *stats = DensityUpdateStats{.seconds = density_update::seconds_since(start),
                                  .nodes = boxes.size(),
                                  .recounted_nodes = selected.size(),
                                  .annotate = counted};
  }

  /// The nodes holding triangles whose box moved past the limit since their last count (ascending).
  static std::vector<std::uint32_t> moved_nodes(const State& state, std::span<const Box> boxes, int grid);
};

}  // namespace bvhlab
