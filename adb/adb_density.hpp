// AdbDensity: the ADB annotation as a density policy (adb/concept.hpp). Per node V, pc(V), the number of
// V's g x g x g grid cells holding at least tau times a cell's mean face area of polygon area
// (adb/README.md, section 1; the counting is adb/annotate.hpp). Its query-time model, the probability table
// for (g, tau), is derived from the stored parameters, so a tree and its model cannot disagree.
#pragma once

#include "annotate.hpp"
#include "model.hpp"
#include "tree.hpp"

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

struct AdbDensity {
  struct Params {
    int grid = 2;                 ///< cells per axis
    double tau = kDefaultAdbTau;  ///< area threshold, fraction of the cell's mean face area
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct Storage {
    Params params;
    std::vector<std::uint8_t> possible_collision_cells;  ///< pc(V) per node, same index as the nodes
    std::shared_ptr<const AdbModel> model;               ///< derived from params; shared per (g, tau)
  };

  static constexpr std::string_view name() { return "adb"; }
  static constexpr std::uint32_t version() { return 1; }
  static std::span<const ParamSpec> parameters();
  /// Throws std::invalid_argument for a tau without an LB value.
  static Params make_params(const ParamValues& values);

  template <TreeVolume BV>
  static Storage annotate(const Bvh<BV>& bvh, const Params& params, const AnnotationContext& context,
                          AnnotateStats* stats) {
    if (!bvh.has_polygons())
      throw std::invalid_argument(
          "annotate: the tree holds no polygons (a tree loaded without them cannot be annotated)");
    AnnotateOptions options;
    options.tau = params.tau;
    options.threads = context.threads;
    options.progress = context.progress;
    CellCounts result = annotate_counts(bvh.node_boxes(), node_triangle_ranges(bvh.nodes()), bvh.triangles(),
                                        params.grid, options);
    if (stats) *stats = result.stats;
    return make_storage(params, std::move(result.counts));
  }

  /// A storage from counts computed elsewhere (tests, decoding). Throws std::invalid_argument for a count
  /// above g^3 or bad parameters.
  static Storage make_storage(const Params& params, std::vector<std::uint8_t> counts);

  static std::string describe(const Storage& storage);
  static std::string describe(const Params& params);
  static std::vector<std::byte> encode(const Storage& storage);
  static Storage decode(std::span<const std::byte> bytes, std::size_t node_count);
  static std::size_t memory_bytes(const Storage& storage) { return storage.possible_collision_cells.size(); }

  /// e(i, box_a, j, box_b, overlap): the estimate for node i of A against node j of B.
  struct Estimator {
    const AdbModel* model;
    const std::uint8_t* pc_a;
    const std::uint8_t* pc_b;
    double operator()(std::uint32_t i, const Box& box_a, std::uint32_t j, const Box& box_b,
                      double overlap) const {
      return model->estimate(box_a, box_b, overlap, pc_a[i], pc_b[j]);
    }
  };
  /// Throws std::invalid_argument when the two trees were annotated with other parameters, or not at all.
  static Estimator estimator(const Storage& a, const Storage& b);
};
static_assert(ProbabilityDensity<AdbDensity>);

/// Shorthand for tests and tools: the ADB-annotated tree of `bvh`.
template <TreeVolume BV>
Tree<BV, AdbDensity> annotate_adb(Bvh<BV> bvh, int grid = 2, double tau = kDefaultAdbTau,
                                  const AnnotationContext& context = {}, AnnotateStats* stats = nullptr) {
  return annotate_tree<AdbDensity>(std::move(bvh), density_params<AdbDensity>({{"grid", grid}, {"tau", tau}}),
                                   context, stats);
}

/// The same with the annotation run's options (threshold, threads, progress) in one struct.
template <TreeVolume BV>
Tree<BV, AdbDensity> annotate_adb(Bvh<BV> bvh, int grid, const AnnotateOptions& options,
                                  AnnotateStats* stats = nullptr) {
  return annotate_adb(std::move(bvh), grid, options.tau, AnnotationContext{options.threads, options.progress},
                      stats);
}

}  // namespace bvhlab
