// The Density concept: what a density-annotation policy must provide to plug into trees, saved trees, the
// traversal strategies and the bench. The bounding-volume counterpart is volumes/concept.hpp.
//
// Concept `Density<D>` (in the manner of a CGAL concept page)
// ------------------------------------------------------------
// A density annotates a built tree with per-node data that a strategy may read at query time instead of
// the polygons (the ADB cell counts), or with nothing at all (NoDensity). It is stored beside the nodes in
// `Tree<BV, D>::density`, so a tree without density pays nothing.
//
// Types
//   D::Params    Run-time parameters (grid and tau for ADB; empty for none). Equality-comparable.
//   D::Storage   The annotation of one tree: per-node data plus the Params it was made with. Copyable;
//                every query-time model is derived from it (never passed beside it), so a tree's
//                parameters and its model cannot disagree.
//
// Operations (storage: const D::Storage&; params: const D::Params&; values: const ParamValues&)
//   D::name()                       Stable identifier of 1 to 15 characters ("none", "adb"), stored in
//                                   saved trees and used by scenes, the CLI and reports.
//   D::version()                    std::uint32_t: the layout version of D's saved bytes. A saved tree
//                                   whose version differs is refused by name.
//   D::parameters()                 std::span<const ParamSpec>: the parameters D takes (adb/parameters.hpp).
//   D::make_params(values)          Params from resolved values (resolve_parameters fills defaults and
//                                   checks ranges); throws std::invalid_argument for a bad combination.
//   D::annotate(bvh, params, context, stats)
//                                   The Storage for a built Bvh<BV> that still holds its polygons, for any
//                                   TreeVolume BV (checked per BV by `DensityFor<D, BV>`). context:
//                                   AnnotationContext; stats: AnnotateStats* or null.
//   D::describe(storage)            One line for reports and `bvhlab info`: "adb g=2 tau=0.25", "none".
//   D::encode(storage)              std::vector<std::byte>: everything D needs to restore the Storage
//                                   (parameters and per-node data), in a layout of D's version.
//   D::decode(bytes, node_count)    The Storage back from encode()'s bytes; validates every value (it may
//                                   come from a corrupt file) and throws std::invalid_argument naming the
//                                   first problem.
//   D::memory_bytes(storage)        Bytes the annotation adds to a tree in memory (model size reports).
//
// Refinement `ProbabilityDensity<D>`: a density that can estimate, per BV pair, the probability that the
// polygons inside collide (what the ADB strategies need).
//   D::estimator(storage_a, storage_b)
//                                   A small callable e with e(i, box_a, j, box_b, overlap) -> double in
//                                   [0, 1]: node i of A (own-frame bounding box box_a), node j of B, and an
//                                   upper bound of the volume of their overlap. Called on the hot path: it
//                                   must be cheap and inlineable. Throws std::invalid_argument, when
//                                   created, for two annotations that cannot be combined (other parameters).
//   D::estimator(storage_a, storage_b, rotation)   (optional)
//                                   The same for a density whose estimate depends on the pair's relative
//                                   orientation ("adb_normal"): rotation maps B's frame into A's. The ADB
//                                   traversal calls this form when D has it.
//
// Concept `DensityUpdate<U, D>`: how the annotation of density D follows a deforming mesh
// ------------------------------------------------------------------------------------------
// A tree refitted to new vertex positions of the same triangles (Bvh<BV>::refit) keeps its topology, but
// its annotation describes the old shape. An update policy U rewrites the annotation (or keeps it) after
// each refit; the query-time density stays D. The policies and their registry are in adb/update.hpp.
//
// Types
//   U::Params    Run-time parameters (possibly none). Equality-comparable.
//   U::State     What U keeps between frames (the boxes at the last count, fixed surface samples, ...).
//                Copyable; made by start() for one tree and valid for that tree's refits only.
//
// Operations (bvh: const Bvh<BV>&; storage: D::Storage; state: U::State&)
//   U::name()                       Stable identifier ("stale", "recount_all", ...).
//   U::parameters()                 std::span<const ParamSpec>, as for densities (adb/parameters.hpp).
//   U::make_params(values)          Params from resolved values (update_params<U> resolves and checks).
//   U::start(bvh, storage, params)  The State for a tree whose `storage` holds the exact annotation of its
//                                   current (rest) shape.
//   U::update(bvh, storage, state, context, stats)
//                                   After bvh was refitted: rewrites `storage` for the new shape, the way U
//                                   does (stats: DensityUpdateStats* or null). Throws std::invalid_argument
//                                   for a tree other than the one the state was started on.
#pragma once

#include "../bvh/bvh.hpp"
#include "parameters.hpp"

#include <concepts>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// How an annotation run may use the machine.
struct AnnotationContext {
  unsigned threads = 0;  ///< 0: hardware concurrency
  /// Called now and then with (work done, total work), from worker threads but never concurrently, and once
  /// at the end with (total, total).
  std::function<void(std::size_t, std::size_t)> progress;
};

