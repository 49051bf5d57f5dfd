#include "engine/specs.hpp"

#include "adb/update.hpp"
#include "engine/policies.hpp"
#include "engine/registry.hpp"

namespace bvhlab {

namespace {

/// The strategy's refusals of a coherent or a wide walk; the two together are refused too.
void check_walk(const StrategyInfo& info, bool coherent, bool wide) {
  if (coherent)
    if (std::string refusal = info.coherent_refusal(); !refusal.empty()) throw std::invalid_argument(refusal);
  if (wide)
    if (std::string refusal = info.wide_refusal(); !refusal.empty()) throw std::invalid_argument(refusal);
  if (coherent && wide)
    throw std::invalid_argument(
        "strategy " + info.name +
        ": a coherent query walks the binary trees; ask for coherent or wide, not both");
}

}  // namespace

std::vector<std::string> volume_names() {
  return type_names(RegisteredVolumes{});
}
std::vector<std::string> density_names() {
  return type_names(RegisteredDensities{});
}
std::vector<std::string> strategy_names() {
  return type_names(RegisteredStrategies{});
}

std::string DensitySpec::label() const {
  return density_label(name, values);
}

std::string DensityUpdateSpec::label() const {
  return with_density_update(name, [&]<class U>(std::type_identity<U>) {
    const std::string params =
        describe_parameters(U::parameters(), values, [](const ParamSpec&) { return true; });
    return name + (params.empty() ? "" : " " + params);
  });
}

std::string StrategyVariant::budget_label() const {
  return bvhlab::budget_label(budget);
}

std::string StrategyVariant::label() const {
  return strategy_label(strategy, values, budget) + (coherent ? " coherent" : "") + (wide ? " wide" : "");
}

double StrategyVariant::value_or(std::string_view name, double fallback) const {
  const auto it = values.find(name);
  return it == values.end() ? fallback : it->second;
}

std::vector<StrategyVariant> expand(const StrategySpec& spec) {
  const StrategyInfo& info = strategy_info(spec.name);
  check_walk(info, spec.coherent, spec.wide);
  // Cross product of the given values (a sweep may hold several), in the order of the parameter table.
  std::vector<ParamValues> combos{{}};
  for (const ParamSpec& p : info.parameters) {
    const auto given = spec.values.find(p.name);
    if (given == spec.values.end()) continue;
    std::vector<ParamValues> next;
    for (const ParamValues& combo : combos)
      for (double v : given->second) {
        ParamValues c = combo;
        c[std::string(p.name)] = v;
        next.push_back(std::move(c));
      }
    combos = std::move(next);
  }
  const std::vector<Budget> budgets = spec.budgets.empty() ? std::vector<Budget>{Budget{}} : spec.budgets;
  std::vector<StrategyVariant> out;
  for (const ParamValues& combo : combos)
    for (const Budget& budget : budgets)
      out.push_back({.strategy = spec.name,
                     .values = resolve_parameters(info.parameters, combo, spec.name),
                     .budget = budget,
                     .coherent = spec.coherent,
                     .wide = spec.wide});
  return out;
}

void check_volume_name(std::string_view name) {
  with_volume(name, [](auto) {});
}

void check_cloud_density(std::string_view density) {
  if (density == NoDensity::name() || density == AdbDensity::name()) return;
  throw std::invalid_argument("density " + std::string(density) +
                              " does not annotate trees over points; they take 'none' or 'adb' (cell counts "
                              "from the points' areas)");
}

DensitySpec density_spec(const std::string& name, const ParamValues& given) {
  DensitySpec density;
  density.name = name;
  density.values = with_density(name, [&]<class D>(std::type_identity<D>) {
    (void)density_params<D>(given);  // the density's own checks of the combination
    return resolve_parameters(D::parameters(), given, D::name());
  });
  return density;
}

StrategyVariant strategy_variant(const std::string& name, const ParamValues& given, const Budget& budget) {
  StrategyVariant variant;
  variant.strategy = name;
  variant.values = resolve_parameters(strategy_info(name).parameters, given, name);
  variant.budget = budget;
  check_strategy_options(variant);
  return variant;
}

void check_strategy_options(const StrategyVariant& variant) {
  check_walk(strategy_info(variant.strategy), variant.coherent, variant.wide);
  if (variant.contact_geometry)
    if (std::string refusal = strategy_info(variant.strategy).contact_geometry_refusal(); !refusal.empty())
      throw std::invalid_argument(refusal);
  with_strategy(variant.strategy, [&]<class S>(std::type_identity<S>) {
    (void)strategy_options<S>(variant.values, variant.budget);
  });
}

}  // namespace bvhlab
