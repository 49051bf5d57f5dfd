// Density update "samples": fixed area-weighted surface samples, drawn once on the rest shape and moved with
// their triangles, binned into every node's grid instead of clipping.
//
// - Drawing: about `per_triangle` samples per triangle on average, spread over the triangles in proportion
//   to their rest area (systematic sampling along the cumulative area, one random offset: a triangle of k
//   mean areas gets k * per_triangle samples, up to rounding), each at uniformly random barycentric
//   coordinates. A triangle may get no sample; its area is then unseen.
// - Per update: a sample's position follows its triangle (same barycentric coordinates), and it carries its
//   triangle's current area divided by the triangle's sample count, so the samples of a triangle add up to
//   its area. Per node, each sample adds its area to the cell of the node's grid it lies in (all g layers
//   along an axis where the box is flat, as the exact annotation counts a flat node); a cell counts when its
//   area A > 0 and A >= tau * F, F its mean face area (the definition of adb/annotate.hpp).
// - `from_rest` = 1 (default): the count is the rest shape's exact count plus the change the samples see,
//   pc = exact_rest + sampled_now - sampled_rest, clamped to [0, g^3]. The samples' own error, mostly the
//   same in both shapes, then cancels for moderate deformation, and an unmoved node keeps its exact count.
//   `from_rest` = 0: pc = sampled_now.
// Cost per update: O(samples x depth), no clipping.
#pragma once

#include "update_common.hpp"

#include <array>
#include <vector>

namespace bvhlab {

struct SampledUpdate {
  struct Params {
    double per_triangle = 4;
    std::uint32_t seed = 1;
    bool from_rest = true;
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct State {
    Params params;
    std::vector<std::uint32_t> first_sample;         ///< per triangle (tree order) + 1: its samples' range
    std::vector<std::array<double, 2>> barycentric;  ///< per sample, weights of vertices 1 and 2
    std::vector<std::uint8_t> rest_exact;            ///< the rest shape's exact counts
    std::vector<std::uint8_t> rest_sampled;          ///< the rest shape's counts from the samples
    density_update::NodeRanges ranges;
  };

  static constexpr std::string_view name() { return "samples"; }
  static std::span<const ParamSpec> parameters();
  static Params make_params(const ParamValues& values);

  template <TreeVolume BV>
  static State start(const Bvh<BV>& bvh, const AdbStorage& rest, const Params& params) {
    density_update::check_tree(name(), bvh.nodes().size(), bvh.nodes().size(),
                               rest.possible_collision_cells.size());
    if (!bvh.has_polygons())
      throw std::invalid_argument("density update 'samples': the tree holds no polygons");
    if constexpr (estimates_in_node_frames<AdbDensity, BV>)
      throw std::invalid_argument("density update 'samples': on " + std::string(BV::name()) +
                                  " trees the counts lie in each node's own frame, which the samples are not "
                                  "binned in; use recount_all or recount_moved");
    State state = draw(bvh.triangles(), params);
    state.ranges = node_triangle_ranges(bvh.nodes());
    state.rest_exact = rest.possible_collision_cells;
    state.rest_sampled = sampled_counts(state, bvh.node_boxes(), bvh.triangles(), rest.params, 1);
    return state;
  }

  template <TreeVolume BV>
  static void update(const Bvh<BV>& bvh, AdbStorage& storage, State& state, const AnnotationContext& context,
                     DensityUpdateStats* stats) {
    const auto start = std::chrono::steady_clock::now();
    density_update::check_tree(name(), state.ranges.size(), bvh.nodes().size(),
                               storage.possible_collision_cells.size());
    if (bvh.triangles().size() + 1 != state.first_sample.size())
      throw std::invalid_argument(
          "density update 'samples': the tree holds " + std::to_string(bvh.triangles().size()) +
          " triangles, the samples were drawn on " + std::to_string(state.first_sample.size() - 1));
    std::vector<std::uint8_t> now =
        sampled_counts(state, bvh.node_boxes(), bvh.triangles(), storage.params, context.threads);
    storage.possible_collision_cells = combine(state, std::move(now), storage.params.grid);
    if (stats)
      *stats = DensityUpdateStats{.seconds = density_update::seconds_since(start),
                                  .nodes = state.ranges.size(),
                                  .samples = state.barycentric.size(),
                                  .annotate = {}};
  }

  /// The samples of `params` on `triangles` (tree order); ranges and counts left empty.
  static State draw(std::span<const TrianglePoints> triangles, const Params& params);
  /// pc per node from the samples at the triangles' current positions. threads: 0 = hardware concurrency.
  static std::vector<std::uint8_t> sampled_counts(const State& state, std::span<const Box> boxes,
                                                  std::span<const TrianglePoints> triangles,
                                                  const AdbParams& adb, unsigned threads);
  /// The stored counts from the sampled ones (from_rest: relative to the rest shape).
  static std::vector<std::uint8_t> combine(const State& state, std::vector<std::uint8_t> sampled, int grid);
};

}  // namespace bvhlab
