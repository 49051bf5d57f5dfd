// Point clouds: validation, the PLY and XYZ readers, deterministic sampling, k-NN areas, and trees over
// points for every shipped volume.
#include "bvh/bvh.hpp"
#include "bvh/mesh_io.hpp"
#include "bvh/point_cloud.hpp"
#include "support/errors.hpp"
#include "support/meshes.hpp"
#include "support/volume_lists.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <numeric>

namespace bvhlab {
namespace {

using testing::error_of;

PointCloud from_text(const std::string& text, std::string_view format) {
  return load_point_cloud_from_memory(std::as_bytes(std::span(text.data(), text.size())), format, "test");
}

Mesh pinion() {
  return load_mesh(testing::bundled_mesh("pinion.off")).mesh;
}

TEST(PointCloudValidate, RefusesBadCloudsByName) {
  PointCloud c;
  c.name = "c";
  EXPECT_NE(error_of([&] { validate(c); }).find("has no points"), std::string::npos);
  c.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, std::nan(""), 0)};
  EXPECT_NE(error_of([&] { validate(c); }).find("point 2 is not finite"), std::string::npos);
  c.positions[2] = Vec3(0, 2e15, 0);  // where a double's spacing is 0.25: refused as for meshes
  EXPECT_NE(error_of([&] { validate(c); }).find("point 2 has a coordinate beyond 1e15"), std::string::npos);
  c.positions[2] = Vec3(0, 1, 0);
  EXPECT_NO_THROW(validate(c, 3));
  EXPECT_NE(error_of([&] { validate(c, 11); }).find("has 3 points, the kernel needs at least 11"),
            std::string::npos);
  c.positions.assign(5, Vec3(1, 2, 3));
  EXPECT_NE(error_of([&] { validate(c); }).find("all 5 points are coincident"), std::string::npos);
  c.positions[4] = Vec3(1, 2, 4);
  c.normals.assign(3, Vec3(0, 0, 1));
  EXPECT_NE(error_of([&] { validate(c); }).find("3 normals for 5 points"), std::string::npos);
  c.normals.clear();
  c.areas.assign(5, 1.0);
  c.areas[3] = -1;
  EXPECT_NE(error_of([&] { validate(c); }).find("area 3"), std::string::npos);
}

TEST(PointCloudLoad, ReadsXyzWithAndWithoutNormals) {
  const PointCloud a = from_text("# comment\n0 0 0\n1 2 3\n\n-4.5 +5e-1 6\n", "xyz");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_FALSE(a.has_normals());
  EXPECT_EQ(a.positions[2], Vec3(-4.5, 0.5, 6));
  const PointCloud b = from_text("0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n", "xyz");
  ASSERT_EQ(b.size(), 2u);
  ASSERT_TRUE(b.has_normals());
  EXPECT_EQ(b.normals[1], Vec3(0, 0, 1));
}

TEST(PointCloudLoad, RefusesBadXyzLinesByNumber) {
  EXPECT_NE(error_of([] { from_text("0 0 0\n1 x 0\n", "xyz"); }).find("line 2: not a list of numbers"),
            std::string::npos);
  EXPECT_NE(error_of([] { from_text("0 0 0\n\n1 0\n", "xyz"); }).find("line 3: 2 numbers"),
            std::string::npos);
  EXPECT_NE(error_of([] { from_text("0 0 0\n1 0 0 0 0 1\n", "xyz"); }).find("earlier lines have 3"),
            std::string::npos);
  EXPECT_NE(error_of([] { from_text("0 0 0\nnan 0 0\n", "xyz"); }).find("point 1 is not finite"),
            std::string::npos);
  EXPECT_NE(error_of([] { from_text("# nothing\n", "xyz"); }).find("has no points"), std::string::npos);
}

std::string ply_header(const std::string& format, std::size_t n, bool normals, const std::string& type,
                       const std::string& extra = "") {
  std::string h = "ply\nformat " + format + " 1.0\ncomment test\nelement vertex " + std::to_string(n) + "\n";
  for (const char* p : {"x", "y", "z"}) h += "property " + type + " " + p + "\n";
  h += extra;
  if (normals)
    for (const char* p : {"nx", "ny", "nz"}) h += "property " + type + " " + p + "\n";
  return h + "end_header\n";
}

