// bvhlab build: builds (and optionally annotates) one mesh's tree and saves it without polygons.
#include "bench/cli/cli.hpp"
#include "engine/specs.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>

namespace bvhlab::cli {
namespace {

struct BuildArgs {
  std::string mesh, output, bv = "aabb", split = "sah", density = "none";
  unsigned leaf = 1, threads = 0;
  bool adb = false, normalize = false;
  ParameterOptions parameters;
};

void print_model(const ModelInfo& m) {
  std::printf("  hierarchy       %s (%s)%s\n", m.hierarchy.c_str(), m.bv.c_str(),
              m.from_cache ? ", from the cache" : "");
  std::printf("  annotation      %s\n", m.annotation.c_str());
  std::printf("  units           %s\n", m.units.describe().c_str());
  std::printf("  triangles       %zu\n  nodes           %zu\n  depth           %zu\n", m.triangles, m.nodes,
              m.depth);
  std::printf("  bytes/triangle  %.2f (%.0f bytes without polygons)\n", m.bytes_per_triangle, m.model_bytes);
  std::printf("  build time      %.3f s\n", m.build_seconds);
  if (m.annotation != "none") std::printf("  annotation time %.3f s\n", m.annotate_seconds);
}

/// A saved tree has no polygons: refuses a density that no registered strategy could query without them.
void refuse_unqueryable(const std::string& density) {
  const auto& strategies = strategy_table();
  if (std::any_of(strategies.begin(), strategies.end(),
                  [&](const StrategyInfo& s) { return !s.needs_polygons && s.accepts(density); }))
    return;
  std::vector<std::string> usable;
  for (const StrategyInfo& s : strategies)
    if (!s.needs_polygons)
      for (const std::string& d : s.densities)
        if (std::find(usable.begin(), usable.end(), d) == usable.end()) usable.push_back(d);
  throw CLI::ValidationError(
      "--density " + density,
      "a saved tree carries no polygons, and no strategy queries a tree with density " + density +
          " without them (the exact ones test triangles: query the meshes instead); build with " +
          (usable.empty() ? std::string("a density some strategy can use") : "--density " + join(usable)) +
          (std::find(usable.begin(), usable.end(), "adb") != usable.end() ? " (--adb)" : ""));
}

int build_command(const BuildArgs& args) {
  check_output_file("--output", args.output);
  const std::string density_name = args.adb ? "adb" : args.density;
  args.parameters.refuse_others({&density_info(density_name).parameters}, "density " + density_name);
  refuse_unqueryable(density_name);
  const DensitySpec density = density_from(density_name, args.parameters);
  const SceneObject object = object_for(args.mesh, args.normalize);
  HierarchySpec h;
  h.bv = h.name = args.bv;
  h.build.split = split_method_from_string(args.split);
  h.build.max_leaf_triangles = args.leaf;
  const BuildOutcome outcome =
      build_tree_file(object, h, density, args.output, args.threads,
                      [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
  if (outcome.model.units.normalized)
    std::fprintf(stderr, "bvhlab: %s %s\n", object.name.c_str(), outcome.model.units.describe().c_str());
  std::printf("%s -> %s (%ju bytes)\n", object.path.c_str(), args.output.c_str(), outcome.file_bytes);
  print_model(outcome.model);
  return 0;
}

}  // namespace

Command add_build_command(CLI::App& app) {
  auto args = std::make_shared<BuildArgs>();
  auto* build =
      app.add_subcommand("build", "Build (and optionally annotate) a tree and save it without polygons");
  build->add_option("MESH", args->mesh, "Mesh file or catalog name")->required();
  build->add_option("--bv", args->bv, "Bounding volume")
      ->check(CLI::IsMember(volume_names()))
      ->capture_default_str();
  build->add_option("--split", args->split, "Split method")
      ->check(CLI::IsMember({"sah", "median"}))
      ->capture_default_str();
  build->add_option("--leaf", args->leaf, "Triangles per leaf at most")
      ->check(CLI::Range(1, 255))
      ->capture_default_str();
  auto* density_option =
      build->add_option("--density", args->density, "Density annotation (`bvhlab policies`)")
          ->check(CLI::IsMember(density_names()))
          ->capture_default_str();
  build->add_flag("--adb", args->adb, "Short for --density adb (CGAL clipping)")->excludes(density_option);
  for (const DensityInfo& d : density_table()) args->parameters.add(build, d.parameters, "density " + d.name);
  args->parameters.finish_help();
  build->add_flag(
      "--normalize", args->normalize,
      "Apply the protocol normalisation (centre to the origin, longest side 2; recorded in the tree); "
      "default: the mesh file's own units");
  build->add_option("--threads", args->threads, "Threads (0: all)");
  build->add_option("-o,--output", args->output, "Saved tree file")->required();
  build->footer("Example: bvhlab build jeep1.ms3d --bv aabb --adb -o jeep1-aabb-adb2.tree");
  return {build, [args] { return build_command(*args); }};
}

}  // namespace bvhlab::cli
