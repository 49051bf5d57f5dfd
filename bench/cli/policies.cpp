// bvhlab policies: the registered densities and strategies, with their parameters.
#include "bench/cli/cli.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

namespace bvhlab::cli {
namespace {

void print_parameters(const std::vector<ParamSpec>& specs) {
  for (const ParamSpec& p : specs)
    std::printf("      %-22s %s; %s%s\n", std::string(p.name).c_str(), std::string(p.description).c_str(),
                p.range_text().c_str(),
                p.required() ? "" : (", default " + parameter_text(p.default_value)).c_str());
}

const char* budget_text(BudgetUse budget) {
  return budget == BudgetUse::None ? "none" : budget == BudgetUse::Required ? "required" : "optional";
}

int policies_command(bool json) {
  if (json) {
    std::cout << policies_json().dump(2) << '\n';
    return 0;
  }
  std::printf("densities\n");
  for (const DensityInfo& d : density_table()) {
    std::printf("  %s (data version %u)\n", d.name.c_str(), d.version);
    print_parameters(d.parameters);
  }
  std::printf("strategies\n");
  for (const StrategyInfo& s : strategy_table()) {
    const bool every_volume = s.volumes.size() == volume_names().size();
    std::printf("  %-14s %s; %s, budget %s, densities: %s%s%s\n", s.name.c_str(), s.description.c_str(),
                s.exact ? "exact" : "inexact", budget_text(s.budget), join(s.densities).c_str(),
                every_volume ? "" : ("; volumes: " + join(s.volumes)).c_str(),
                s.needs_polygons ? "; needs polygons" : "");
    print_parameters(s.parameters);
  }
  return 0;
}

}  // namespace

Command add_policies_command(CLI::App& app) {
  auto json = std::make_shared<bool>(false);
  auto* policies =
      app.add_subcommand("policies", "The registered densities and strategies, with their parameters");
  policies->add_flag("--json", *json, "Print JSON");
  return {policies, [json] { return policies_command(*json); }};
}

}  // namespace bvhlab::cli
