#include "bvh/mesh_io.hpp"

namespace bvhlab {
// Placeholder: the assimp loader lands with the mesh-loading work.
LoadedMesh load_mesh(const std::filesystem::path& path) { throw MeshError(path.string() + ": loader not implemented"); }
LoadedMesh load_mesh_from_memory(std::span<const std::byte>, std::string_view, std::string_view name) {
  throw MeshError(std::string(name) + ": loader not implemented");
}
double normalize_to_unit_cube(Mesh& mesh) {
  const Box b = mesh.bounds();
  if (b.empty()) throw MeshError(mesh.name + ": empty mesh");
  const double longest = b.extent().maxCoeff();
  if (!(longest > 0)) throw MeshError(mesh.name + ": all vertices coincide");
  const double scale = 2.0 / longest;
  const Vec3 c = b.center();
  for (auto& v : mesh.vertices) v = (v - c) * scale;
  return scale;
}
}  // namespace bvhlab
