// bvhlab query: one query between two meshes, or two saved trees, at one pose; prints the full result.
#include "bench/cli/cli.hpp"
#include "bench/core/protocol.hpp"
#include "bench/core/registry.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace bvhlab::cli {
namespace {

namespace fs = std::filesystem;

struct QueryArgs {
  std::string a, b, pose, protocol, bv = "aabb", strategy = "exact", cache, density;
  double deadline = 0;
  std::uint64_t bv_tests = 0;
  bool all = false, json = false, raw = false, no_cache = false;
  ParameterOptions parameters;
  const CLI::Option* bv_tests_option = nullptr;
  const CLI::Option* deadline_option = nullptr;
  [[nodiscard]] bool budget_given() const { return bv_tests_option->count() || deadline_option->count(); }
};

std::vector<double> parse_numbers(const std::string& text, const std::string& what) {
  std::vector<double> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw CLI::ValidationError(what, "'" + item + "' is not a number");
    }
  }
  return out;
}

RigidTransform parse_pose(const std::string& pose, const std::string& protocol) {
  if (!protocol.empty()) {
    const auto v = parse_numbers(protocol, "--protocol");
    if (v.size() != 3 || v[2] < 1 || v[1] < 0 || v[1] != std::floor(v[1]) || v[2] != std::floor(v[2]))
      throw CLI::ValidationError("--protocol",
                                 "expected DISTANCE,STEP,STEPS with integer 0 <= STEP, 1 <= STEPS");
    return protocol_pose(v[0], static_cast<int>(v[1]), static_cast<int>(v[2]));
  }
  const auto v = parse_numbers(pose, "--pose");
  if (v.size() != 3 && v.size() != 7)
    throw CLI::ValidationError("--pose", "expected TX,TY,TZ or TX,TY,TZ,AX,AY,AZ,DEGREES");
  RigidTransform out;
  out.translation = Vec3(v[0], v[1], v[2]);
  if (v.size() == 7) {
    const Vec3 axis(v[3], v[4], v[5]);
    if (axis.norm() == 0) throw CLI::ValidationError("--pose", "the rotation axis has zero length");
    out.rotation = Eigen::AngleAxisd(v[6] * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  }
  if (!out.translation.allFinite()) throw CLI::ValidationError("--pose", "the translation is not finite");
  return out;
}

/// Whether A and B are saved trees (else meshes); refuses one of each.
bool saved_trees(const QueryArgs& args) {
  const bool tree_a = fs::is_regular_file(args.a) && is_saved_tree(args.a);
  const bool tree_b = fs::is_regular_file(args.b) && is_saved_tree(args.b);
  if (tree_a != tree_b)
    throw CLI::ValidationError("query", "give two meshes or two saved trees, not one of each");
  return tree_a;
}

/// The strategy and density names a query runs with: --all-contacts and the default density applied.
struct QueryPolicies {
  std::string strategy, density;
};

QueryPolicies query_policies(const QueryArgs& args, bool trees) {
  QueryPolicies out{args.strategy, args.density};
  if (args.all) {
    if (out.strategy != ExactStrategy::name() && out.strategy != AllContactsStrategy::name())
      throw CLI::ValidationError("--all-contacts",
                                 "lists exact contacts; it does not apply to strategy " + out.strategy);
    out.strategy = AllContactsStrategy::name();
  }
  const StrategyInfo& strategy = strategy_info(out.strategy);
  if (out.density.empty())  // the first density the strategy runs on: none when it needs none
    out.density = strategy.densities.empty() ? std::string(NoDensity::name()) : strategy.densities.front();
  if (!strategy.accepts(out.density))
    throw CLI::ValidationError("--density",
                               "strategy " + out.strategy + " does not run on density " + out.density);
  if (trees && !args.density.empty())
    throw CLI::ValidationError("--density", "saved trees carry their own density; it does not apply");
  return out;
}

/// The checked request: hierarchy, density (for meshes) and strategy with its parameters and budget.
QueryRequest query_request(const QueryArgs& args, bool trees) {
  const QueryPolicies names = query_policies(args, trees);
  const StrategyInfo& strategy = strategy_info(names.strategy);
  const auto& density_parameters = density_info(names.density).parameters;
  if (trees)
    args.parameters.refuse_others({&strategy.parameters}, "strategy " + names.strategy + " on saved trees");
  else
    args.parameters.refuse_others({&strategy.parameters, &density_parameters},
                                  "strategy " + names.strategy + " with density " + names.density);
  QueryRequest request;
  request.hierarchy.bv = request.hierarchy.name = args.bv;
  request.strategy.strategy = names.strategy;
  request.strategy.values =
      resolve_parameters(strategy.parameters, args.parameters.pick(strategy.parameters), names.strategy);
  if (!trees) request.density = density_from(names.density, args.parameters);
  request.strategy.budget.max_bv_tests = args.bv_tests;
  request.strategy.budget.deadline_us = args.deadline;
  if (strategy.budget == BudgetUse::None && args.budget_given())
    throw CLI::ValidationError("--bv-tests/--deadline-us", "strategy " + names.strategy + " takes no budget");
  if (strategy.budget == BudgetUse::Required && request.strategy.budget.unlimited())
    throw CLI::ValidationError("--strategy " + names.strategy, "needs --bv-tests and/or --deadline-us");
  return request;
}

/// A query's outcome, and the names and BV to print it under.
struct QueryRun {
  QueryOutcome outcome;
  std::string name_a, name_b, bv;
};

QueryRun execute_query(const QueryArgs& args, bool trees, const QueryRequest& request,
                       const RigidTransform& pose) {
  QueryRun out;
  if (trees) {  // saved trees: ADB without polygons; BV, grid and tau come from the files
    out.outcome = run_query_on_trees(args.a, args.b, request.strategy, pose);
    out.name_a = args.a;
    out.name_b = args.b;
    out.bv = out.outcome.model_a.bv;
    return out;
  }
  const SceneObject a = object_for(args.a, !args.raw);
  const SceneObject b_separate = object_for(args.b, !args.raw);
  const bool same = a.path == b_separate.path;
  const RunOptions options = run_options(args.cache, args.no_cache, true);
  out.outcome = run_query(a, same ? a : b_separate, request, pose, options);
  out.name_a = a.name;
  out.name_b = b_separate.name;
  out.bv = args.bv;
  return out;
}

void print_json(const QueryOutcome& outcome, bool all_contacts) {
  const Result& r = outcome.result;
  nlohmann::json j = {{"collides", r.collides},
                      {"probability", r.probability},
                      {"exact", r.exact},
                      {"budget_exhausted", r.budget_exhausted},
                      {"time_us", outcome.micros},
                      {"bv_tests", r.counters.bv_tests},
                      {"triangle_tests", r.counters.triangle_tests},
                      {"nodes_visited", r.counters.nodes_visited},
                      {"probability_evaluations", r.counters.probability_evaluations}};
  if (r.witness) j["witness"] = {r.witness->a, r.witness->b};
  if (all_contacts) {
    j["contacts"] = nlohmann::json::array();
    for (const auto& c : r.contacts) j["contacts"].push_back({c.a, c.b});
  }
  std::cout << j.dump(2) << '\n';
}

void print_text(const QueryRun& run, const QueryRequest& request, bool all_contacts) {
  const Result& r = run.outcome.result;
  std::printf("%s vs %s, %s on %s\n", run.name_a.c_str(), run.name_b.c_str(),
              request.strategy.label().c_str(), run.bv.c_str());
  std::printf("  collides          %s\n  probability       %g\n  exact             %s\n",
              r.collides ? "yes" : "no", r.probability, r.exact ? "yes" : "no");
  if (r.budget_exhausted) std::printf("  budget            exhausted (best-effort answer)\n");
  if (r.witness)
    std::printf("  witness           triangle %u of A, triangle %u of B\n", r.witness->a, r.witness->b);
  if (all_contacts) std::printf("  contacts          %zu triangle pairs\n", r.contacts.size());
  std::printf("  time              %.2f us\n", run.outcome.micros);
  if (!request.hierarchy.is_fcl())
    std::printf("  BV tests          %ju\n  triangle tests    %ju\n  nodes visited     %ju\n",
                std::uintmax_t(r.counters.bv_tests), std::uintmax_t(r.counters.triangle_tests),
                std::uintmax_t(r.counters.nodes_visited));
  if (r.counters.probability_evaluations)
    std::printf("  estimates         %ju\n", std::uintmax_t(r.counters.probability_evaluations));
}

int query_command(const QueryArgs& args) {
  if (args.pose.empty() && args.protocol.empty())
    throw CLI::ValidationError("query", "give B's pose with --pose or --protocol");
  const bool trees = saved_trees(args);
  const QueryRequest request = query_request(args, trees);
  const RigidTransform pose = parse_pose(args.pose, args.protocol);
  const QueryRun result = execute_query(args, trees, request, pose);
  if (args.json)
    print_json(result.outcome, args.all);
  else
    print_text(result, request, args.all);
  return 0;
}

/// The policies' options: the strategies' and densities' parameters, and the budget.
void add_policy_options(CLI::App* query, QueryArgs& args) {
  query->add_option("--bv", args.bv, "Hierarchy: a bvhlab BV, or fcl_obb / fcl_obbrss")
      ->check(CLI::IsMember(hierarchy_bv_names()))
      ->capture_default_str();
  query->add_option("--strategy", args.strategy, "Strategy (`bvhlab policies`)")
      ->check(CLI::IsMember(strategy_names()))
      ->capture_default_str();
  query
      ->add_option(
          "--density", args.density,
          "Density of the trees built from meshes (default: none, or the first one the strategy needs)")
      ->check(CLI::IsMember(density_names()));
  for (const StrategyInfo& st : strategy_table())
    args.parameters.add(query, st.parameters, "strategy " + st.name);
  for (const DensityInfo& d : density_table()) args.parameters.add(query, d.parameters, "density " + d.name);
  args.parameters.finish_help();
  args.bv_tests_option =
      query->add_option("--bv-tests", args.bv_tests, "Budget of BV tests (strategies with a budget)");
  args.deadline_option =
      query->add_option("--deadline-us", args.deadline, "Deadline in microseconds (strategies with a budget)")
          ->check(CLI::PositiveNumber);
}

}  // namespace

Command add_query_command(CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  auto* query = app.add_subcommand("query", "One query between two meshes; prints the full result");
  query->add_option("A", args->a, "Mesh A (stays at the origin), or a saved tree")->required();
  query->add_option("B", args->b, "Mesh B (moved by the pose), or a saved tree")->required();
  auto* pose_option =
      query->add_option("--pose", args->pose, "B's pose: TX,TY,TZ or TX,TY,TZ,AX,AY,AZ,DEGREES");
  query->add_option("--protocol", args->protocol, "B's pose from the protocol: DISTANCE,STEP,STEPS")
      ->excludes(pose_option);
  add_policy_options(query, *args);
  query->add_flag("--all-contacts", args->all,
                  "Short for --strategy all_contacts: every intersecting triangle pair");
  query->add_flag("--no-normalize", args->raw, "Keep the meshes' coordinates");
  query->add_flag("--json", args->json, "Print JSON");
  query->add_option("--cache", args->cache, "Tree cache directory (default: <build>/cache)");
  query->add_flag("--no-cache", args->no_cache, "Neither read nor write the tree cache");
  query->footer(
      "Examples:\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --pose 1.5,0,0,0,0,1,30\n"
      "  bvhlab query injector_pipes.stl injector_pipes.stl --protocol 1.6,42,5000 --strategy time_critical "
      "--bv-tests 200");
  return {query, [args] { return query_command(*args); }};
}

}  // namespace bvhlab::cli
