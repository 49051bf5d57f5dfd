// Density update "stale": the counts of the rest shape are kept as they are. No cost; the lower bound of
// effort that the other policies (adb/update.hpp) are measured against.
#pragma once

#include "update_common.hpp"

namespace bvhlab {

struct StaleUpdate {
  struct Params {
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct State {
    std::size_t nodes = 0;
  };

  static constexpr std::string_view name() { return "stale"; }
  static std::span<const ParamSpec> parameters() { return {}; }
  static Params make_params(const ParamValues&) { return {}; }

  template <TreeVolume BV>
  static State start(const Bvh<BV>& bvh, const AdbStorage& rest, const Params&) {
    density_update::check_tree(name(), bvh.nodes().size(), bvh.nodes().size(),
                               rest.possible_collision_cells.size());
    return {bvh.nodes().size()};
  }

  template <TreeVolume BV>
  static void update(const Bvh<BV>& bvh, AdbStorage& storage, State& state, const AnnotationContext&,
                     DensityUpdateStats* stats) {
    density_update::check_tree(name(), state.nodes, bvh.nodes().size(),
                               storage.possible_collision_cells.size());
    if (stats) *stats = DensityUpdateStats{.nodes = state.nodes, .annotate = {}};
  }
};

}  // namespace bvhlab
