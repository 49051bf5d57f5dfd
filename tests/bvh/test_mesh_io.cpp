// Mesh loading: real bundled meshes, welding, merging, node transforms, every refused input, normalisation.
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace bvhlab {
namespace {

namespace fs = std::filesystem;
using testing::bundled_mesh;

// Each test writes its inputs into its own directory, removed afterwards.
class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("bvhlab_mesh_io_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path write(const std::string& name, const std::string& content) const {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << content;
    return path;
  }

  // Loads `path` expecting a MeshError whose message names the file and contains `problem`.
  static void expect_refused(const fs::path& path, const std::string& problem) {
    try {
      const auto loaded = load_mesh(path);
      ADD_FAILURE() << path << " was accepted with " << loaded.mesh.triangle_count() << " triangles";
    } catch (const MeshError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path.filename().string()), std::string::npos) << message;
      EXPECT_NE(message.find(problem), std::string::npos) << "expected '" << problem << "' in: " << message;
    }
  }

  fs::path dir_;
};

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void expect_valid_indices(const Mesh& mesh) {
  for (const auto& t : mesh.triangles)
    for (const auto v : t) ASSERT_LT(v, mesh.vertices.size());
}

// How many triangles use each undirected edge.
std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_uses(const Mesh& mesh) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  return uses;
}

// ---------------------------------------------------------------------------------------------------------
// Real meshes

TEST_F(MeshIo, BundledMeshesHaveTheDocumentedTriangleCounts) {
  const std::vector<std::pair<std::string, std::size_t>> expected = {
      {"pinion.off", 1300}, {"jeep1.ms3d", 2032}, {"teapot.obj", 6320}};
  for (const auto& [file, triangles] : expected) {
    SCOPED_TRACE(file);
    const LoadedMesh loaded = load_mesh(bundled_mesh(file));
    EXPECT_EQ(loaded.mesh.triangle_count(), triangles);
    EXPECT_EQ(loaded.mesh.name, fs::path(file).stem().string());
    EXPECT_LE(loaded.mesh.vertices.size(), loaded.report.input_vertices);
    EXPECT_GE(loaded.report.submeshes, 1u);
    EXPECT_FALSE(loaded.report.bounds.empty());
    EXPECT_TRUE(loaded.report.bounds.min.allFinite() && loaded.report.bounds.max.allFinite());
    expect_valid_indices(loaded.mesh);
  }
}

// pinion.off's header says 650 vertices, 1300 faces, 1950 edges, and the gear is closed.
TEST_F(MeshIo, PinionIsClosedWithTheHeadersCounts) {
  const LoadedMesh loaded = load_mesh(bundled_mesh("pinion.off"));
  EXPECT_EQ(loaded.mesh.vertices.size(), 650u);
  const auto uses = edge_uses(loaded.mesh);
  EXPECT_EQ(uses.size(), 1950u);
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 2) << edge.first << "-" << edge.second;
  EXPECT_EQ(loaded.report.degenerate_triangles, 0u);
}

// assimp's OBJ reader hands over one vertex per face corner (18,960 for the teapot); only a correct weld
// gives back the shared edges, leaving the 160 boundary edges meshes/README.md documents.
TEST_F(MeshIo, WeldRestoresTheTeapotsEdgeGraph) {
  const LoadedMesh loaded = load_mesh(bundled_mesh("teapot.obj"));
  EXPECT_EQ(loaded.report.input_vertices, 3 * loaded.mesh.triangle_count());
  EXPECT_LT(loaded.mesh.vertices.size(), loaded.report.input_vertices / 4);
  std::size_t boundary = 0;
  for (const auto& [edge, count] : edge_uses(loaded.mesh)) boundary += count == 1;
  EXPECT_EQ(boundary, 160u);
}

TEST_F(MeshIo, Jeep1MergesItsSubMeshes) {
  const LoadedMesh loaded = load_mesh(bundled_mesh("jeep1.ms3d"));
  EXPECT_GT(loaded.report.submeshes, 1u);  // the MS3D file has several groups
}

// ---------------------------------------------------------------------------------------------------------
// Welding, merging, transforms

TEST_F(MeshIo, WeldJoinsTheUnsharedVerticesOfStl) {
  // Two triangles of a unit square: STL stores 6 corners for 4 distinct points.
  const auto path =
      write("square.stl",
            "solid square\n"
            " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 0\n"
            "  endloop\n endfacet\n"
            " facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n"
            "  endloop\n endfacet\n"
            "endsolid square\n");
  const LoadedMesh loaded = load_mesh(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 2u);
  EXPECT_EQ(loaded.report.input_vertices, 6u);
  EXPECT_EQ(loaded.mesh.vertices.size(), 4u);
  const auto uses = edge_uses(loaded.mesh);
  EXPECT_EQ(uses.size(), 5u);  // the diagonal is shared
  EXPECT_EQ(loaded.mesh.name, "square");
}

TEST_F(MeshIo, WeldTreatsNegativeZeroAsZero) {
  const auto path =
      write("signed_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -0 -0 -0\nv 0 -1 0\nf 1 2 3\nf 4 5 2\n");
  const LoadedMesh loaded = load_mesh(path);
  EXPECT_EQ(loaded.mesh.vertices.size(), 4u);
}

