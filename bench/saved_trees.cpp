// Saved trees (adb/saved_tree.hpp) as the CLI reads them: recognised, described, queried without polygons.
#include "bench/run.hpp"

#include "adb/saved_tree.hpp"
#include "bench/core/policies.hpp"
#include "bench/core/registry.hpp"
#include "bench/prepare.hpp"
#include "traversal/strategies.hpp"

#include <chrono>
#include <fstream>

namespace bvhlab {

using Clock = std::chrono::steady_clock;

bool is_saved_tree(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, 8) && std::string_view(magic, 8) == "BVHLTREE";
}

namespace {

/// Calls f(tree) with the saved tree in `file`, typed by the BV and density its header names.
template <class F>
void with_saved_tree(const std::filesystem::path& file, F&& f) {
  const std::vector<std::byte> bytes = saved_tree_detail::read_file(file);
  const saved_tree_detail::Header header = saved_tree_detail::read_header(bytes, file.string());
  try {  // a name this build does not know is refused naming the file; f's own errors pass unchanged
    with_volume(header.bv_name, [](auto) {});
    with_density(header.density_name, [](auto) {});
  } catch (const std::invalid_argument& e) {
    throw SavedTreeError("saved tree '" + file.string() + "': " + e.what());
  }
  with_volume(header.bv_name, [&]<class BV>(std::type_identity<BV>) {
    with_density(header.density_name, [&]<class D>(std::type_identity<D>) {
      f(load_tree_from_buffer<BV, D>(bytes, file.string()));
    });
  });
}

}  // namespace

SavedTreeInfo peek_saved_tree(const std::filesystem::path& file) {
  SavedTreeInfo info;
  with_saved_tree(file, [&]<class BV, class D>(const Tree<BV, D>& tree) {
    info.bv = BV::name();
    info.density = D::name();
    info.annotation = D::describe(tree.density);
    info.nodes = tree.bvh.nodes().size();
    const BvhStats stats = tree.bvh.stats();
    info.triangles = stats.triangles;
  });
  return info;
}

namespace {

/// B's tree typed as A's: its header must name the same BV and density (else the error describes both).
template <class BV, class D>
Tree<BV, D> load_matching(const Tree<BV, D>& tree_a, const std::filesystem::path& b) {
  const std::vector<std::byte> bytes = saved_tree_detail::read_file(b);
  const saved_tree_detail::Header header = saved_tree_detail::read_header(bytes, b.string());
  if (header.bv_name != BV::name() || header.density_name != D::name()) {
    const SavedTreeInfo other = peek_saved_tree(b);
    throw std::invalid_argument("the two trees differ in BV or density (" + std::string(BV::name()) + ", " +
                                D::describe(tree_a.density) + " vs " + other.bv + ", " + other.annotation +
                                ")");
  }
  return load_tree_from_buffer<BV, D>(bytes, b.string());
}

template <class BV, class D>
void describe_saved(ModelInfo& model, const Tree<BV, D>& tree, const std::filesystem::path& file) {
  model.object = file.filename().string();
  model.hierarchy = model.bv = BV::name();
  model.annotation = D::describe(tree.density);
  describe_tree_size(model, tree);
  model.from_cache = true;
}

}  // namespace

QueryOutcome run_query_on_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                const StrategyVariant& strategy, const RigidTransform& pose) {
  const StrategyInfo& info = strategy_info(strategy.strategy);
  if (info.needs_polygons)
    throw std::invalid_argument("saved trees carry no polygons, and strategy " + strategy.strategy +
                                " tests triangles; give the meshes instead");
  QueryOutcome outcome;
  // One dispatch on A's header; B is loaded as the same type (a nested dispatch would instantiate every
  // pair of types, nearly all of them only to refuse).
  with_saved_tree(a, [&]<class BV, class D>(const Tree<BV, D>& tree_a) {
    const Tree<BV, D> tree_b = load_matching(tree_a, b);
    with_strategy(strategy.strategy, [&]<class S>(std::type_identity<S>) {
      if constexpr (S::template accepts<D>) {
        const auto options = strategy_options<S>(strategy.values, strategy.budget);
        const auto start = Clock::now();
        outcome.result = S::query(tree_a, tree_b, pose, options);
        outcome.micros = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
      } else {
        throw std::invalid_argument("strategy " + strategy.strategy +
                                    " does not run on trees with density '" + std::string(D::name()) + "'");
      }
    });
    describe_saved(outcome.model_a, tree_a, a);
    describe_saved(outcome.model_b, tree_b, b);
  });
  return outcome;
}

}  // namespace bvhlab
