// The registered densities and strategies (engine/registry.hpp) as run-time tables: what the scene
// parser, the CLI, the runner, the report and the plot script read to name, check and label them. Nothing
// outside a policy's header and its registry line says which strategies exist or what they take.
#pragma once

#include "adb/parameters.hpp"
#include "traversal/strategy.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

struct DensityInfo {
  std::string name;
  std::uint32_t version = 0;
  std::vector<ParamSpec> parameters;
};

struct StrategyInfo {
  std::string name, description;
  bool exact = false;  ///< answers agree with the exact ground truth
  BudgetUse budget = BudgetUse::None;
  bool needs_polygons = false;  ///< cannot run on trees saved without polygons
  bool needs_density = false;   ///< does not run on trees without a density
  bool coherent = false;        ///< runs coherent over a sequence of poses (traversal/coherent.hpp)
  bool wide = false;            ///< runs on the trees' wide layout (traversal/wide_*.hpp)
  bool density_free = false;    ///< reads the hierarchies alone: one compiled query per volume (kDensityFree)
  std::vector<std::string> densities;     ///< the registered densities it runs on
  std::vector<std::string> volumes;       ///< the registered volumes it runs on
  std::vector<std::string> wide_volumes;  ///< those its wide walk runs on (empty: no wide walk)
  std::vector<ParamSpec> parameters;
  [[nodiscard]] bool accepts(std::string_view density) const;
  /// Empty when it runs on `density`; else the one message every caller gives: "strategy adb does not run
  /// on trees with density 'none' (it runs on: adb, adb_paper, adb_normal)".
  [[nodiscard]] std::string refusal(std::string_view density) const;
  /// Empty when it runs on trees of volume `bv`; else the one message every caller gives: "strategy distance
  /// does not run on trees of volume 'rbox', which has no distance bound (it runs on: aabb, ...)".
  [[nodiscard]] std::string volume_refusal(std::string_view bv) const;
  [[nodiscard]] const ParamSpec* parameter(std::string_view name) const;
  /// Empty when it runs coherent; else the one message every caller gives: "strategy adb does not run
  /// coherent (the strategies that do: exact, all_contacts)".
  [[nodiscard]] std::string coherent_refusal() const;
  /// Empty when it runs on the trees' wide layout; else the one message every caller gives: "strategy
  /// adb_dfs does not run on wide trees (the strategies that do: exact, all_contacts, adb, ...)".
  [[nodiscard]] std::string wide_refusal() const;
  /// Empty when its wide walk runs on trees of volume `bv`; else the one message every caller gives: the
  /// wide_refusal() above, wide_layout_refusal(bv) below, or "strategy distance has no wide walk on 'aabb'
  /// trees (the volumes it walks wide: obb)".
  [[nodiscard]] std::string wide_walk_refusal(std::string_view bv) const;
  /// Empty when its answers name intersecting triangle pairs (needs_polygons); else the one message every
  /// caller gives for contact geometry asked of it.
  [[nodiscard]] std::string contact_geometry_refusal() const;
};

/// Empty when volume `bv` has a wide layout (bvh/wide_bvh.hpp); else the one message every caller gives:
/// "bounding volume 'rss' has no wide layout (the volumes that do: aabb, ...)".
std::string wide_layout_refusal(std::string_view bv);

/// In registration order.
const std::vector<DensityInfo>& density_table();
const std::vector<StrategyInfo>& strategy_table();
/// Throw std::invalid_argument naming the choices for an unknown name.
const DensityInfo& density_info(std::string_view name);
const StrategyInfo& strategy_info(std::string_view name);

/// "none", or "adb grid=2 tau=0.25": the density's name and every parameter, as reports label trees.
std::string density_label(std::string_view density, const ParamValues& values);
/// "adb p_min=0.9", "time_critical p_min=0.9 bv_tests=50": the name, its labelled parameters, the budget.
std::string strategy_label(std::string_view strategy, const ParamValues& values, const Budget& budget);

/// Both tables as JSON ({"densities": [...], "strategies": [...]}) for results.json and `bvhlab policies`.
nlohmann::json policies_json();

}  // namespace bvhlab