TEST_F(MeshIo, SubMeshesAreMergedAndPolygonsTriangulated) {
  const auto path = write("two_objects.obj",
                          "o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
                          "o second\nv 0 0 5\nv 1 0 5\nv 1 1 5\nv 0 1 5\nf 4 5 6 7\n");
  const LoadedMesh loaded = load_mesh(path);
  EXPECT_EQ(loaded.report.submeshes, 2u);
  EXPECT_EQ(loaded.mesh.triangle_count(), 3u);  // the quad becomes two
  EXPECT_EQ(loaded.mesh.vertices.size(), 7u);
  EXPECT_DOUBLE_EQ(loaded.report.bounds.min.z(), 0.0);
  EXPECT_DOUBLE_EQ(loaded.report.bounds.max.z(), 5.0);
  expect_valid_indices(loaded.mesh);
}

// One triangle (0,0,0) (1,0,0) (0,1,0) in an embedded glTF buffer, instanced by two nodes: one translated,
// one mirrored in x (its winding must be flipped so the normal keeps pointing the same way as the
// original's).
std::string gltf_two_instances() {
  return R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0, 1]}],
  "nodes": [{"mesh": 0, "translation": [10, 20, 30]}, {"mesh": 0, "scale": [-1, 1, 1]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "buffers": [{"byteLength": 44,
    "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA="}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]
})";
}

TEST_F(MeshIo, NodeTransformsAreAppliedPerInstance) {
  const LoadedMesh loaded = load_mesh(write("instances.gltf", gltf_two_instances()));
  ASSERT_EQ(loaded.mesh.triangle_count(), 2u);
  EXPECT_EQ(loaded.report.submeshes, 2u);
  std::set<std::vector<double>> points;
  for (const auto& v : loaded.mesh.vertices) points.insert({v.x(), v.y(), v.z()});
  const std::set<std::vector<double>> expected = {{10, 20, 30}, {11, 20, 30}, {10, 21, 30},
                                                  {0, 0, 0},    {-1, 0, 0},   {0, 1, 0}};
  EXPECT_EQ(points, expected);
  for (std::size_t i = 0; i < 2; ++i) {
    const auto t = loaded.mesh.triangle(i);
    const Vec3 normal = (t[1] - t[0]).cross(t[2] - t[0]);
    EXPECT_GT(normal.z(), 0) << "triangle " << i << " turned inside out";
  }
}

TEST_F(MeshIo, MemoryLoadingMatchesFileLoading) {
  const fs::path file = bundled_mesh("teapot.obj");
  const std::string bytes = read_all(file);
  const auto span = std::as_bytes(std::span(bytes.data(), bytes.size()));
  const LoadedMesh from_memory = load_mesh_from_memory(span, ".obj", "teapot.obj");
  const LoadedMesh from_file = load_mesh(file);
  EXPECT_EQ(from_memory.mesh.name, "teapot");
  EXPECT_EQ(from_memory.mesh.triangles, from_file.mesh.triangles);
  EXPECT_EQ(from_memory.mesh.vertices, from_file.mesh.vertices);
}

