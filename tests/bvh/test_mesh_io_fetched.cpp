// Mesh loading on a fetched mesh (meshes/fetch.sh): runs after the ctest fixture `meshes`.
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

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

// Counts from meshes/README.md; the big dragon's 108 degenerate triangles check welding and the exact
// collinearity test on real data. About 1 s for all six.
TEST(MeshIoFetched, AllFetchedMeshesHaveTheDocumentedTriangleCounts) {
  const std::vector<std::pair<std::string, std::size_t>> expected = {
      {"injector_pipes.stl", 15088}, {"occt_tr12j_housing.stl", 67498}, {"bunny.obj", 69666},
      {"motorBike.obj", 331653},     {"dragon_871k.ply", 871414},       {"dragon_11k.ply", 11102}};
  for (const auto& [file, triangles] : expected) {
    SCOPED_TRACE(file);
    const LoadedMesh loaded = load_mesh(testing::fetched_mesh(file));
    EXPECT_EQ(loaded.mesh.triangle_count(), triangles);
    EXPECT_TRUE(loaded.report.warnings.empty());
    if (file == "dragon_871k.ply") {
      EXPECT_EQ(loaded.report.degenerate_triangles, 108u);
    }
  }
}

}  // namespace
}  // namespace bvhlab