TEST(PointCloudLoad, ReadsAsciiPlyAndSkipsFacesAndOtherProperties) {
  const std::string text = ply_header("ascii", 3, true, "float", "property uchar red\n") +
                           "0 0 0 255 0 0 1\n1 0 0 0 0 0 1\n0 1 0 7 0 0 -1\n";
  const PointCloud c = from_text(text, "ply");
  ASSERT_EQ(c.size(), 3u);
  ASSERT_TRUE(c.has_normals());
  EXPECT_EQ(c.positions[1], Vec3(1, 0, 0));
  EXPECT_EQ(c.normals[2], Vec3(0, 0, -1));
  // A mesh PLY: the vertices are the cloud, the faces are not read.
  const std::string mesh =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const PointCloud m = from_text(mesh, "ply");
  EXPECT_EQ(m.size(), 3u);
  EXPECT_FALSE(m.has_normals());
}

template <class T>
void append(std::string& s, T value, bool big) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  s.append(b, sizeof(T));
}

TEST(PointCloudLoad, ReadsBinaryPlyInBothByteOrders) {
  for (bool big : {false, true}) {
    std::string text = ply_header(big ? "binary_big_endian" : "binary_little_endian", 2, false, "double",
                                  "property short s\n");
    for (int v = 0; v < 2; ++v) {
      append<double>(text, 1.5 + v, big);
      append<double>(text, -2.0, big);
      append<double>(text, 1e-3 * v, big);
      append<std::int16_t>(text, -7, big);
    }
    const PointCloud c = from_text(text, "ply");
    ASSERT_EQ(c.size(), 2u) << big;
    EXPECT_EQ(c.positions[1], Vec3(2.5, -2.0, 1e-3)) << big;
    // Truncated body: refused with the counts.
    EXPECT_NE(error_of([&] {
                from_text(text.substr(0, text.size() - 1), "ply");
              }).find("the body holds 1 vertices, the header declares 2"),
              std::string::npos);
  }
}

TEST(PointCloudLoad, RefusesBadPlyHeaders) {
  EXPECT_NE(error_of([] { from_text("plx\n", "ply"); }).find("not a PLY file"), std::string::npos);
  EXPECT_NE(error_of([] {
              from_text("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "ply");
            }).find("no end_header"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              from_text("ply\nformat ascii 1.0\nelement face 1\nend_header\n", "ply");
            }).find("expected 'vertex'"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              from_text(ply_header("ascii", 1, false, "flaot") + "0 0 0\n", "ply");
            }).find("unknown property type 'flaot'"),
            std::string::npos);
  const std::string some_normals =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nend_header\n0 0 0 1\n";
  EXPECT_NE(error_of([&] { from_text(some_normals, "ply"); }).find("not all three"), std::string::npos);
  EXPECT_NE(error_of([] {
              from_text(ply_header("ascii", 2, false, "float") + "0 0 0\n", "ply");
            }).find("the body ends after 1 of 2 vertices"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              from_text(ply_header("ascii", 1, false, "float") + "0 0\n", "ply");
            }).find("vertex 0: expected 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of([] { from_text("0 0 0", "pts"); }).find("unknown point cloud format"),
            std::string::npos);
}