TEST_F(MeshIo, MemoryLoadingRefusesEmptyAndGarbageBuffers) {
  EXPECT_THROW(load_mesh_from_memory({}, "obj", "nothing.obj"), MeshError);
  const std::string garbage = "ply\nthis is not a header\n\x01\x02\x03";
  try {
    load_mesh_from_memory(std::as_bytes(std::span(garbage.data(), garbage.size())), "ply", "junk.ply");
    ADD_FAILURE() << "garbage accepted";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.ply"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------------------
// Refused input

TEST_F(MeshIo, MissingFileIsRefused) {
  expect_refused(dir_ / "does_not_exist.obj", "not found");
}

TEST_F(MeshIo, DirectoryIsRefused) {
  fs::create_directories(dir_ / "folder.obj");
  expect_refused(dir_ / "folder.obj", "directory");
}

TEST_F(MeshIo, EmptyFileIsRefused) {
  expect_refused(write("empty.obj", ""), "empty");
}

TEST_F(MeshIo, GarbageBytesAreRefused) {
  std::string garbage;
  for (int i = 0; i < 512; ++i) garbage.push_back(static_cast<char>((i * 7919 + 13) % 256));
  expect_refused(write("garbage.bin", garbage), "unknown or unsupported file format");
  expect_refused(write("garbage.ply", garbage), "not a PLY file");
  expect_refused(write("garbage.stl", garbage), "assimp could not read it");
}

TEST_F(MeshIo, NanCoordinateIsRefusedWithItsVertex) {
  const auto path = write("nan.obj", "v 0 0 0\nv 1 0 0\nv nan 0 0\nf 1 2 3\n");
  expect_refused(path, "NaN or infinite coordinate");
  expect_refused(path, "at vertex 2");
}

TEST_F(MeshIo, InfiniteCoordinateIsRefused) {
  expect_refused(write("inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n"), "NaN or infinite coordinate");
  expect_refused(write("minus_inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"), "NaN or infinite");
}

TEST_F(MeshIo, OutOfRangeIndexIsRefused) {
  // OBJ: assimp itself fails.
  expect_refused(write("oor.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n"), "out of range");
  // PLY: assimp passes the index through; the loader's own check catches it.
  expect_refused(
      write("oor.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n"),
      "index out of range");
  // OFF: assimp only logs the bad index and substitutes another vertex; the log must turn it into an error.
  expect_refused(write("oor.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"), "index out of range");
}

TEST_F(MeshIo, PointsAndLinesOnlyIsRefused) {
  const auto path = write("wire.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1\nl 1 2\nl 2 3\n");
  expect_refused(path, "no triangles");
  expect_refused(path, "1 point and 2 line primitives");
}

TEST_F(MeshIo, PointsAndLinesBesideTrianglesAreDroppedAndCounted) {
  const LoadedMesh loaded =
      load_mesh(write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 50 50 50\nf 1 2 3\np 4\nl 1 4\n"));
  EXPECT_EQ(loaded.mesh.triangle_count(), 1u);
  EXPECT_EQ(loaded.report.ignored_points, 1u);
  EXPECT_EQ(loaded.report.ignored_lines, 1u);
  // The stray point is not part of the triangle mesh and must not stretch its bounds.
  EXPECT_EQ(loaded.mesh.vertices.size(), 3u);
  EXPECT_DOUBLE_EQ(loaded.report.bounds.max.x(), 1.0);
}

TEST_F(MeshIo, HugeCoordinatesAreRefused) {
  expect_refused(write("huge.obj", "v 0 0 0\nv 1e16 0 0\nv 0 1 0\nf 1 2 3\n"), "coordinates too large");
}

TEST_F(MeshIo, ZeroSizeModelIsRefused) {
  expect_refused(write("point.obj", "v 3 3 3\nv 3 3 3\nv 3 3 3\nf 1 2 3\n"), "zero size");
}

TEST_F(MeshIo, FarOffsetSmallModelWarns) {
  // Size ~1.4 at 1e7 from the origin: ratio 7e6 > 1e6. (assimp parses into float, whose spacing at 1e7 is
  // exactly 1, so the file cannot place a smaller model further out.)
  const LoadedMesh far = load_mesh(write("far.obj", "v 1e7 0 0\nv 10000001 0 0\nv 1e7 1 0\nf 1 2 3\n"));
  EXPECT_EQ(far.mesh.vertices.size(), 3u);
  bool warned = false;
  for (const auto& w : far.report.warnings) warned |= w.find("far from the origin") != std::string::npos;
  EXPECT_TRUE(warned);

  const LoadedMesh near = load_mesh(bundled_mesh("pinion.off"));
  EXPECT_TRUE(near.report.warnings.empty()) << near.report.warnings.front();
}

// ---------------------------------------------------------------------------------------------------------
// Degenerate triangles are kept and counted

TEST_F(MeshIo, DegenerateTrianglesAreKeptAndCounted) {
  const auto path = write("degenerate.obj",
                          "v 0 0 0\nv 1 0 0\nv 0 1 0\n"             // 1-3: a proper triangle
                          "v 1 2 3\nv 2 4 6\nv 3 6 9\n"             // 4-6: exactly collinear
                          "v 5 5 5\nv 5 5 5\nv 6 5 5\n"             // 7-9: 7 and 8 weld together
                          "v 0 0 0.5\nv 1 1 0.5\nv 2 2 0.500001\n"  // 10-12: nearly, not exactly, collinear
                          "f 1 2 3\nf 4 5 6\nf 7 8 9\nf 1 1 2\nf 10 11 12\n");
  const LoadedMesh loaded = load_mesh(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 5u);
  EXPECT_EQ(loaded.report.degenerate_triangles, 3u);
}

// ---------------------------------------------------------------------------------------------------------
// Normalisation

TEST_F(MeshIo, NormalisationCentresAndScalesLongestSideToTwo) {
  LoadedMesh loaded = load_mesh(bundled_mesh("jeep1.ms3d"));
  const Box before = loaded.mesh.bounds();
  const double scale = normalize_to_unit_cube(loaded.mesh);
  const Box after = loaded.mesh.bounds();
  EXPECT_NEAR(after.center().norm(), 0.0, 1e-12);
  EXPECT_NEAR(after.extent().maxCoeff(), 2.0, 1e-12);
  EXPECT_NEAR(scale, 2.0 / before.extent().maxCoeff(), 1e-12 * scale);
  // Uniform: the proportions of the box stay.
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(after.extent()[axis], before.extent()[axis] * scale, 1e-12) << "axis " << axis;
}

TEST_F(MeshIo, NormalisationRefusesEmptyAndPointMeshes) {
  Mesh empty;
  empty.name = "empty";
  EXPECT_THROW(normalize_to_unit_cube(empty), MeshError);
  Mesh point;
  point.name = "point";
  point.vertices = {Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3)};
  point.triangles = {{0, 1, 2}};
  EXPECT_THROW(normalize_to_unit_cube(point), MeshError);
}

}  // namespace
}  // namespace bvhlab
