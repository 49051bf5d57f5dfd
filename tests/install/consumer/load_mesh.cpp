// Loads a tetrahedron from memory through the installed mesh loader and builds a tree over it.
#include <bvhlab/bvh/bvh.hpp>
#include <bvhlab/bvh/mesh_io.hpp>
#include <bvhlab/volumes/aabb.hpp>

#include <cstdio>
#include <span>
#include <string_view>

int main() {
  using namespace bvhlab;
  constexpr std::string_view off =
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  const LoadedMesh loaded = load_mesh_from_memory(std::as_bytes(std::span(off.data(), off.size())), "off");
  const auto tree = Bvh<Aabb>::build(loaded.mesh);
  std::printf("loaded %zu triangles, %zu nodes\n", loaded.mesh.triangle_count(), tree.nodes().size());
  return loaded.mesh.triangle_count() == 4 && !tree.nodes().empty() ? 0 : 1;
}
