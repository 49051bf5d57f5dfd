// Saved trees (adb/saved_tree.hpp) as the CLI reads them: recognised, described, queried without polygons.
#include "bench/run.hpp"

#include "adb/saved_tree.hpp"
#include "bench/core/policies.hpp"
#include "bench/core/registry.hpp"
#include "bench/measure.hpp"
#include "bench/prepare.hpp"
#include "traversal/strategies.hpp"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <utility>

namespace bvhlab {

bool is_saved_tree(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, 8) && std::string_view(magic, 8) == "BVHLTREE";
}

SavedTreeFile read_saved_tree(const std::filesystem::path& file) {
  SavedTreeFile out;
  out.bytes = saved_tree_detail::read_file(file);
  out.header = saved_tree_detail::read_header(out.bytes, file.string());
  try {
    with_volume(out.header.bv_name, [](auto) {});
    with_density(out.header.density_name, [](auto) {});
  } catch (const std::invalid_argument& e) {
    throw SavedTreeError("saved tree '" + file.string() + "': " + e.what());
  }
  return out;
}

namespace {

/// Calls f(tree, header) with the saved tree in `file`, typed by the BV and density its header names.
template <class F>
void with_saved_tree(const std::filesystem::path& file, F&& f) {
  const SavedTreeFile saved = read_saved_tree(file);
  with_volume(saved.header.bv_name, [&]<class BV>(std::type_identity<BV>) {
    with_density(saved.header.density_name, [&]<class D>(std::type_identity<D>) {
      f(load_tree_from_buffer<BV, D>(saved.bytes, file.string()), saved.header);
    });
  });
}

}  // namespace

SavedTreeInfo peek_saved_tree(const std::filesystem::path& file) {
  SavedTreeInfo info;
  with_saved_tree(file, [&]<class BV, class D>(const Tree<BV, D>& tree, const saved_tree_detail::Header& h) {
    info.bv = BV::name();
    info.density = D::name();
    info.annotation = D::describe(tree.density);
    info.nodes = tree.bvh.nodes().size();
    const BvhStats stats = tree.bvh.stats();
    info.triangles = stats.triangles;
    info.units = h.units;
  });
  return info;
}

namespace {

/// Refuses to query a normalised tree against one in its file's units: a pose cannot be in both units.
void check_same_kind_of_units(const std::filesystem::path& a, const TreeUnits& units_a,
                              const std::filesystem::path& b, const TreeUnits& units_b) {
  if (units_a.normalized == units_b.normalized) return;
  const auto& [normalized, raw] = units_a.normalized ? std::pair(a, b) : std::pair(b, a);
  throw std::invalid_argument("saved trees in different units: " + normalized.string() + " is " +
                              (units_a.normalized ? units_a : units_b).describe() + ", " + raw.string() +
                              " is in its mesh file's units; build both with --normalize, or both without");
}

/// B's tree typed as A's: its header must name the same BV and density (else the error describes both).
template <class BV, class D>
Tree<BV, D> load_matching(const Tree<BV, D>& tree_a, const std::filesystem::path& b,
                          const SavedTreeFile& saved_b) {
  if (saved_b.header.bv_name != BV::name() || saved_b.header.density_name != D::name()) {
    const SavedTreeInfo other = peek_saved_tree(b);
    throw std::invalid_argument("the two trees differ in BV or density (" + std::string(BV::name()) + ", " +
                                D::describe(tree_a.density) + " vs " + other.bv + ", " + other.annotation +
                                ")");
  }
  return load_tree_from_buffer<BV, D>(saved_b.bytes, b.string());
}

template <class BV, class D>
void describe_saved(ModelInfo& model, const Tree<BV, D>& tree, const std::filesystem::path& file,
                    const TreeUnits& units) {
  model.object = file.filename().string();
  model.hierarchy = model.bv = BV::name();
  model.annotation = D::describe(tree.density);
  model.units = units;
  describe_tree_size(model, tree);
  model.from_cache = true;
}

/// The first query at `pose` with its full result, then `repeat` more timed as the runner times a series.
template <class S, class BV, class D>
std::vector<PoseAnswer> answer_on_trees(const Tree<BV, D>& a, const Tree<BV, D>& b,
                                        const typename S::Options& options,
                                        std::span<const RigidTransform> poses, int repeat,
                                        double clock_overhead) {
  const auto query = [&](const RigidTransform& p) { return S::query(a, b, p, options); };
  return answer_poses(poses, repeat, clock_overhead, query,
                      [&](std::span<const RigidTransform> all, std::vector<QueryRecord>& records) {
                        timed_series(all, 0, records, query);
                      });
}

}  // namespace

QueryOutcome run_query_on_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                const StrategyVariant& strategy, std::span<const RigidTransform> poses,
                                int repeat) {
  if (poses.empty()) throw std::invalid_argument("query: no pose given");
  const StrategyInfo& info = strategy_info(strategy.strategy);
  if (info.needs_polygons)
    throw std::invalid_argument("saved trees carry no polygons, and strategy " + strategy.strategy +
                                " tests triangles; give the meshes instead");
  const SavedTreeFile saved_b = read_saved_tree(b);
  QueryOutcome outcome;
  const double overhead = repeat > 0 ? clock_overhead_us() : 0;
  // One dispatch on A's header; B is loaded as the same type (a nested dispatch would instantiate every
  // pair of types, nearly all of them only to refuse).
  with_saved_tree(a, [&]<class BV, class D>(const Tree<BV, D>& tree_a, const saved_tree_detail::Header& h) {
    check_same_kind_of_units(a, h.units, b, saved_b.header.units);
    const Tree<BV, D> tree_b = load_matching(tree_a, b, saved_b);
    with_strategy(strategy.strategy, [&]<class S>(std::type_identity<S>) {
      if constexpr (S::template accepts<D>) {
        const auto options = strategy_options<S>(strategy.values, strategy.budget);
        outcome.answers = answer_on_trees<S>(tree_a, tree_b, options, poses, repeat, overhead);
      } else {
        throw std::invalid_argument("strategy " + strategy.strategy +
                                    " does not run on trees with density '" + std::string(D::name()) + "'");
      }
    });
    describe_saved(outcome.model_a, tree_a, a, h.units);
    describe_saved(outcome.model_b, tree_b, b, saved_b.header.units);
  });
  return outcome;
}

}  // namespace bvhlab
