// ADB counts from points: the point areas against the exact clipped area of the mesh they were sampled from,
// and trees over points annotated with the ADB density.
#include "adb/point_density.hpp"
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"
#include "volumes/aabb.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <numeric>

namespace bvhlab {
namespace {

Mesh pinion() {
  return load_mesh(testing::bundled_mesh("pinion.off")).mesh;
}

std::vector<TrianglePoints> triangles_of(const Mesh& m) {
  std::vector<TrianglePoints> out;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) out.push_back(m.triangle(t));
  return out;
}

/// Errors of the point areas on a g^3 grid over the mesh's box, relative to the mesh's area: of the total,
/// of the cells (sum of |point - exact| over cells), and the number of cells whose ADB decision differs.
struct AreaError {
  double total = 0, cells = 0;
  int decisions = 0;
};

AreaError area_error(const PointCloud& cloud, const Box& box, int grid, std::span<const double> exact) {
  const std::vector<double> points = point_cell_areas(box, grid, cloud.positions, cloud.areas);
  const double area = std::accumulate(exact.begin(), exact.end(), 0.0);
  AreaError e;
  double sum = 0;
  for (std::size_t c = 0; c < exact.size(); ++c) {
    sum += points[c];
    e.cells += std::abs(points[c] - exact[c]);
    const std::array<double, 1> p{points[c]}, x{exact[c]};
    e.decisions += count_cells(box, grid, p, kDefaultAdbTau) != count_cells(box, grid, x, kDefaultAdbTau);
  }
  e.total = std::abs(sum - area) / area;
  e.cells /= area;
  return e;
}

PointCloud sampled(const Mesh& mesh, bool varying, std::size_t n) {
  if (!varying) return sample_uniform(mesh, n, 17);
  PointCloud c = sample_varying(mesh, n, 17, 4.0);
  assign_knn_areas(c, 10);
  return c;
}

TEST(PointDensity, CellAreasFromPointsApproachTheExactAreasAsPointsGrow) {
  const Mesh mesh = pinion();
  const Box box = mesh.bounds();
  const int grid = 4;
  const std::vector<double> exact = triangle_cell_areas(box, grid, triangles_of(mesh));
  for (bool varying : {false, true}) {
    const AreaError coarse = area_error(sampled(mesh, varying, 1000), box, grid, exact);
    const AreaError fine = area_error(sampled(mesh, varying, 16000), box, grid, exact);
    const char* what = varying ? "varying, k-NN areas" : "uniform, area / N";
    // 16 times the points: sampling noise falls about 4 times; k-NN areas keep a border bias.
    EXPECT_LT(fine.cells, 0.6 * coarse.cells) << what;
    EXPECT_LT(fine.cells, 0.1) << what;
    if (varying) {
      EXPECT_LT(fine.total, 0.06) << what;
    } else {
      EXPECT_LT(fine.total, 1e-9) << what;  // the areas add up to the mesh's by construction
    }
  }
}

TEST(PointDensity, ExactCellAreasAddUpToTheMeshArea) {
  const Mesh mesh = pinion();
  const auto tris = triangles_of(mesh);
  double area = 0;
  for (const auto& t : tris) area += 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
  const auto exact = triangle_cell_areas(mesh.bounds(), 3, tris);
  // Closed cells count a polygon in a shared face twice, so the sum may only exceed the area.
  EXPECT_GE(std::accumulate(exact.begin(), exact.end(), 0.0), area * (1 - 1e-9));
  EXPECT_LE(std::accumulate(exact.begin(), exact.end(), 0.0), area * 1.01);
}

// The error table of bvh/README.md "Point clouds" (printed; the assertions are in the test above).
TEST(PointDensity, ReportsTheErrorAtSeveralDensities) {
  const Mesh mesh = pinion();
  const Box box = mesh.bounds();
  for (int grid : {4, 6}) {
    const std::vector<double> exact = triangle_cell_areas(box, grid, triangles_of(mesh));
    for (bool varying : {false, true})
      for (std::size_t n : {1000u, 4000u, 16000u}) {
        const AreaError e = area_error(sampled(mesh, varying, n), box, grid, exact);
        std::printf("pinion g=%d %-8s N=%-6zu total %.4f cells %.4f decisions %d of %d\n", grid,
                    varying ? "varying" : "uniform", n, e.total, e.cells, e.decisions, grid * grid * grid);
      }
  }
}

TEST(PointDensity, TreesOverPointsCarryAdbCounts) {
  const Mesh mesh = pinion();
  const PointCloud cloud = sample_uniform(mesh, 4000, 5);
  const auto tree = annotate_adb_points(Bvh<Aabb>::build(cloud), cloud, 2);
  ASSERT_EQ(tree.density.possible_collision_cells.size(), tree.bvh.nodes().size());
  for (std::uint8_t pc : tree.density.possible_collision_cells) EXPECT_LE(pc, 8);
  // The root's count equals the count of the exact areas in the root box (4000 points: no cell near a tie).
  const Box root = tree.bvh.node_boxes()[0];
  const auto exact = triangle_cell_areas(root, 2, triangles_of(mesh));
  EXPECT_EQ(tree.density.possible_collision_cells[0], count_cells(root, 2, exact, kDefaultAdbTau));
  // Every volume: the restricted boxtree's decoded boxes too.
  const auto restricted = annotate_adb_points(Bvh<RestrictedBox>::build(cloud), cloud, 3);
  EXPECT_GT(restricted.density.possible_collision_cells[0], 0);
}

// On OBB trees the ADB estimate reads cells in the nodes' own frames (adb/pair_geometry.hpp), so the point
// counts must be taken there too. A flat 2 x 1 rectangle tilted by 45 degrees: in its root's frame the box is
// flat, so its area counts in both layers of a 2^3 grid (8 cells), as the exact annotation in that frame
// counts it; the axis-aligned box of the same node would see the slanted sheet in only some cells.
TEST(PointDensity, ObbTreesCountThePointsInTheNodesOwnFrames) {
  const double c = std::sqrt(0.5);
  Mesh rectangle;
  rectangle.name = "tilted rectangle";
  for (const auto& [u, v] : {std::pair{-1.0, -0.5}, {1.0, -0.5}, {1.0, 0.5}, {-1.0, 0.5}})
    rectangle.vertices.push_back(Vec3(c * u, v, c * u));  // the plane x = z
  rectangle.triangles = {{0, 1, 2}, {0, 2, 3}};
  const PointCloud cloud = sample_uniform(rectangle, 4000, 3);
  const auto tree = annotate_adb_points(Bvh<Obb>::build(cloud), cloud, 2);
  const std::array<OrientedBox, 1> root{tree.bvh.volume(0).oriented_box()};
  const std::array<std::pair<std::uint32_t, std::uint32_t>, 1> both{std::pair{0u, 2u}};
  const CellCounts exact =
      annotate_counts_in_frames(root, both, triangles_of(rectangle), 2, AnnotateOptions{});
  EXPECT_EQ(exact.counts[0], 8);
  EXPECT_EQ(tree.density.possible_collision_cells[0], exact.counts[0]);
  // The same points counted on the node's axis-aligned box give another count: the test tells them apart.
  std::vector<double> areas;
  for (std::uint32_t id : tree.bvh.point_ids()) areas.push_back(cloud.areas[id]);
  const std::array<std::pair<std::uint32_t, std::uint32_t>, 1> all{
      std::pair{0u, static_cast<std::uint32_t>(areas.size())}};
  const std::vector<Box> boxes = tree.bvh.node_boxes();
  const auto in_boxes =
      point_cell_counts(std::span(boxes).first(1), all, tree.bvh.points(), areas, 2, kDefaultAdbTau);
  EXPECT_NE(in_boxes[0], exact.counts[0]);
}

TEST(PointDensity, RefusesTreesAndCloudsThatDoNotFit) {
  const Mesh mesh = pinion();
  PointCloud cloud = sample_varying(mesh, 500, 5);
  EXPECT_THROW(annotate_adb_points(Bvh<Aabb>::build(cloud), cloud), std::invalid_argument);  // no areas
  EXPECT_THROW(annotate_adb_points(Bvh<Aabb>::build(mesh), sample_uniform(mesh, 50, 1)),
               std::invalid_argument);
  const PointCloud small = sample_uniform(mesh, 50, 1);
  EXPECT_THROW(annotate_adb_points(Bvh<Aabb>::build(cloud), small), std::invalid_argument);  // other cloud
  const std::array<Vec3, 1> p{Vec3(0, 0, 0)};
  const std::array<double, 2> a{1, 2};
  EXPECT_THROW(point_cell_areas(mesh.bounds(), 2, p, a), std::invalid_argument);
  EXPECT_THROW(point_cell_areas(mesh.bounds(), 7, p, std::span(a).first(1)), std::invalid_argument);
  EXPECT_THROW(point_cell_areas(Box{}, 2, p, std::span(a).first(1)), std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab
