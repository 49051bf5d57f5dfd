// bvhlab query: queries between two meshes, or two saved trees, at one pose or a list of poses; prints the
// full result.
#include "bench/cli/cli.hpp"
#include "bench/cloud_query.hpp"
#include "bvh/point_cloud.hpp"
#include "engine/protocol.hpp"
#include "engine/specs.hpp"
#include "traversal/strategy_names.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
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
  std::string a, b, pose, protocol, poses_file, bv = "aabb", strategy = "exact", cache, density, cloud;
  double deadline = 0, bv_tests = 0;
  int repeat = 0;
  bool all = false, json = false, normalize = false, no_cache = false, coherent = false, geometry = false,
       wide = false;
  ParameterOptions parameters;
  const CLI::Option* bv_option = nullptr;
  const CLI::Option* strategy_option = nullptr;
  const CLI::Option* bv_tests_option = nullptr;
  const CLI::Option* deadline_option = nullptr;
  const CLI::Option* cache_option = nullptr;
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

/// Throws CLI::ValidationError for `value` outside `spec`'s range (the range the scene parser checks too).
void check_value(const ParamSpec& spec, double value, const std::string& option) {
  if (const std::string problem = spec.problem(value); !problem.empty())
    throw CLI::ValidationError(option, std::string(spec.name) + " " + problem);
}

/// DISTANCE,STEP,STEPS: that step's pose; DISTANCE,STEPS: every step in order, each listed by its step.
std::vector<ListedPose> protocol_poses_argument(const std::string& protocol) {
  const auto v = parse_numbers(protocol, "--protocol");
  if (v.size() != 2 && v.size() != 3)
    throw CLI::ValidationError("--protocol", "expected DISTANCE,STEP,STEPS or DISTANCE,STEPS");
  check_value(limits::kDistance, v[0], "--protocol");
  check_value(limits::kSteps, v.back(), "--protocol");
  const int steps = static_cast<int>(v.back());
  if (v.size() == 2) {
    check_value(limits::kPoses, v.back(), "--protocol");  // every step is listed
    std::vector<ListedPose> out;
    for (const RigidTransform& pose : protocol_poses(v[0], steps)) out.push_back({pose, out.size()});
    return out;
  }
  if (!(v[1] >= 0 && v[1] < v[2] && v[1] == std::floor(v[1])))
    throw CLI::ValidationError("--protocol", "STEP must be an integer in [0, STEPS - 1], got " +
                                                 parameter_text(v[1]) + " with STEPS " +
                                                 parameter_text(v[2]));
  return {{protocol_pose(v[0], static_cast<int>(v[1]), steps), 0}};
}

/// The poses to query, each with the line of the pose list it came from (0 for --pose and a single
/// --protocol step; the step for a --protocol turn).
std::vector<ListedPose> poses_of(const QueryArgs& args) {
  if (!args.poses_file.empty()) {
    try {
      return load_pose_list(args.poses_file);
    } catch (const SceneError& e) {
      throw CLI::ValidationError("--poses", e.what());
    }
  }
  if (!args.protocol.empty()) return protocol_poses_argument(args.protocol);
  try {
    return {{pose_from_numbers(parse_numbers(args.pose, "--pose")), 0}};
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--pose", e.what());
  }
}

bool is_saved_tree_file(const std::string& file) {
  return fs::is_regular_file(file) && is_saved_tree(file);
}

/// Options that do not apply to point clouds: they are read in their files' own units and not cached.
void refuse_cloud_options(const QueryArgs& args) {
  for (const std::string& file : {args.a, args.b})
    if (is_saved_tree_file(file))
      throw CLI::ValidationError("--cloud", "'" + file + "' is a saved tree; give mesh and cloud files");
  if (args.normalize)
    throw CLI::ValidationError("--normalize",
                               "applies to meshes; with --cloud both files keep their own units");
  if (args.cache_option->count() || args.no_cache)
    throw CLI::ValidationError("--cache/--no-cache", "trees over clouds are not cached; it does not apply");
  if (args.bv.rfind("fcl_", 0) == 0)
    throw CLI::ValidationError("--bv", "FCL hierarchies hold no point clouds; give a bvhlab volume");
  if (args.geometry)
    throw CLI::ValidationError("--contact-geometry", "a point cloud has no triangles to meet in a segment");
}

/// Whether A and B are saved trees (else meshes); refuses one of each.
bool saved_trees(const QueryArgs& args) {
  const bool tree_a = is_saved_tree_file(args.a);
  const bool tree_b = is_saved_tree_file(args.b);
  if (tree_a != tree_b)
    throw CLI::ValidationError("query", "give two meshes or two saved trees, not one of each");
  return tree_a;
}

/// Options that shape trees built from meshes: a saved tree already has its BV, units and density.
void refuse_tree_building_options(const QueryArgs& args) {
  const std::string why = "saved trees carry their own ";
  if (args.bv_option->count()) throw CLI::ValidationError("--bv", why + "BV; it does not apply");
  if (args.normalize) throw CLI::ValidationError("--normalize", why + "units; it does not apply");
  if (!args.density.empty()) throw CLI::ValidationError("--density", why + "density; it does not apply");
  if (args.cache_option->count() || args.no_cache)
    throw CLI::ValidationError("--cache/--no-cache",
                               "saved trees are read as they are; the cache does not apply");
}

/// The strategy and density names a query runs with: --all-contacts, --tolerance without --strategy and the
/// default density applied.
struct QueryPolicies {
  std::string strategy, density;
};

QueryPolicies query_policies(const QueryArgs& args) {
  QueryPolicies out{args.strategy, args.density};
  if (!args.strategy_option->count() && args.parameters.given(kToleranceStrategyName))
    out.strategy = kToleranceStrategyName;
  if (args.all) {
    if (out.strategy != kExactStrategyName && out.strategy != kAllContactsStrategyName)
      throw CLI::ValidationError("--all-contacts",
                                 "lists exact contacts; it does not apply to strategy " + out.strategy);
    out.strategy = kAllContactsStrategyName;
  }
  const StrategyInfo& strategy = strategy_info(out.strategy);
  if (out.density.empty())  // the first density the strategy runs on: none when it needs none
    out.density = strategy.densities.empty() ? std::string(NoDensity::name()) : strategy.densities.front();
  if (std::string refusal = strategy.refusal(out.density); !refusal.empty())
    throw CLI::ValidationError("--density", refusal);
  return out;
}

/// The budget given, checked against the ranges a scene's budgets have.
Budget budget_of(const QueryArgs& args, const StrategyInfo& strategy) {
  if (strategy.budget == BudgetUse::None && args.budget_given())
    throw CLI::ValidationError("--bv-tests/--deadline-us", "strategy " + strategy.name + " takes no budget");
  Budget budget;
  if (args.bv_tests_option->count()) {
    check_value(limits::kBvTests, args.bv_tests, "--bv-tests");
    budget.max_bv_tests = static_cast<std::uint64_t>(args.bv_tests);
  }
  if (args.deadline_option->count()) {
    check_value(limits::kDeadlineUs, args.deadline, "--deadline-us");
    budget.deadline_us = args.deadline;
  }
  if (strategy.budget == BudgetUse::Required && budget.unlimited())
    throw CLI::ValidationError("--strategy " + strategy.name, "needs --bv-tests and/or --deadline-us");
  return budget;
}

/// The checked request: hierarchy, density (for meshes) and strategy with its parameters and budget.
QueryRequest query_request(const QueryArgs& args, bool trees) {
  if (trees) refuse_tree_building_options(args);
  const QueryPolicies names = query_policies(args);
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
  request.strategy.budget = budget_of(args, strategy);
  request.strategy.coherent = args.coherent;
  if (args.coherent) {
    if (std::string refusal = strategy.coherent_refusal(); !refusal.empty())
      throw CLI::ValidationError("--coherent", refusal);
    if (args.bv.rfind("fcl_", 0) == 0)
      throw CLI::ValidationError("--coherent", "FCL hierarchies do not run coherent; give a bvhlab volume");
  }
  request.strategy.wide = args.wide;
  if (args.wide) {
    if (args.bv.rfind("fcl_", 0) == 0)
      throw CLI::ValidationError("--wide", "FCL hierarchies have no wide layout here; give a bvhlab volume");
    if (std::string refusal = strategy.wide_refusal(); !refusal.empty())
      throw CLI::ValidationError("--wide", refusal);
    if (std::string refusal = trees ? "" : strategy.wide_walk_refusal(args.bv); !refusal.empty())
      throw CLI::ValidationError("--wide", refusal);
    if (args.coherent)
      throw CLI::ValidationError("--wide",
                                 "a coherent query walks the binary trees; give --coherent or --wide");
  }
  request.strategy.contact_geometry = args.geometry;
  if (args.geometry) {
    if (std::string refusal = strategy.contact_geometry_refusal(); !refusal.empty())
      throw CLI::ValidationError("--contact-geometry", refusal);
    if (args.bv.rfind("fcl_", 0) == 0)
      throw CLI::ValidationError("--contact-geometry",
                                 "FCL hierarchies give no contact geometry here; give a "
                                 "bvhlab volume");
  }
  request.repeat = args.repeat;
  return request;
}

