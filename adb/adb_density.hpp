// AdbDensity: the ADB annotation as a density policy (adb/concept.hpp). Per node V, pc(V), the number of
// V's g x g x g grid cells holding at least tau times a cell's mean face area of polygon area
// (adb/README.md, section 1; the counting is adb/annotate.hpp). Its query-time model, the probability table
// for (g, tau), is derived from the stored parameters, so a tree and its model cannot disagree.
#pragma once

#include "annotate.hpp"
#include "model.hpp"
#include "pair_geometry.hpp"
#include "tree.hpp"

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// What every ADB density stores: the parameters and pc(V) per node. The variants differ only in the
/// estimate they read from it (AdbRule, adb/model.hpp), so their saved bytes have one layout.
struct AdbParams {
  int grid = 2;                 ///< cells per axis
  double tau = kDefaultAdbTau;  ///< area threshold, fraction of the cell's mean face area
  friend bool operator==(const AdbParams&, const AdbParams&) = default;
};
struct AdbStorage {
  AdbParams params;
  std::vector<std::uint8_t> possible_collision_cells;  ///< pc(V) per node, same index as the nodes
  std::shared_ptr<const AdbModel> model;               ///< derived from params; shared per (g, tau)
};

/// The work shared by the ADB densities; `name` is the density's, for messages and descriptions.
namespace adb_storage {
std::span<const ParamSpec> parameters();
AdbParams make_params(const ParamValues& values, std::string_view name);
AdbStorage make(const AdbParams& params, std::vector<std::uint8_t> counts, std::string_view name);
std::string describe(const AdbParams& params, std::string_view name);
std::vector<std::byte> encode(const AdbStorage& storage);
AdbStorage decode(std::span<const std::byte> bytes, std::size_t node_count, std::string_view name);
/// Throws std::invalid_argument when the two trees were annotated with other parameters, or not at all.
void check_combinable(const AdbStorage& a, const AdbStorage& b, std::string_view name);
}  // namespace adb_storage

/// Every node's own box (FramedVolume::oriented_box), by node index: the grids "adb" counts its cells on in
/// trees of such a volume (estimates_in_node_frames).
template <TreeVolume BV>
requires FramedVolume<BV> std::vector<OrientedBox> node_frames(const Bvh<BV>& bvh) {
  std::vector<OrientedBox> frames(bvh.nodes().size());
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i] = bvh.volume(i).oriented_box();
  return frames;
}

/// An ADB density: the cell counts, read through `Variant::rule`. `Variant` names it: a struct with
/// `static constexpr std::string_view name`, `static constexpr AdbRule rule` and
/// `static constexpr bool cells_in_node_frames`.
template <class Variant>
struct BasicAdbDensity {
  using Params = AdbParams;
  using Storage = AdbStorage;
  static constexpr AdbRule rule = Variant::rule;
  /// Cells in the node's own frame on volumes that have one (adb/pair_geometry.hpp), else on its bounding
  /// box.
  static constexpr bool cells_in_node_frames = Variant::cells_in_node_frames;

  static constexpr std::string_view name() { return Variant::name; }
  /// Version 2: the counts of a FramedVolume's nodes lie in the nodes' frames (version 1 had them on the
  /// bounding boxes, so those files are refused, not misread).
  static constexpr std::uint32_t version() { return cells_in_node_frames ? 2 : 1; }
  static std::span<const ParamSpec> parameters() { return adb_storage::parameters(); }
  /// Throws std::invalid_argument for a tau without an LB value.
  static Params make_params(const ParamValues& values) { return adb_storage::make_params(values, name()); }

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
    CellCounts result = count_cells(bvh, params.grid, options);
    if (stats) *stats = result.stats;
    return make_storage(params, std::move(result.counts));
  }

  /// The counts on the nodes' own frames where the density and the volume have them, else on the boxes.
  template <TreeVolume BV>
  static CellCounts count_cells(const Bvh<BV>& bvh, int grid, const AnnotateOptions& options) {
    if constexpr (estimates_in_node_frames<BasicAdbDensity, BV>) {
      return annotate_counts_in_frames(node_frames(bvh), node_triangle_ranges(bvh.nodes()), bvh.triangles(),
                                       grid, options);
    } else {
      return annotate_counts(bvh.node_boxes(), node_triangle_ranges(bvh.nodes()), bvh.triangles(), grid,
                             options);
    }
  }

  /// A storage from counts computed elsewhere (tests, decoding). Throws std::invalid_argument for a count
  /// above g^3 or bad parameters.
  static Storage make_storage(const Params& params, std::vector<std::uint8_t> counts) {
    return adb_storage::make(params, std::move(counts), name());
  }

  static std::string describe(const Storage& storage) { return describe(storage.params); }
  static std::string describe(const Params& params) { return adb_storage::describe(params, name()); }
  static std::vector<std::byte> encode(const Storage& storage) { return adb_storage::encode(storage); }
  static Storage decode(std::span<const std::byte> bytes, std::size_t node_count) {
    return adb_storage::decode(bytes, node_count, name());
  }
  static std::size_t memory_bytes(const Storage& storage) { return storage.possible_collision_cells.size(); }

  /// e(i, box_a, j, box_b, overlap): the estimate for node i of A against node j of B.
  struct Estimator {
    const AdbModel* model;
    const std::uint8_t* pc_a;
    const std::uint8_t* pc_b;
    double operator()(std::uint32_t i, const Box& box_a, std::uint32_t j, const Box& box_b,
                      double overlap) const {
      return model->estimate<rule>(box_a, box_b, overlap, pc_a[i], pc_b[j]);
    }
  };
  /// Throws std::invalid_argument when the two trees were annotated with other parameters, or not at all.
  static Estimator estimator(const Storage& a, const Storage& b) {
    adb_storage::check_combinable(a, b, name());
    return {a.model.get(), a.possible_collision_cells.data(), b.possible_collision_cells.data()};
  }
};

/// The default ADB density: finer cells for differently sized nodes, no count read as 0 (adb/model.hpp), and
/// cells in an OBB's own frame (adb/pair_geometry.hpp).
struct SizedAdbVariant {
  static constexpr std::string_view name = "adb";
  static constexpr AdbRule rule = kAdbSizedRule;
  static constexpr bool cells_in_node_frames = true;
};
using AdbDensity = BasicAdbDensity<SizedAdbVariant>;
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
