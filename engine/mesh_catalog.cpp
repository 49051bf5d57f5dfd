#include "engine/mesh_catalog.hpp"

#include "bvh/mesh_io.hpp"

#include <cstdlib>
#include <stdexcept>

namespace bvhlab {

std::optional<std::filesystem::path> find_mesh(const std::string& file_name) {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("BVHLAB_MESH_CACHE")) dirs.emplace_back(env);
  dirs.emplace_back(BVHLAB_DEFAULT_MESH_CACHE);
  dirs.emplace_back(std::filesystem::path(BVHLAB_SOURCE_DIR) / "meshes");
  for (const auto& dir : dirs) {
    const auto candidate = dir / file_name;
    if (std::filesystem::is_regular_file(candidate)) return candidate;
  }
  return std::nullopt;
}

Mesh load_protocol_mesh(const std::string& file_name) {
  const auto path = find_mesh(file_name);
  if (!path)
    throw std::runtime_error(
        "mesh '" + file_name +
        "' not found in the mesh cache or meshes/ (run meshes/fetch.sh or `cmake --build "
        "<build> --target fetch_meshes`)");
  Mesh mesh = load_mesh(*path).mesh;
  normalize_to_unit_cube(mesh);
  return mesh;
}

TreeUnits normalize_mesh(Mesh& mesh) {
  TreeUnits units;
  units.centre = mesh.bounds().center();  // what normalize_to_unit_cube moves to the origin
  units.scale = normalize_to_unit_cube(mesh);
  units.normalized = true;
  return units;
}

}  // namespace bvhlab