/// The queries' outcome, and the names and BV to print it under.
struct QueryRun {
  QueryOutcome outcome;
  std::vector<ListedPose> poses;
  std::string name_a, name_b, bv;
  const char* index = "line";  ///< what ListedPose::line holds: a pose list's line, or a protocol step
};

/// Says on stderr in which units the poses are read, when they are not the mesh files' own.
void report_units(const QueryRun& run, bool trees) {
  const ModelInfo* models[] = {&run.outcome.model_a, &run.outcome.model_b};
  const std::string names[] = {run.name_a, run.name_b};
  for (int k = 0; k < (run.name_a == run.name_b ? 1 : 2); ++k)
    if (models[k]->units.normalized)
      std::fprintf(stderr, "bvhlab: %s %s %s\n", names[k].c_str(), trees ? "is" : "was",
                   models[k]->units.describe().c_str());
  if (models[0]->units.normalized)
    std::fprintf(stderr, "bvhlab: poses are read in normalised units (both objects' longest side is 2)\n");
}

QueryRun execute_query(const QueryArgs& args, bool trees, const QueryRequest& request,
                       std::vector<ListedPose> listed) {
  QueryRun out;
  out.poses = std::move(listed);
  std::vector<RigidTransform> poses;
  for (const ListedPose& p : out.poses) poses.push_back(p.pose);
  if (!args.cloud.empty()) {  // a cloud on one side or both, in the files' own units
    const QueryObject a{args.a, args.cloud != "b"}, b{args.b, args.cloud != "a"};
    out.outcome = run_cloud_query(a, b, args.bv, request.density, request.strategy, poses, request.repeat);
    out.name_a = out.outcome.model_a.object;
    out.name_b = out.outcome.model_b.object;
    out.bv = args.bv;
  } else if (trees) {  // saved trees: ADB without polygons; BV, grid, tau and units come from the files
    out.outcome = run_query_on_trees(args.a, args.b, request.strategy, poses, request.repeat);
    out.name_a = args.a;
    out.name_b = args.b;
    out.bv = out.outcome.model_a.bv;
  } else {
    const SceneObject a = object_for(args.a, args.normalize);
    const SceneObject b_separate = object_for(args.b, args.normalize);
    const bool same = a.path == b_separate.path;
    const RunOptions options = run_options(args.cache, args.no_cache, true);
    out.outcome = run_query(a, same ? a : b_separate, request, poses, options);
    for (const std::string& warning : out.outcome.warnings)
      std::fprintf(stderr, "bvhlab: warning: %s\n", warning.c_str());
    for (const std::string& advice : out.outcome.advice)
      std::fprintf(stderr, "bvhlab: note: %s\n", advice.c_str());
    out.name_a = a.name;
    out.name_b = b_separate.name;
    out.bv = args.bv;
  }
  report_units(out, trees);
  return out;
}

/// Median, min and max of the warm times.
struct Spread {
  double median = 0, min = 0, max = 0;
};

Spread spread_of(std::vector<double> times) {
  std::sort(times.begin(), times.end());
  const std::size_t n = times.size();
  return {n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]), times.front(), times.back()};
}

/// A distance strategy's answer; JSON has no infinity: trees without a triangle pair give null.
nlohmann::json proximity_json(const Proximity& p) {
  const auto finite_or_null = [](double x) {
    return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
  };
  nlohmann::json j = {{"distance", finite_or_null(p.distance)},
                      {"lower_bound", finite_or_null(p.lower_bound)},
                      {"on_a", p.on_a},
                      {"on_b", p.on_b}};
  if (p.triangles) j["triangles"] = {p.triangles->a, p.triangles->b};
  return j;
}

nlohmann::json geometry_json(const ContactGeometry& g) {
  return {{"triangles", {g.triangles.a, g.triangles.b}},
          {"from", g.from},
          {"to", g.to},
          {"point", g.point},
          {"normal", g.normal},
          {"coplanar", g.coplanar}};
}

