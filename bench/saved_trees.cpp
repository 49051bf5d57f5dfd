// Saved trees (adb/saved_tree.hpp) as the CLI reads them: recognised, described, queried without polygons,
// all through the run-time layer's handle (engine/any_tree.hpp).
#include "bench/run.hpp"

#include "adb/saved_tree.hpp"
#include "bench/pairs/measure.hpp"
#include "bench/pairs/prepare.hpp"
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"

#include <fstream>
#include <utility>

namespace bvhlab {

bool is_saved_tree(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, 8) && std::string_view(magic, 8) == "BVHLTREE";
}

SavedTreeInfo peek_saved_tree(const std::filesystem::path& file) {
  const AnyTree tree = AnyTree::load(file);
  SavedTreeInfo info;
  info.bv = tree.info().bv;
  info.density = tree.info().density;
  info.annotation = tree.info().annotation;
  info.nodes = tree.info().nodes;
  info.triangles = tree.info().triangles;
  info.units = tree.info().units.file;
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

ModelInfo describe_saved(const AnyTree& tree, const std::filesystem::path& file) {
  ModelInfo model;
  describe_tree(model, tree.info());
  model.object = file.filename().string();
  model.hierarchy = tree.info().bv;
  model.from_cache = true;
  return model;
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
  const AnyTree tree_a = AnyTree::load(a);
  const AnyTree tree_b = AnyTree::load(b);
  check_same_kind_of_units(a, tree_a.info().units.file, b, tree_b.info().units.file);
  QueryOutcome outcome;
  outcome.answers = answer_prepared(*tree_a.prepare(tree_b, strategy), poses, repeat);
  outcome.model_a = describe_saved(tree_a, a);
  outcome.model_b = describe_saved(tree_b, b);
  return outcome;
}

}  // namespace bvhlab
