// Tree topology, independent of the bounding volume (after Embree: topology apart from node layout).
#pragma once

#include "mesh.hpp"

#include <cstdint>
#include <functional>
#include <span>
#include <string_view>
#include <vector>

namespace bvhlab {

/// One node of a flat tree. Inner node: `count == 0`, children at `first` and `first + 1`.
/// Leaf: triangles `triangle_order[first .. first + count)`.
struct TreeNode {
  std::uint32_t first = 0;
  std::uint32_t count = 0;
  [[nodiscard]] bool is_leaf() const { return count != 0; }
  [[nodiscard]] std::uint32_t left() const { return first; }
  [[nodiscard]] std::uint32_t right() const { return first + 1; }
};

enum class SplitMethod {
  Median,  ///< object median along the split direction of widest centroid spread
  Sah,     ///< binned surface-area heuristic over all split directions
};
std::string_view to_string(SplitMethod m);
/// Parses "median" or "sah"; throws std::invalid_argument naming the bad value.
SplitMethod split_method_from_string(std::string_view s);

struct BuildOptions {
  SplitMethod split = SplitMethod::Sah;
  std::uint32_t max_leaf_triangles = 1;  ///< the DOP-tree uses one polygon per leaf
  std::uint32_t max_leaf_points = 16;    ///< for trees over point clouds: 8 to 32 keeps leaf tests cheap
  unsigned threads = 0;                  ///< 0: hardware concurrency
  /// Called now and then with (triangles placed in leaves, total); may be called from worker threads,
  /// but never concurrently.
  std::function<void(std::size_t, std::size_t)> progress;
};

struct Topology {
  std::vector<TreeNode> nodes;                ///< root at 0
  std::vector<std::uint32_t> triangle_order;  ///< tree order -> mesh triangle (or cloud point) index
  std::uint32_t depth = 0;                    ///< edges on the longest root-leaf path
  std::uint32_t leaves = 0;
};

/// [begin, end) of every node's triangles in tree order (a subtree's triangles are contiguous).
/// Requires children to be stored after their parent, as build_topology does; throws otherwise.
std::vector<std::pair<std::uint32_t, std::uint32_t>> node_triangle_ranges(std::span<const TreeNode> nodes);

/// Builds the topology over the triangles' centroids, trying the given split directions.
/// Throws std::invalid_argument for an empty mesh or max_leaf_triangles == 0.
Topology build_topology(const Mesh& mesh, std::span<const Vec3> split_directions,
                        const BuildOptions& options);

/// The same over points (each point its own centroid), max_leaf_points per leaf; leaves then hold points
/// and triangle_order maps tree order to point indices. Throws std::invalid_argument for no points, a
/// non-finite point (naming its index) or max_leaf_points == 0.
Topology build_topology(std::span<const Vec3> points, std::span<const Vec3> split_directions,
                        const BuildOptions& options);

}  // namespace bvhlab