nlohmann::json answer_json(const PoseAnswer& answer, bool all_contacts) {
  const Result& r = answer.result;
  nlohmann::json j = {{"collides", r.collides},
                      {"probability", r.probability},
                      {"exact", r.exact},
                      {"budget_exhausted", r.budget_exhausted},
                      {"time_us", answer.micros},
                      {"bv_tests", r.counters.bv_tests},
                      {"triangle_tests", r.counters.triangle_tests},
                      {"nodes_visited", r.counters.nodes_visited},
                      {"probability_evaluations", r.counters.probability_evaluations}};
  if (!answer.warm_micros.empty()) {
    const Spread s = spread_of(answer.warm_micros);
    j["warm_time_us"] = {
        {"queries", answer.warm_micros.size()}, {"median", s.median}, {"min", s.min}, {"max", s.max}};
  }
  if (r.witness) j["witness"] = {r.witness->a, r.witness->b};
  if (all_contacts) {
    j["contacts"] = nlohmann::json::array();
    for (const auto& c : r.contacts) j["contacts"].push_back({c.a, c.b});
  }
  if (r.proximity) j["distance"] = proximity_json(*r.proximity);
  if (!r.contact_geometry.empty()) {
    j["contact_geometry"] = nlohmann::json::array();
    for (const ContactGeometry& g : r.contact_geometry) j["contact_geometry"].push_back(geometry_json(g));
  }
  return j;
}

void print_json(const QueryRun& run, bool all_contacts, bool batch) {
  if (!batch) {
    std::cout << answer_json(run.outcome.answers.front(), all_contacts).dump(2) << '\n';
    return;
  }
  nlohmann::json results = nlohmann::json::array();
  for (std::size_t k = 0; k < run.poses.size(); ++k) {
    nlohmann::json j = answer_json(run.outcome.answers[k], all_contacts);
    j[run.index] = run.poses[k].line;
    results.push_back(std::move(j));
  }
  std::cout << nlohmann::json{{"results", results}}.dump(2) << '\n';
}

void print_times(const PoseAnswer& answer) {
  std::printf("  time              %.2f us (one query, no warm-up)\n", answer.micros);
  if (answer.warm_micros.empty()) return;
  const Spread s = spread_of(answer.warm_micros);
  std::printf("  warm time         median %.3f us, min %.3f us, max %.3f us over %zu queries\n", s.median,
              s.min, s.max, answer.warm_micros.size());
}

void print_proximity(const Proximity& p) {
  std::printf("  distance          %.17g\n", p.distance);
  if (p.lower_bound != p.distance)
    std::printf("  lower bound       %.17g (the distance lies between the two)\n", p.lower_bound);
  if (!p.triangles) return;
  std::printf("  nearest           triangle %u of A, triangle %u of B\n", p.triangles->a, p.triangles->b);
  std::printf("  point on A        %.17g %.17g %.17g\n", p.on_a[0], p.on_a[1], p.on_a[2]);
  std::printf("  point on B        %.17g %.17g %.17g (in A's frame)\n", p.on_b[0], p.on_b[1], p.on_b[2]);
}

void print_geometry(const std::vector<ContactGeometry>& geometry, const char* indent) {
  for (const ContactGeometry& g : geometry)
    std::printf("%striangles %u %u: %s %.9g %.9g %.9g to %.9g %.9g %.9g, normal %.6g %.6g %.6g\n", indent,
                g.triangles.a, g.triangles.b, g.coplanar ? "coplanar, across" : "segment", g.from[0],
                g.from[1], g.from[2], g.to[0], g.to[1], g.to[2], g.normal[0], g.normal[1], g.normal[2]);
}

void print_answer(const PoseAnswer& answer, bool all_contacts, bool counters) {
  const Result& r = answer.result;
  std::printf("  collides          %s\n  probability       %g\n  exact             %s\n",
              r.collides ? "yes" : "no", r.probability, r.exact ? "yes" : "no");
  if (r.budget_exhausted)
    std::printf(
        "  budget            exhausted (deadline or BV-test cap reached before the traversal finished)\n");
  if (r.witness)
    std::printf("  witness           triangle %u of A, triangle %u of B\n", r.witness->a, r.witness->b);
  if (all_contacts) {
    std::printf("  contacts          %zu triangle pairs%s\n", r.contacts.size(),
                r.contacts.empty() ? "" : " (triangle of A, triangle of B):");
    for (const auto& c : r.contacts) std::printf("    %u %u\n", c.a, c.b);
  }
  if (r.proximity) print_proximity(*r.proximity);
  if (!r.contact_geometry.empty()) {
    std::printf("  contact geometry  in A's frame, normals from A into B:\n");
    print_geometry(r.contact_geometry, "    ");
  }
  print_times(answer);
  if (counters)
    std::printf("  BV tests          %ju\n  triangle tests    %ju\n  nodes visited     %ju\n",
                std::uintmax_t(r.counters.bv_tests), std::uintmax_t(r.counters.triangle_tests),
                std::uintmax_t(r.counters.nodes_visited));
  if (r.counters.probability_evaluations)
    std::printf("  estimates         %ju\n", std::uintmax_t(r.counters.probability_evaluations));
}

