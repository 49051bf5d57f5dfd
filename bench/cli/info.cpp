// bvhlab info: what a mesh file holds, or what a saved tree's header says.
#include "bench/cli/cli.hpp"
#include "bvh/mesh_io.hpp"
#include "bvh/point_cloud.hpp"
#include "engine/content_hash.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <iostream>
#include <memory>

namespace bvhlab::cli {
namespace {

namespace fs = std::filesystem;

struct InfoArgs {
  std::string mesh;
  bool json = false;
};

void print_saved_tree(const std::string& file, bool json) {
  const SavedTreeInfo t = peek_saved_tree(file);
  if (json) {
    nlohmann::json j = {{"file", file},
                        {"saved_tree", true},
                        {"bv", t.bv},
                        {"density", t.density},
                        {"annotation", t.annotation},
                        {"nodes", t.nodes},
                        {"triangles", t.triangles},
                        {"normalized", t.units.normalized}};
    if (t.units.normalized)
      j["normalization"] = {{"scale", t.units.scale},
                            {"centre", {t.units.centre.x(), t.units.centre.y(), t.units.centre.z()}}};
    std::cout << j.dump(2) << '\n';
    return;
  }
  std::printf("%s (saved tree)\n  bv              %s\n  nodes           %ju\n  triangles       %ju\n",
              file.c_str(), t.bv.c_str(), std::uintmax_t(t.nodes), std::uintmax_t(t.triangles));
  std::printf("  annotation      %s\n", t.annotation.c_str());
  std::printf("  units           %s\n", t.units.describe().c_str());
}

void print_mesh_json(const fs::path& path, const LoadedMesh& loaded, const std::string& checksum) {
  const LoadReport& r = loaded.report;
  const Box& b = r.bounds;
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
}

void print_mesh_text(const fs::path& path, const LoadedMesh& loaded, const std::string& checksum) {
  const LoadReport& r = loaded.report;
  const Box& b = r.bounds;
  std::printf("%s\n  triangles       %zu\n  vertices        %zu (from %zu before joining equal ones)\n",
              path.c_str(), loaded.mesh.triangle_count(), loaded.mesh.vertices.size(), r.input_vertices);
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

/// A point cloud file (a PLY without faces, XYZ): its points, normals, bounds and checksum.
void print_cloud(const fs::path& path, const PointCloud& cloud, const std::string& checksum, bool json) {
  const Box b = cloud.bounds();
  if (json) {
    std::cout << nlohmann::json{{"file", path.string()},
                                {"point_cloud", true},
                                {"points", cloud.size()},
                                {"normals", cloud.has_normals()},
                                {"bounds_min", {b.min.x(), b.min.y(), b.min.z()}},
                                {"bounds_max", {b.max.x(), b.max.y(), b.max.z()}},
                                {"checksum", checksum}}
                     .dump(2)
              << '\n';
    return;
  }
  std::printf("%s (point cloud)\n  points          %zu\n  normals         %s\n", path.c_str(), cloud.size(),
              cloud.has_normals() ? "yes" : "no");
  std::printf("  bounds          [%g, %g] x [%g, %g] x [%g, %g]\n", b.min.x(), b.max.x(), b.min.y(),
              b.max.y(), b.min.z(), b.max.z());
  const Vec3 e = b.extent();
  std::printf("  size            %g x %g x %g\n  checksum        %s\n", e.x(), e.y(), e.z(),
              checksum.c_str());
}

int info_command(const InfoArgs& args) {
  if (fs::is_regular_file(args.mesh) && is_saved_tree(args.mesh)) {
    print_saved_tree(args.mesh, args.json);
    return 0;
  }
  const fs::path path = resolve_mesh_argument(args.mesh);
  if (is_point_cloud_file(path)) {
    print_cloud(path, load_point_cloud(path), ContentHash::to_hex(hash_file(path)), args.json);
    return 0;
  }
  const LoadedMesh loaded = load_mesh(path);
  const std::string checksum = ContentHash::to_hex(hash_file(path));
  if (args.json)
    print_mesh_json(path, loaded, checksum);
  else
    print_mesh_text(path, loaded, checksum);
  return 0;
}

}  // namespace

Command add_info_command(CLI::App& app) {
  auto args = std::make_shared<InfoArgs>();
  auto* info = app.add_subcommand(
      "info", "Triangles, degenerate triangles, bounds and checksum of a mesh (or the points of a cloud)");
  info->add_option(
          "MESH", args->mesh,
          "Mesh file or catalog name, a point cloud (a PLY without faces, XYZ), or a saved tree (its "
          "header)")
      ->required();
  info->add_flag("--json", args->json, "Print JSON");
  info->footer("Example: bvhlab info meshes/pinion.off");
  return {info, [args] { return info_command(*args); }};
}

}  // namespace bvhlab::cli
