// ADB cell counts from points instead of polygons: each point stands for an area (PointCloud::areas: total
// area / N for a uniform sampling, pi r_k^2 / k from its k-NN radius otherwise), and the area in a cell is
// the sum of the areas of the points that fall in it. The counts then mean what the exact annotation's mean
// (adb/annotate.hpp: cells holding at least tau times a cell's mean face area), so a tree over points is an
// AdbDensity tree: same storage, same saved bytes, same probability model and strategies.
//
// Why not a density policy of its own: the Density concept annotates a Bvh from its polygons, and a second
// name for the same counts would add a registry entry (and its per-volume instantiations in the runner)
// without a new query-time model. The source of the areas is a preprocessing choice, not a density.
#pragma once

#include "adb_density.hpp"
#include "tree.hpp"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

/// The g^3 cell areas of `box` (cell index x + g (y + g z)) from points with areas: a point belongs to the
/// cell its coordinates fall in (the last cell of an axis includes its upper face); points outside the box
/// are ignored. Along an axis where the box is flat, a point's area counts in every layer, as the exact
/// annotation counts a polygon lying in a flat box. Throws std::invalid_argument for a grid outside [1, 6],
/// mismatched sizes, or an empty or non-finite box.
std::vector<double> point_cell_areas(const Box& box, int grid, std::span<const Vec3> points,
                                     std::span<const double> areas);

/// The same from triangles, exactly (triangle_area_in_box per cell): the reference the point areas are
/// checked against.
std::vector<double> triangle_cell_areas(const Box& box, int grid, std::span<const TrianglePoints> triangles);

/// pc per node from point areas: node i has box node_boxes[i] and the points points[node_ranges[i]] (tree
/// order), with the ADB threshold (area > 0 and area >= tau * the cell's mean face area).
std::vector<std::uint8_t> point_cell_counts(
    std::span<const Box> node_boxes, std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
    std::span<const Vec3> points, std::span<const double> areas, int grid, double tau);

/// The same with each node's grid in its own frame (`node_frames[i]`, an OBB's box), as the exact
/// annotation counts there (annotate_counts_in_frames): the node's points mapped into the frame and counted
/// on [-half, half] (grown to hold them), an axis thinner than kMinRelativeThickness of the longest
/// flattened to the plane 0.
std::vector<std::uint8_t> point_cell_counts_in_frames(
    std::span<const OrientedBox> node_frames,
    std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges, std::span<const Vec3> points,
    std::span<const double> areas, int grid, double tau);

/// The number of cells of g^3 whose area reaches the ADB threshold of `box`.
std::uint8_t count_cells(const Box& box, int grid, std::span<const double> cell_areas, double tau);

/// A tree over `cloud` (Bvh<BV>::build(cloud)) annotated with ADB counts from its points' areas, on the
/// cells the estimate reads: the nodes' own frames on OBB trees, else their bounding boxes. Throws
/// std::invalid_argument when the tree holds no points or not this cloud's, or the cloud has no areas
/// (sample_uniform sets them; assign_knn_areas estimates them), or for bad parameters.
template <TreeVolume BV>
Tree<BV, AdbDensity> annotate_adb_points(Bvh<BV> tree, const PointCloud& cloud, int grid = 2,
                                         double tau = kDefaultAdbTau) {
  if (!tree.has_points()) throw std::invalid_argument("annotate_adb_points: the tree holds no points");
  if (!cloud.has_areas() || cloud.areas.size() != cloud.size())
    throw std::invalid_argument("annotate_adb_points: cloud '" + cloud.name +
                                "' has no per-point areas (assign_knn_areas estimates them)");
  std::vector<double> areas;
  areas.reserve(tree.point_ids().size());
  for (std::uint32_t id : tree.point_ids()) {
    if (id >= cloud.size())
      throw std::invalid_argument("annotate_adb_points: the tree was built over another cloud than '" +
                                  cloud.name + "'");
    areas.push_back(cloud.areas[id]);
  }
  const AdbParams params = density_params<AdbDensity>({{"grid", grid}, {"tau", tau}});
  std::vector<std::uint8_t> counts;
  if constexpr (estimates_in_node_frames<AdbDensity, BV>) {  // the cells the estimate reads (OBB)
    counts = point_cell_counts_in_frames(node_frames(tree), node_triangle_ranges(tree.nodes()), tree.points(),
                                         areas, params.grid, params.tau);
  } else {
    counts = point_cell_counts(tree.node_boxes(), node_triangle_ranges(tree.nodes()), tree.points(), areas,
                               params.grid, params.tau);
  }
  AdbStorage storage = AdbDensity::make_storage(params, std::move(counts));
  return Tree<BV, AdbDensity>{std::move(tree), std::move(storage)};
}

}  // namespace bvhlab