/// A pose list: one row per pose; --json (or a single --pose) has every detail.
void print_table(const QueryRun& run, bool all_contacts, bool repeat) {
  const bool distances = !run.outcome.answers.empty() && run.outcome.answers.front().result.proximity;
  std::printf("  %6s  %-8s  %11s  %-5s  %10s  %10s  %14s%s%s%s\n", run.index, "collides", "probability",
              "exact", "time_us", "bv_tests", "triangle_tests", repeat ? "  warm_median_us" : "",
              all_contacts ? "  contacts" : "", distances ? "      distance   lower_bound" : "");
  for (std::size_t k = 0; k < run.poses.size(); ++k) {
    const PoseAnswer& answer = run.outcome.answers[k];
    const Result& r = answer.result;
    std::printf("  %6zu  %-8s  %11.6g  %-5s  %10.2f  %10ju  %14ju", run.poses[k].line,
                r.collides ? "yes" : "no", r.probability, r.exact ? "yes" : "no", answer.micros,
                std::uintmax_t(r.counters.bv_tests), std::uintmax_t(r.counters.triangle_tests));
    if (repeat) std::printf("  %14.3f", spread_of(answer.warm_micros).median);
    if (all_contacts) std::printf("  %8zu", r.contacts.size());
    if (r.proximity) std::printf("  %12.9g  %12.9g", r.proximity->distance, r.proximity->lower_bound);
    std::printf("\n");
    print_geometry(r.contact_geometry, "          ");
  }
}

void print_text(const QueryRun& run, const QueryRequest& request, bool all_contacts, bool batch) {
  std::printf("%s vs %s, %s on %s", run.name_a.c_str(), run.name_b.c_str(), request.strategy.label().c_str(),
              run.bv.c_str());
  if (!batch) {
    std::printf("\n");
    print_answer(run.outcome.answers.front(), all_contacts, !request.hierarchy.is_fcl());
    return;
  }
  std::printf(", %zu poses\n", run.poses.size());
  print_table(run, all_contacts, request.repeat > 0);
}

/// Without --cloud, a side whose file is a point cloud (a PLY without faces, XYZ) is read as one, as --cloud
/// would have it, with a note: a cloud is taken as it is given, never refused as a mesh without faces.
QueryArgs with_detected_clouds(QueryArgs args) {
  if (!args.cloud.empty()) return args;
  auto cloud_file = [](const std::string& argument) {
    return !is_saved_tree_file(argument) && is_point_cloud_file(resolve_mesh_argument(argument));
  };
  const bool a = cloud_file(args.a), b = cloud_file(args.b);
  if (!a && !b) return args;
  args.cloud = a && b ? "both" : a ? "a" : "b";
  std::fprintf(stderr, "bvhlab: %s: a point cloud file, queried as with --cloud %s\n",
               (a && b ? args.a + " and " + args.b
                : a    ? args.a
                       : args.b)
                   .c_str(),
               args.cloud.c_str());
  return args;
}

int query_command(const QueryArgs& given) {
  const int sources =
      int(!given.pose.empty()) + int(!given.protocol.empty()) + int(!given.poses_file.empty());
  if (sources != 1)
    throw CLI::ValidationError("query", "give B's pose with one of --pose, --protocol, --poses");
  const QueryArgs args = with_detected_clouds(given);
  if (!args.cloud.empty()) refuse_cloud_options(args);
  const bool trees = args.cloud.empty() && saved_trees(args);
  const QueryRequest request = query_request(args, trees);
  std::vector<ListedPose> poses = poses_of(args);
  const bool batch = !args.poses_file.empty() || poses.size() > 1;
  QueryRun run = execute_query(args, trees, request, std::move(poses));
  if (!args.protocol.empty()) run.index = "step";
  // The contacts are listed whether the strategy was named or given by --all-contacts.
  const bool all_contacts = request.strategy.strategy == kAllContactsStrategyName;
  if (args.json)
    print_json(run, all_contacts, batch);
  else
    print_text(run, request, all_contacts, batch);
  return 0;
}

