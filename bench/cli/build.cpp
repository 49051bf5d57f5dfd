// bvhlab build: builds (and optionally annotates) one mesh's tree and saves it without polygons.
#include "bench/cli/cli.hpp"
#include "bench/core/registry.hpp"

#include <cstdint>
#include <cstdio>
#include <memory>

namespace bvhlab::cli {
namespace {

struct BuildArgs {
  std::string mesh, output, bv = "aabb", split = "sah", density = "none";
  unsigned leaf = 1, threads = 0;
  bool adb = false, raw = false;
  ParameterOptions parameters;
};

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

int build_command(const BuildArgs& args) {
  const std::string density_name = args.adb ? "adb" : args.density;
  args.parameters.refuse_others({&density_info(density_name).parameters}, "density " + density_name);
  const DensitySpec density = density_from(density_name, args.parameters);
  const SceneObject object = object_for(args.mesh, !args.raw);
  HierarchySpec h;
  h.bv = h.name = args.bv;
  h.build.split = split_method_from_string(args.split);
  h.build.max_leaf_triangles = args.leaf;
  const BuildOutcome outcome =
      build_tree_file(object, h, density, args.output, args.threads,
                      [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); });
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
  build->add_flag("--no-normalize", args->raw,
                  "Keep the mesh's coordinates (default: the protocol normalisation)");
  build->add_option("--threads", args->threads, "Threads (0: all)");
  build->add_option("-o,--output", args->output, "Saved tree file")->required();
  build->footer("Example: bvhlab build jeep1.ms3d --bv aabb --adb -o jeep1-aabb-adb2.tree");
  return {build, [args] { return build_command(*args); }};
}

}  // namespace bvhlab::cli