TEST(PointCloudLoad, FilesRoundTripAndExtensionsAreChecked) {
  const auto dir = std::filesystem::temp_directory_path() / ("bvhlab_points_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const PointCloud sampled = sample_uniform(pinion(), 200, 3);
  save_point_cloud_ply(sampled, dir / "p.ply");
  const PointCloud back = load_point_cloud(dir / "p.ply");
  EXPECT_EQ(back.name, "p");
  ASSERT_EQ(back.size(), sampled.size());
  ASSERT_TRUE(back.has_normals());
  for (std::size_t i = 0; i < back.size(); ++i) EXPECT_EQ(back.positions[i], sampled.positions[i]);
  EXPECT_NE(error_of([&] { load_point_cloud(dir / "p.txt"); }).find("unknown extension"), std::string::npos);
  EXPECT_NE(error_of([&] { load_point_cloud(dir / "missing.xyz"); }).find("cannot be opened"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

// A cloud file is told from a mesh file by its header alone: XYZ, or a PLY that declares no faces.
TEST(PointCloudLoad, ACloudFileIsAPlyWithoutFacesOrXyz) {
  const auto dir = std::filesystem::temp_directory_path() / ("bvhlab_kind_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return dir / name;
  };
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\n";
  const std::string points = "0 0 0\n1 0 0\n0 1 0\n";
  EXPECT_TRUE(is_point_cloud_file(write("a.ply", header + "end_header\n" + points)));
  EXPECT_TRUE(is_point_cloud_file(write(
      "b.ply", header + "element face 0\nproperty list uchar int vertex_indices\nend_header\n" + points)));
  EXPECT_FALSE(is_point_cloud_file(
      write("c.ply", header + "element face 1\nproperty list uchar int vertex_indices\nend_header\n" +
                         points + "3 0 1 2\n")));
  EXPECT_TRUE(is_point_cloud_file(write("d.xyz", points)));
  EXPECT_FALSE(is_point_cloud_file(write("e.ply", "not a ply\n")));  // the mesh loader names the problem
  EXPECT_FALSE(is_point_cloud_file(write("f.obj", "v 0 0 0\n")));
  EXPECT_FALSE(is_point_cloud_file(dir / "missing.ply"));
  std::filesystem::remove_all(dir);
}

double mesh_area(const Mesh& m) {
  double a = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto p = m.triangle(t);
    a += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
  }
  return a;
}

TEST(PointCloudSample, UniformIsDeterministicOnTheMeshWithItsArea) {
  const Mesh mesh = pinion();
  const PointCloud a = sample_uniform(mesh, 1000, 42), b = sample_uniform(mesh, 1000, 42);
  const PointCloud c = sample_uniform(mesh, 1000, 43);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_NE(a.positions, c.positions);
  ASSERT_EQ(a.areas.size(), 1000u);
  EXPECT_NEAR(std::accumulate(a.areas.begin(), a.areas.end(), 0.0), mesh_area(mesh), 1e-9 * mesh_area(mesh));
  // The first point for seed 42, recorded on x86-64 (GCC 12): the sampling uses its own integer generator and
  // no contraction, so a platform that samples differently fails here.
  EXPECT_EQ(a.positions[0], Vec3(0.22411890212662072, 0.20248716024588684, -0.53957345263386469));
  const Box bounds = mesh.bounds();
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(bounds.contains(a.positions[i])) << i;
    EXPECT_NEAR(a.normals[i].norm(), 1.0, 1e-12);
  }
  EXPECT_THROW(sample_uniform(mesh, 0, 1), std::invalid_argument);
}

TEST(PointCloudSample, VaryingDensityGrowsAlongTheLongestAxis) {
  const Mesh mesh = pinion();
  const PointCloud c = sample_varying(mesh, 4000, 7, 4.0);
  EXPECT_EQ(c.positions, sample_varying(mesh, 4000, 7, 4.0).positions);
  EXPECT_TRUE(c.areas.empty());
  const Box box = mesh.bounds();
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (box.extent()[a] > box.extent()[axis]) axis = a;
  // Points per unit area in the high third against the low third, relative to the uniform sampling.
  const PointCloud u = sample_uniform(mesh, 4000, 7);
  auto thirds = [&](const PointCloud& cloud) {
    std::array<double, 2> n{};
    for (const Vec3& p : cloud.positions) {
      const double t = (p[axis] - box.min[axis]) / box.extent()[axis];
      if (t < 1.0 / 3) n[0] += 1;
      if (t > 2.0 / 3) n[1] += 1;
    }
    return n[1] / n[0];
  };
  // Density 1 + 3t: mean 2.67 in the high third, 1.33 in the low, so about twice the uniform ratio.
  EXPECT_GT(thirds(c) / thirds(u), 1.6);
  EXPECT_LT(thirds(c) / thirds(u), 2.5);
  EXPECT_THROW(sample_varying(mesh, 10, 1, 0.5), std::invalid_argument);
}

TEST(PointCloudSample, KnnAreasAddUpToTheMeshArea) {
  const Mesh mesh = pinion();
  const double area = mesh_area(mesh);
  for (bool varying : {false, true}) {
    PointCloud c = varying ? sample_varying(mesh, 4000, 5, 4.0) : sample_uniform(mesh, 4000, 5);
    assign_knn_areas(c, 10);
    const double total = std::accumulate(c.areas.begin(), c.areas.end(), 0.0);
    EXPECT_NEAR(total / area, 1.0, 0.2) << (varying ? "varying" : "uniform");
  }
  PointCloud few;
  few.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  EXPECT_NE(error_of([&] { assign_knn_areas(few, 10); }).find("needs at least 11"), std::string::npos);
}

// ---- trees over points, for every shipped volume ----

template <class BV>
class PointTree : public ::testing::Test {};
TYPED_TEST_SUITE(PointTree, testing::AllShippedVolumes);

/// Every node's (decoded) volume, parents decoded before children.
template <class BV>
std::vector<typename Bvh<BV>::Fitted> decoded_volumes(const Bvh<BV>& tree) {
  std::vector<typename Bvh<BV>::Fitted> out(tree.nodes().size());
  if constexpr (Bvh<BV>::hierarchical) {
    out[0] = tree.root_volume();
    for (std::uint32_t i = 0; i < tree.nodes().size(); ++i)
      if (!tree.node(i).is_leaf())
        for (std::uint32_t c : {tree.node(i).left(), tree.node(i).right()})
          out[c] = BV::decode(out[i], tree.volume(c));
  } else {
    out = tree.volumes();
  }
  return out;
}

TYPED_TEST(PointTree, EveryVolumeContainsItsPointsAndLeavesKeepTheirSize) {
  const PointCloud cloud = sample_uniform(pinion(), 3000, 11);
  for (std::uint32_t leaf : {8u, 32u}) {
    BuildOptions options;
    options.max_leaf_points = leaf;
    const auto tree = Bvh<TypeParam>::build(cloud, options);
    ASSERT_TRUE(tree.has_points());
    EXPECT_FALSE(tree.has_polygons());
    EXPECT_EQ(tree.stats().points, cloud.size());
    std::vector<std::uint32_t> ids = tree.point_ids();
    std::sort(ids.begin(), ids.end());
    for (std::uint32_t i = 0; i < ids.size(); ++i) ASSERT_EQ(ids[i], i);  // each point once
    const auto volumes = decoded_volumes(tree);
    const auto ranges = node_triangle_ranges(tree.nodes());
    for (std::uint32_t i = 0; i < tree.nodes().size(); ++i) {
      if (tree.node(i).is_leaf()) {
        EXPECT_LE(tree.node(i).count, leaf);
      }
      for (std::uint32_t p = ranges[i].first; p < ranges[i].second; ++p) {
        ASSERT_EQ(tree.points()[p], cloud.positions[tree.point_ids()[p]]);
        ASSERT_TRUE(volumes[i].contains(tree.points()[p]))
            << "node " << i << ", point " << p << ", leaf " << leaf;
      }
    }
    EXPECT_GE(tree.stats().leaves, cloud.size() / leaf);
  }
}

TYPED_TEST(PointTree, RefusesEmptyCloudsAndRefit) {
  EXPECT_THROW(Bvh<TypeParam>::build(PointCloud{}), std::invalid_argument);
  PointCloud nan;
  nan.positions = {Vec3(0, 0, 0), Vec3(std::nan(""), 0, 0)};
  EXPECT_NE(error_of([&] { Bvh<TypeParam>::build(nan); }).find("point 1 is not finite"), std::string::npos);
  auto tree = Bvh<TypeParam>::build(sample_uniform(pinion(), 100, 1));
  EXPECT_NE(error_of([&] { tree.refit(pinion()); }).find("point cloud"), std::string::npos);
}

}  // namespace
}  // namespace bvhlab