/// The policies' options: the strategies' and densities' parameters, and the budget.
void add_policy_options(CLI::App* query, QueryArgs& args) {
  args.bv_option = query->add_option("--bv", args.bv, "Hierarchy: a bvhlab BV, or fcl_obb / fcl_obbrss")
                       ->check(CLI::IsMember(hierarchy_bv_names()))
                       ->capture_default_str();
  args.strategy_option = query->add_option("--strategy", args.strategy, "Strategy (`bvhlab policies`)")
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
      query->add_option("--bv-tests", args.bv_tests,
                        "Budget of BV tests (strategies with a budget); " + limits::kBvTests.range_text());
  args.deadline_option = query->add_option(
      "--deadline-us", args.deadline,
      "Deadline in microseconds (strategies with a budget); " + limits::kDeadlineUs.range_text());
}

}  // namespace

Command add_query_command(CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  auto* query = app.add_subcommand("query", "Queries between two meshes at one pose or a list of poses");
  query->add_option("A", args->a, "Mesh A (stays at the origin), or a saved tree")->required();
  query->add_option("B", args->b, "Mesh B (moved by the pose), or a saved tree")->required();
  query->add_option(
      "--pose", args->pose,
      "B's pose: TX,TY,TZ or TX,TY,TZ,AX,AY,AZ,DEGREES, or the 12 numbers of [R | t] row by row");
  query->add_option("--protocol", args->protocol,
                    "B's pose from the protocol: DISTANCE,STEP,STEPS, or DISTANCE,STEPS for every step in "
                    "order (its distances assume --normalize)");
  query->add_option("--poses", args->poses_file,
                    "A pose list: one pose per line, as --pose takes it (blanks or commas between numbers; "
                    "'#' starts a comment line)");
  add_policy_options(query, *args);
  query->add_flag("--all-contacts", args->all,
                  "Short for --strategy all_contacts: every intersecting triangle pair, listed");
  query->add_flag("--coherent", args->coherent,
                  "Start each pose where the previous one ended (less work on poses close to each other; "
                  "traversal/README.md, \"Coherent queries\"): the poses of --poses or a --protocol turn in "
                  "order, and each --repeat pass");
  query->add_flag(
      "--wide", args->wide,
      "Walk the trees' wide layout: four children a node tested at once (exact and all_contacts on "
      "aabb, the k-DOPs, obb and sphere; distance on obb). The same answers, in less time");
  query->add_flag("--contact-geometry", args->geometry,
                  "Also give each contact's geometry: the segment where its two triangles meet, its midpoint "
                  "and a normal from A into B (in A's frame; no penetration depth)");
  query->add_flag("--normalize", args->normalize,
                  "Apply the protocol normalisation to each mesh (centre to the origin, longest side 2); "
                  "default: the mesh files' own units");
  query
      ->add_option("--repeat", args->repeat,
                   "Also time N warm passes over the poses (each pose once per pass, so no pose repeats back "
                   "to back): per pose the median, min and max")
      ->check(CLI::Range(1, 10'000'000));
  query
      ->add_option("--cloud", args->cloud,
                   "Read A, B or both as point clouds (PLY: the vertices; XYZ), queried through their "
                   "implicit surfaces; density none or adb (areas from each point's 10th neighbour)")
      ->check(CLI::IsMember({"a", "b", "both"}));
  query->add_flag("--json", args->json, "Print JSON");
  args->cache_option =
      query->add_option("--cache", args->cache, "Tree cache directory (default: <build>/cache)");
  query->add_flag("--no-cache", args->no_cache, "Neither read nor write the tree cache");
  query->footer(
      "Poses are in the meshes' units (the files' own, or normalised with --normalize).\n"
      "Examples:\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --pose 12,0,0,0,0,1,30\n"
      "  bvhlab query injector_pipes.stl injector_pipes.stl --normalize --protocol 1.6,42,5000 "
      "--strategy time_critical --bv-tests 200 --repeat 100\n"
      "  bvhlab query pinion.off pinion.off --normalize --poses bench/scenes/example_poses.txt --json\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --normalize --protocol 0.8,2000 --coherent --repeat 5\n"
      "  bvhlab query bunny.obj bunny.obj --normalize --protocol 1.0,200 --bv obb --wide --repeat 20\n"
      "  bvhlab query scan.xyz pinion.off --cloud a --pose 0.5,0,0 --strategy adb --p-min 0.99");
  return {query, [args] { return query_command(*args); }};
}

}  // namespace bvhlab::cli
