// Mesh loading on a fetched mesh (meshes/fetch.sh): runs after the ctest fixture `meshes`.
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

namespace bvhlab {
namespace {

TEST(MeshIoFetched, Dragon11kHasTheDocumentedTriangleCount) {
  const auto path = testing::fetched_mesh("dragon_11k.ply");
  const LoadedMesh loaded = load_mesh(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 11102u);
  EXPECT_EQ(loaded.mesh.name, "dragon_11k");

  // The PLY header's vertex count bounds the welded count from above.
  std::ifstream in(path);
  std::string line;
  std::size_t header_vertices = 0;
  while (std::getline(in, line) && line.rfind("end_header", 0) != 0)
    if (line.rfind("element vertex ", 0) == 0) header_vertices = std::stoul(line.substr(15));
  ASSERT_GT(header_vertices, 0u);
  EXPECT_LE(loaded.mesh.vertices.size(), header_vertices);
  for (const auto& t : loaded.mesh.triangles)
    for (const auto v : t) ASSERT_LT(v, loaded.mesh.vertices.size());
}

}  // namespace
}  // namespace bvhlab
