// The surface a point cloud defines: the zero set of a weighted-least-squares function in the manner of
// Adamson and Alexa (2003), with a kernel radius per point; per node a covering of its part of the surface by
// a few spheres; and the test of two point leaves (do the surfaces cross there, else how far apart are they).
//
// f(x) = n(x) . (x - a(x)), where a(x) is the weighted mean of the points near x and n(x) the direction of
// least weighted covariance about a(x), turned to agree with the weighted mean of the points' normals (so f
// is positive outside, on the side the normals point to). Weights are Gaussian, exp(-|x - p_i|^2 / h_i^2),
// h_i point i's kernel radius: the distance to its k-th nearest neighbour. Only points with |x - p_i| <=
// support * h_i take part; where there is none f is undefined (std::nullopt): far from the points f means
// nothing, and reading it as a number would call everything there "outside".
#pragma once

#include "bvh.hpp"
#include "point_cloud.hpp"

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace bvhlab {

struct PointSurfaceOptions {
  std::size_t k = 10;    ///< kernel radius: distance to the k-th nearest neighbour
  double support = 3.0;  ///< a point takes part in f(x) within this many of its kernel radii (weight e^-9)
};

class PointSurface {
 public:
  /// Validates the cloud (at least k + 1 points: validate(cloud, k + 1)) and computes the kernel radii and,
  /// for a cloud without normals, normals from the covariance of each point's k neighbours, turned away
  /// from the cloud's centroid: right for closed star-shaped objects only; load or sample normals for
  /// others. A radius below a quarter of the median radius (a point with k copies of itself) is raised to
  /// it, so no weight divides by zero. Throws PointCloudError naming the problem.
  explicit PointSurface(const PointCloud& cloud, const PointSurfaceOptions& options = {});
  ~PointSurface();
  PointSurface(PointSurface&&) noexcept;
  PointSurface& operator=(PointSurface&&) noexcept;

  /// f(x) in the cloud's own frame; nullopt where no point is within its support.
  [[nodiscard]] std::optional<double> value(const Vec3& x) const;

  [[nodiscard]] const std::vector<Vec3>& points() const;
  [[nodiscard]] const std::vector<Vec3>& normals() const;         ///< given or estimated, unit length
  [[nodiscard]] const std::vector<double>& kernel_radii() const;  ///< per point, after the clamp
  [[nodiscard]] const PointSurfaceOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A node's part of the surface covered by up to kCoverSpheres balls: every point of the node lies within
/// `radius` of one of the centres (points of the node, chosen farthest first). The surface itself may stray
/// up to about a kernel radius from the points: `margin` is the node's largest kernel radius, so the balls
/// of radius + margin cover the surface near the node's points as well.
struct SphereCovering {
  static constexpr std::size_t kCoverSpheres = 4;
  std::array<Vec3, kCoverSpheres> centres{};
  std::uint32_t count = 0;
  double radius = 0;
  double margin = 0;
};

/// One covering per node of a tree over points: nodes, the tree's points in tree order, the tree-order ->
/// cloud index map and the surface's kernel radii by cloud index. Throws std::invalid_argument for
/// inconsistent sizes.
std::vector<SphereCovering> sphere_coverings(std::span<const TreeNode> nodes, std::span<const Vec3> points,
                                             std::span<const std::uint32_t> point_ids,
                                             std::span<const double> kernel_radii);

/// The same for a Bvh built over `surface`'s cloud. Throws std::invalid_argument for a tree over a mesh.
template <TreeVolume BV>
std::vector<SphereCovering> sphere_coverings(const Bvh<BV>& tree, const PointSurface& surface) {
  if (!tree.has_points()) throw std::invalid_argument("sphere_coverings: the tree holds no points");
  return sphere_coverings(tree.nodes(), tree.points(), tree.point_ids(), surface.kernel_radii());
}

/// The points of node i of a tree over points, in tree order (the node's own frame).
template <TreeVolume BV>
std::span<const Vec3> node_points(const Bvh<BV>& tree, std::uint32_t i) {
  const TreeNode& n = tree.node(i);
  if (!n.is_leaf()) throw std::invalid_argument("node_points: node " + std::to_string(i) + " is not a leaf");
  return std::span<const Vec3>(tree.points()).subspan(n.first, n.count);
}

/// f of one surface over a set of points: the half of a leaf test that depends on one leaf only (the other
/// side's f is the whole other cloud's), so a traversal may reuse it for every leaf pair of that leaf.
struct SurfaceSigns {
  bool both = false;  ///< f took both signs (or was 0 at a point: touching)
  double smallest = std::numeric_limits<double>::infinity();  ///< the smallest |f| seen (when not stopped)
  std::size_t defined_values = 0;                             ///< evaluations where f was defined
};

/// Evaluates `surface`'s f at `points` mapped by `into` (into the surface's frame). With stop_at_both the
/// evaluation ends once both signs are seen (then `smallest` covers only the points seen).
SurfaceSigns surface_signs(const PointSurface& surface, std::span<const Vec3> points,
                           const RigidTransform& into, bool stop_at_both = false);

/// What the test of two point leaves found.
struct LeafSurfaceTest {
  bool crossing = false;  ///< f_B changes sign over A's points, or f_A over B's, or is 0 at one (touching)
  std::optional<double> distance;  ///< no crossing: the smallest |f| seen; nullopt when f was nowhere defined
  std::size_t defined_values = 0;  ///< evaluations where f was defined
};

/// Evaluates f_B at A's leaf points (mapped into B's frame) and f_A at B's leaf points (mapped into A's
/// frame by b_to_a): surface_signs of each side. Values of both signs from one side mean the surfaces cross
/// between those points; otherwise the smallest |f| estimates their distance (to within the kernel's
/// smoothing). A leaf wholly inside the other object sees one sign only, like a separated one: a crossing is
/// a surface crossing.
LeafSurfaceTest test_leaf_surfaces(const PointSurface& a, std::span<const Vec3> a_points,
                                   const PointSurface& b, std::span<const Vec3> b_points,
                                   const RigidTransform& b_to_a);

}  // namespace bvhlab
