// Density update "stale": the counts of the rest shape are kept as they are. No cost; the lower bound of
// effort that the other policies (adb/update.hpp) are measured against.
#pragma once

#include "update_common.hpp"

namespace bvhlab {

struct StaleUpdate : density_update::StatelessPolicy<StaleUpdate> {
  static constexpr std::string_view name() { return "stale"; }

  template <TreeVolume BV>
  static void update(const Bvh<BV>& bvh, AdbStorage& storage, State& state, const AnnotationContext&,
                     DensityUpdateStats* stats) {
    density_update::check_tree(name(), state.nodes, bvh.nodes().size(),
                               storage.possible_collision_cells.size());
    if (stats) *stats = DensityUpdateStats{.nodes = state.nodes, .annotate = {}};
  }
};

}  // namespace bvhlab
