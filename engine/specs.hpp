// What a tree and a query are, by name: the spec types every caller of the run-time layer fills in (the
// scene parser, the CLI, the Python module), and the checks that turn given names and numbers into them.
// Declared without the registry, so that nothing but the run-time layer compiles the policies' templates.
#pragma once

#include "adb/parameters.hpp"
#include "bvh/topology.hpp"
#include "traversal/budget.hpp"

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// The density the scene's trees carry ("annotation" in the file): a registered density and its parameters.
struct DensitySpec {
  std::string name = "none";                ///< a registered density (engine/registry.hpp)
  ParamValues values;                       ///< resolved: every parameter, defaults filled in
  [[nodiscard]] std::string label() const;  ///< "none", "adb grid=2 tau=0.25"
};

/// A density-update policy (adb/update.hpp) with its resolved parameters: how a deform scene's ADB counts
/// follow a refitted tree (FollowingDensity, engine/deforming.hpp).
struct DensityUpdateSpec {
  std::string name;
  ParamValues values;
  [[nodiscard]] std::string label() const;  ///< "recount_moved fraction=0.25 ignore_translation=0"
};

struct HierarchySpec {
  std::string name;  ///< label in reports; default: the BV name
  std::string bv;    ///< a registered BV name, or fcl_obb / fcl_obbrss
  BuildOptions build;
  /// Its own "annotation", in place of the scene's: variants of a density compared in one run.
  std::optional<DensitySpec> density;
  [[nodiscard]] bool is_fcl() const { return bv.rfind("fcl_", 0) == 0; }
};

/// One entry of "strategies": a registered strategy with its given parameters; a sweep parameter may hold
/// several values, and each budget is a variant too.
struct StrategySpec {
  std::string name = "exact";
  std::map<std::string, std::vector<double>, std::less<>> values;  ///< as given; defaults come in expand()
  std::vector<Budget> budgets;                                     ///< strategies that take a budget
  std::vector<std::string> hierarchies;  ///< restricts the strategy to these; empty: all it applies to
  bool coherent = false;                 ///< each variant runs coherent (StrategyVariant::coherent)
  bool wide = false;                     ///< each variant walks the wide layout (StrategyVariant::wide)
};

/// One concrete way to answer a query: the unit of a results row.
struct StrategyVariant {
  std::string strategy = "exact";
  ParamValues values;  ///< resolved
  Budget budget;
  /// A query over a sequence of poses starts each pose where the previous one ended (traversal/coherent.hpp);
  /// only strategies that run coherent take it (StrategyInfo::coherent). Same answers, less work.
  bool coherent = false;
  /// Each named contact also gets its geometry (Result::contact_geometry): only strategies that test
  /// triangles take it, on trees with polygons.
  bool contact_geometry = false;
  /// The query walks the trees' wide layout (four children a node tested at once, bvh/wide_bvh.hpp), built
  /// from each tree on first use and kept with it: only strategies that run wide take it
  /// (StrategyInfo::wide), on volumes with a wide layout, not coherent. The exact strategies give the same
  /// answers in less time; ADB's wide walk estimates fewer pairs, and so may answer otherwise.
  bool wide = false;
  [[nodiscard]] std::string budget_label() const;  ///< "" or "bv_tests=200" or "deadline_us=20"
  [[nodiscard]] std::string label() const;         ///< e.g. "adb p_min=0.9", "exact coherent", "exact wide"
  /// The value of parameter `name`, or `fallback` when the strategy has none.
  [[nodiscard]] double value_or(std::string_view name, double fallback) const;
};
/// Every variant of a spec: the cross product of its sweep values and its budgets, defaults filled in.
/// Throws std::invalid_argument for values the strategy refuses.
std::vector<StrategyVariant> expand(const StrategySpec& spec);

/// The registered names, in registration order (engine/registry.hpp).
std::vector<std::string> volume_names();
std::vector<std::string> density_names();
std::vector<std::string> strategy_names();

/// Throws std::invalid_argument naming the registered volumes when none is called `name`.
void check_volume_name(std::string_view name);
/// Throws std::invalid_argument unless `density` is one a tree over points takes: none, or adb (cell counts
/// from the points' areas).
void check_cloud_density(std::string_view density);

/// `given` checked against the density's parameter table and its own checks, defaults filled in. Throws
/// std::invalid_argument naming an unknown density or a refused value.
DensitySpec density_spec(const std::string& name, const ParamValues& given);
/// A strategy variant from its name, given parameters and budget, checked as `bvhlab query` checks them.
/// Throws std::invalid_argument.
StrategyVariant strategy_variant(const std::string& name, const ParamValues& given, const Budget& budget);
/// Throws std::invalid_argument when the strategy refuses the variant's values, budget, coherence or wide
/// layout (or is asked for both).
void check_strategy_options(const StrategyVariant& variant);

}  // namespace bvhlab
