// Density update "recount_all": every node counted anew by the annotation's exact clipping. The same counts
// as annotating the refitted tree from scratch, at the same cost: the baseline of adb/update.hpp.
#pragma once

#include "update_common.hpp"

namespace bvhlab {

struct RecountAllUpdate : density_update::StatelessPolicy<RecountAllUpdate> {
  static constexpr std::string_view name() { return "recount_all"; }

  template <TreeVolume BV>
  static void update(const Bvh<BV>& bvh, AdbStorage& storage, State& state, const AnnotationContext& context,
                     DensityUpdateStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    density_update::check_tree(name(), state.nodes, bvh.nodes().size(),
                               storage.possible_collision_cells.size());
    if (!bvh.has_polygons())
      throw std::invalid_argument("density update 'recount_all': the tree holds no polygons");
    AnnotateOptions options;
    options.tau = storage.params.tau;
    options.threads = context.threads;
    options.progress = context.progress;
    CellCounts result = AdbDensity::count_cells(bvh, storage.params.grid, options);  // as annotating anew
    storage.possible_collision_cells = std::move(result.counts);
    if (stats)
      *stats = DensityUpdateStats{.seconds = density_update::seconds_since(start),
                                  .nodes = state.nodes,
                                  .recounted_nodes = state.nodes,
                                  .annotate = result.stats};
  }
};

}  // namespace bvhlab
