#include "engine/policies.hpp"

#include "bvh/wide_bvh.hpp"
#include "engine/registry.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <stdexcept>

namespace bvhlab {

namespace {

template <class D>
DensityInfo density_row() {
  const auto specs = D::parameters();
  return {std::string(D::name()), D::version(), {specs.begin(), specs.end()}};
}

template <class S>
StrategyInfo strategy_row() {
  StrategyInfo info;
  info.name = S::name();
  info.description = S::description();
  info.exact = S::exact;
  info.budget = S::budget;
  info.needs_polygons = S::needs_polygons;
  info.needs_density = !S::template accepts<NoDensity>;
  info.coherent = kRunsCoherent<S>;
  info.wide = kRunsWide<S>;
  info.density_free = kDensityFree<S>;
  with_each_density([&]<class D>(std::type_identity<D>) {
    if constexpr (S::template accepts<D>) info.densities.emplace_back(D::name());
  });
  with_each_volume([&]<class BV>(std::type_identity<BV>) {
    if constexpr (kAcceptsVolume<S, BV>) info.volumes.emplace_back(BV::name());
    if constexpr (kRunsWide<S> && kAcceptsVolume<S, BV> && HasWideLayout<BV> && kWalksWideOn<S, BV>)
      info.wide_volumes.emplace_back(BV::name());
  });
  const auto specs = S::parameters();
  info.parameters.assign(specs.begin(), specs.end());
  return info;
}

template <class Row>
const Row& find_named(const std::vector<Row>& table, std::string_view name, std::string_view kind) {
  for (const Row& row : table)
    if (row.name == name) return row;
  std::string known;
  for (const Row& row : table) known += (known.empty() ? "" : ", ") + row.name;
  throw std::invalid_argument("unknown " + std::string(kind) + " '" + std::string(name) +
                              "' (known: " + known + ")");
}

nlohmann::json parameters_json(const std::vector<ParamSpec>& specs) {
  nlohmann::json out = nlohmann::json::array();
  for (const ParamSpec& p : specs) {
    nlohmann::json row = {{"name", p.name},       {"description", p.description},
                          {"min", p.min},         {"max", p.max},
                          {"integer", p.integer}, {"exclusive_min", p.exclusive_min},
                          {"sweep", p.sweep},     {"in_label", p.in_label}};
    row["default"] = p.required() ? nlohmann::json(nullptr) : nlohmann::json(p.default_value);
    out.push_back(std::move(row));
  }
  return out;
}

std::string_view budget_text(BudgetUse use) {
  switch (use) {
    case BudgetUse::None:
      return "none";
    case BudgetUse::Optional:
      return "optional";
    case BudgetUse::Required:
      return "required";
  }
  return "none";
}

}  // namespace

bool StrategyInfo::accepts(std::string_view density) const {
  return std::find(densities.begin(), densities.end(), density) != densities.end();
}

std::string StrategyInfo::refusal(std::string_view density) const {
  if (accepts(density)) return {};
  return "strategy " + name + " does not run on trees with density '" + std::string(density) +
         "' (it runs on: " + joined_names(densities) + ")";
}

std::string StrategyInfo::volume_refusal(std::string_view bv) const {
  if (std::find(volumes.begin(), volumes.end(), bv) != volumes.end()) return {};
  return "strategy " + name + " does not run on trees of volume '" + std::string(bv) +
         "', which has no distance bound (it runs on: " + joined_names(volumes) + ")";
}

namespace {

/// The registered strategies that have `flag`, comma-separated: what a refusal offers instead.
std::string strategies_with(bool StrategyInfo::*flag) {
  std::string those;
  for (const StrategyInfo& s : strategy_table())
    if (s.*flag) those += (those.empty() ? "" : ", ") + s.name;
  return those;
}

}  // namespace

std::string StrategyInfo::coherent_refusal() const {
  if (coherent) return "";
  return "strategy " + name +
         " does not run coherent (the strategies that do: " + strategies_with(&StrategyInfo::coherent) + ")";
}

std::string StrategyInfo::wide_refusal() const {
  if (wide) return "";
  return "strategy " + name +
         " does not run on wide trees (the strategies that do: " + strategies_with(&StrategyInfo::wide) + ")";
}

std::string StrategyInfo::wide_walk_refusal(std::string_view bv) const {
  if (std::string refusal = wide_refusal(); !refusal.empty()) return refusal;
  if (std::string refusal = wide_layout_refusal(bv); !refusal.empty()) return refusal;
  if (std::find(wide_volumes.begin(), wide_volumes.end(), bv) != wide_volumes.end()) return "";
  std::string those;
  for (const std::string& v : wide_volumes) those += (those.empty() ? "" : ", ") + v;
  return "strategy " + name + " has no wide walk on '" + std::string(bv) +
         "' trees (the volumes it walks wide: " + those + ")";
}

std::string wide_layout_refusal(std::string_view bv) {
  check_volume_name(bv);
  bool has = false;
  std::string those;
  with_each_volume([&]<class BV>(std::type_identity<BV>) {
    if constexpr (HasWideLayout<BV>) {
      those += (those.empty() ? "" : ", ") + std::string(BV::name());
      has = has || BV::name() == bv;
    }
  });
  if (has) return "";
  return "bounding volume '" + std::string(bv) + "' has no wide layout (the volumes that do: " + those + ")";
}

std::string StrategyInfo::contact_geometry_refusal() const {
  if (needs_polygons) return "";
  return "strategy " + name + " tests no triangles, so it names no contacts to give the geometry of (the " +
         "strategies that do: " + strategies_with(&StrategyInfo::needs_polygons) + ")";
}

const ParamSpec* StrategyInfo::parameter(std::string_view name) const {
  for (const ParamSpec& p : parameters)
    if (p.name == name) return &p;
  return nullptr;
}

const std::vector<DensityInfo>& density_table() {
  static const std::vector<DensityInfo> table = [] {
    std::vector<DensityInfo> rows;
    with_each_density([&]<class D>(std::type_identity<D>) { rows.push_back(density_row<D>()); });
    return rows;
  }();
  return table;
}

const std::vector<StrategyInfo>& strategy_table() {
  static const std::vector<StrategyInfo> table = [] {
    std::vector<StrategyInfo> rows;
    with_each_strategy([&]<class S>(std::type_identity<S>) { rows.push_back(strategy_row<S>()); });
    return rows;
  }();
  return table;
}

const DensityInfo& density_info(std::string_view name) {
  return find_named(density_table(), name, "density");
}

const StrategyInfo& strategy_info(std::string_view name) {
  return find_named(strategy_table(), name, "strategy");
}

std::string density_label(std::string_view density, const ParamValues& values) {
  const std::string params =
      describe_parameters(density_info(density).parameters, values, [](const ParamSpec&) { return true; });
  return std::string(density) + (params.empty() ? "" : " " + params);
}

std::string strategy_label(std::string_view strategy, const ParamValues& values, const Budget& budget) {
  ParamValues shown = values;
  for (const ParamSpec& p : strategy_info(strategy).parameters)
    if (const auto it = shown.find(p.name);
        !p.label_default && it != shown.end() && it->second == p.default_value)
      shown.erase(it);
  const std::string params = describe_parameters(strategy_info(strategy).parameters, shown,
                                                 [](const ParamSpec& p) { return p.in_label; });
  const std::string budget_text = budget_label(budget);
  return std::string(strategy) + (params.empty() ? "" : " " + params) +
         (budget_text.empty() ? "" : " " + budget_text);
}

nlohmann::json policies_json() {
  nlohmann::json densities = nlohmann::json::array(), strategies = nlohmann::json::array();
  for (const DensityInfo& d : density_table())
    densities.push_back(
        {{"name", d.name}, {"version", d.version}, {"parameters", parameters_json(d.parameters)}});
  for (const StrategyInfo& s : strategy_table())
    strategies.push_back({{"name", s.name},
                          {"description", s.description},
                          {"exact", s.exact},
                          {"budget", budget_text(s.budget)},
                          {"needs_polygons", s.needs_polygons},
                          {"needs_density", s.needs_density},
                          {"coherent", s.coherent},
                          {"wide", s.wide},
                          {"wide_volumes", s.wide_volumes},
                          {"densities", s.densities},
                          {"volumes", s.volumes},
                          {"parameters", parameters_json(s.parameters)}});
  return {{"densities", densities}, {"strategies", strategies}};
}

}  // namespace bvhlab