/// What one annotation run did: the caller's evidence that annotation ran, and how it spent its time.
/// A density fills what applies to it; the clipping counters are the ADB annotation's.
struct AnnotateStats {
  double seconds = 0;
  unsigned threads = 0;
  std::size_t nodes = 0;
  std::size_t triangle_node_pairs = 0;  ///< sum over nodes of the node's triangle count
  std::size_t fast_path_triangles = 0;  ///< pairs whose triangle lies inside one cell: no clipping
  std::size_t clipped_triangles = 0;    ///< pairs that needed clipping
  std::size_t clip_calls = 0;     ///< CGAL intersections (one per open candidate cell of a clipped pair)
  std::size_t skipped_clips = 0;  ///< candidate cells already decided by area bounds: not clipped
  std::size_t derived_areas = 0;  ///< candidate cells whose area was the triangle's minus the others'
  std::size_t degenerate_triangles = 0;  ///< pairs skipped because the triangle has zero area
  std::size_t exact_cells = 0;           ///< cells whose decision needed exact arithmetic (ties, near-ties)
};

template <class D>
concept Density = std::equality_comparable<typename D::Params> && std::copyable<typename D::Storage> &&
    requires(const typename D::Storage& storage, const ParamValues& values, std::span<const std::byte> bytes,
             std::size_t node_count) {
  { D::name() } -> std::convertible_to<std::string_view>;
  { D::version() } -> std::same_as<std::uint32_t>;
  { D::parameters() } -> std::same_as<std::span<const ParamSpec>>;
  { D::make_params(values) } -> std::same_as<typename D::Params>;
  { D::describe(storage) } -> std::convertible_to<std::string>;
  { D::encode(storage) } -> std::same_as<std::vector<std::byte>>;
  { D::decode(bytes, node_count) } -> std::same_as<typename D::Storage>;
  { D::memory_bytes(storage) } -> std::convertible_to<std::size_t>;
};

/// D can annotate trees of BV.
template <class D, class BV>
concept DensityFor = Density<D> && requires(const Bvh<BV>& bvh, const typename D::Params& params,
                                            const AnnotationContext& context, AnnotateStats* stats) {
  { D::annotate(bvh, params, context, stats) } -> std::same_as<typename D::Storage>;
};

template <class D>
concept ProbabilityDensity = Density<D> &&
    requires(const typename D::Storage& a, const typename D::Storage& b, std::uint32_t i, const Box& box,
             double overlap) {
  { D::estimator(a, b)(i, box, i, box, overlap) } -> std::convertible_to<double>;
};

/// The parameters of D from name/value pairs: checked against D::parameters(), defaults filled in.
/// Throws std::invalid_argument naming the density and the problem.
template <Density D>
typename D::Params density_params(const ParamValues& given = {}) {
  return D::make_params(resolve_parameters(D::parameters(), given, D::name()));
}

/// What one density update did (DensityUpdate::update).
struct DensityUpdateStats {
  double seconds = 0;
  std::size_t nodes = 0;            ///< nodes of the tree
  std::size_t recounted_nodes = 0;  ///< nodes counted anew by exact clipping
  std::size_t samples = 0;          ///< surface samples moved and binned
  AnnotateStats annotate;           ///< the exact recount's counters, when one ran
};

/// How far a policy's counts are from an exact recount of the same tree (count_error, adb/update.hpp).
struct CountError {
  double mean_difference = 0;  ///< mean |count - exact| per node
  double under_counted = 0;    ///< share of nodes counted below the exact count
};

template <class U, class D>
concept DensityUpdate = Density<D> && std::equality_comparable<typename U::Params> &&
    std::copyable<typename U::State> && requires(const ParamValues& values) {
  { U::name() } -> std::convertible_to<std::string_view>;
  { U::parameters() } -> std::same_as<std::span<const ParamSpec>>;
  { U::make_params(values) } -> std::same_as<typename U::Params>;
};

/// U can update D's annotation of trees of BV.
template <class U, class D, class BV>
concept DensityUpdateFor = DensityUpdate<U, D> &&
    requires(const Bvh<BV>& bvh, const typename D::Storage& rest, typename D::Storage& storage,
             typename U::State& state, const typename U::Params& params, const AnnotationContext& context,
             DensityUpdateStats* stats) {
  { U::start(bvh, rest, params) } -> std::same_as<typename U::State>;
  { U::update(bvh, storage, state, context, stats) } -> std::same_as<void>;
};

/// The parameters of update policy U from name/value pairs: checked against U::parameters(), defaults
/// filled in. Throws std::invalid_argument naming the policy and the problem.
template <class U>
typename U::Params update_params(const ParamValues& given = {}) {
  return U::make_params(resolve_parameters(U::parameters(), given, U::name()));
}

}  // namespace bvhlab
