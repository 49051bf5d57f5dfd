#include "bvh/point_surface.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace bvhlab {

// A named namespace: PointSurface::Impl holds a CellGrid, and GCC rejects a member of an internal type in a
// class with linkage when the file is compiled inside a unity build's unit (-Wsubobject-linkage).
namespace point_surface_detail {

/// Points hashed into cubic cells at least as wide as the largest support radius, so the points that can
/// reach x lie in the 27 cells around x's cell.
class CellGrid {
 public:
  CellGrid(std::span<const Vec3> points, double cell) {
    Box box;
    for (const Vec3& p : points) box.extend(p);
    origin_ = box.min;
    // Indices stay within 20 bits per axis: a cloud far wider than its kernel gets coarser cells.
    cell_ = std::max(cell, box.extent().maxCoeff() / double(1 << 20));
    if (!(cell_ > 0)) cell_ = 1;
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(index(points[i]))].push_back(std::uint32_t(i));
  }

  /// Calls f(point index) for every point in the cells around x.
  template <class F>
  void around(const Vec3& x, F&& f) const {
    const std::array<std::int64_t, 3> c = index(x);
    for (int a = 0; a < 3; ++a)
      if (c[a] < -1 || c[a] > (std::int64_t{1} << 20) + 1) return;  // far outside: no cell there
    for (std::int64_t i = c[0] - 1; i <= c[0] + 1; ++i)
      for (std::int64_t j = c[1] - 1; j <= c[1] + 1; ++j)
        for (std::int64_t k = c[2] - 1; k <= c[2] + 1; ++k) {
          const auto it = cells_.find(key({i, j, k}));
          if (it != cells_.end())
            for (std::uint32_t p : it->second) f(p);
        }
  }

 private:
  [[nodiscard]] std::array<std::int64_t, 3> index(const Vec3& p) const {
    std::array<std::int64_t, 3> out{};
    for (int a = 0; a < 3; ++a) {
      const double t = std::floor((p[a] - origin_[a]) / cell_);
      out[a] = std::int64_t(std::clamp(t, -4.0, double(1 << 22)));
    }
    return out;
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    auto part = [](std::int64_t v) { return std::uint64_t(v + 8) & 0x1fffff; };
    return part(c[0]) | part(c[1]) << 21 | part(c[2]) << 42;
  }

  Vec3 origin_ = Vec3::Zero();
  double cell_ = 1;
  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cells_;
};

}  // namespace point_surface_detail

using point_surface_detail::CellGrid;

namespace {

/// Unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix.
Vec3 least_direction(const Mat3& covariance) {
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
  return solver.eigenvectors().col(0).normalized();
}

}  // namespace

struct PointSurface::Impl {
  PointSurfaceOptions options;
  std::vector<Vec3> points, normals;
  std::vector<double> radii;
  std::unique_ptr<CellGrid> grid;
};

PointSurface::PointSurface(const PointCloud& cloud, const PointSurfaceOptions& options)
    : impl_(std::make_unique<Impl>()) {
  if (options.k == 0) throw std::invalid_argument("PointSurface: k must be at least 1");
  if (!(options.support >= 1 && options.support <= 10))
    throw std::invalid_argument("PointSurface: support must be in [1, 10] kernel radii");
  validate(cloud, options.k + 1);
  Impl& s = *impl_;
  s.options = options;
  s.points = cloud.positions;
  s.radii = kth_neighbour_distances(s.points, options.k);
  std::vector<double> sorted = s.radii;
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  if (!(median > 0))
    throw PointCloudError("point cloud '" + cloud.name + "': more than half of the points have " +
                          std::to_string(options.k) + " coincident copies; no kernel radius can be derived");
  for (double& r : s.radii) r = std::max(r, 0.25 * median);
  s.grid = std::make_unique<CellGrid>(s.points,
                                      options.support * *std::max_element(s.radii.begin(), s.radii.end()));

  if (cloud.has_normals()) {
    s.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const double len = cloud.normals[i].norm();
      if (!(len > 0))
        throw PointCloudError("point cloud '" + cloud.name + "': normal " + std::to_string(i) + " is zero");
      s.normals[i] = cloud.normals[i] / len;
    }
    return;
  }
  // No normals: the covariance of each point's kernel neighbourhood, turned away from the centroid.
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : s.points) centroid += p;
  centroid /= double(s.points.size());
  s.normals.resize(s.points.size());
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    Mat3 covariance = Mat3::Zero();
    const Vec3& p = s.points[i];
    s.grid->around(p, [&](std::uint32_t j) {
      const Vec3 d = s.points[j] - p;
      if (d.squaredNorm() <= s.radii[i] * s.radii[i]) covariance += d * d.transpose();
    });
    Vec3 n = least_direction(covariance);
    if (n.dot(p - centroid) < 0) n = -n;
    s.normals[i] = n;
  }
}

PointSurface::~PointSurface() = default;
PointSurface::PointSurface(PointSurface&&) noexcept = default;
PointSurface& PointSurface::operator=(PointSurface&&) noexcept = default;

std::optional<double> PointSurface::value(const Vec3& x) const {
  const Impl& s = *impl_;
  const double support2 = s.options.support * s.options.support;
  // Sums about x, not the origin: a cloud far from the origin keeps its precision.
  double total = 0;
  Vec3 mean = Vec3::Zero(), normal = Vec3::Zero();
  std::size_t count = 0;
  s.grid->around(x, [&](std::uint32_t i) {
    const Vec3 d = s.points[i] - x;
    const double q = d.squaredNorm() / (s.radii[i] * s.radii[i]);
    if (q > support2) return;
    const double w = std::exp(-q);
    total += w;
    mean += w * d;
    normal += w * s.normals[i];
    ++count;
  });
  if (count == 0 || !(total > 0)) return std::nullopt;
  mean /= total;
  Vec3 n;
  if (count < 3) {
    n = normal.normalized();  // too few points for a plane: their normals
  } else {
    Mat3 covariance = Mat3::Zero();
    s.grid->around(x, [&](std::uint32_t i) {
      const Vec3 d = s.points[i] - x;
      const double q = d.squaredNorm() / (s.radii[i] * s.radii[i]);
      if (q > support2) return;
      const Vec3 e = d - mean;
      covariance += std::exp(-q) * (e * e.transpose());
    });
    n = least_direction(covariance);
  }
  if (n.dot(normal) < 0) n = -n;
  return n.dot(-mean);  // n . (x - a), with a = x + mean
}

const std::vector<Vec3>& PointSurface::points() const {
  return impl_->points;
}
const std::vector<Vec3>& PointSurface::normals() const {
  return impl_->normals;
}
const std::vector<double>& PointSurface::kernel_radii() const {
  return impl_->radii;
}
const PointSurfaceOptions& PointSurface::options() const {
  return impl_->options;
}

std::vector<SphereCovering> sphere_coverings(std::span<const TreeNode> nodes, std::span<const Vec3> points,
                                             std::span<const std::uint32_t> point_ids,
                                             std::span<const double> kernel_radii) {
  if (point_ids.size() != points.size())
    throw std::invalid_argument("sphere_coverings: " + std::to_string(point_ids.size()) + " ids for " +
                                std::to_string(points.size()) + " points");
  for (std::uint32_t id : point_ids)
    if (id >= kernel_radii.size())
      throw std::invalid_argument("sphere_coverings: point id " + std::to_string(id) +
                                  " has no kernel radius");
  const auto ranges = node_triangle_ranges(nodes);
  std::vector<SphereCovering> out(nodes.size());
  std::vector<double> nearest;  // per point of the node: distance to its nearest centre so far
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const auto [first, last] = ranges[i];
    if (last > points.size())
      throw std::invalid_argument("sphere_coverings: a node's range is past the points");
    if (first == last) continue;
    SphereCovering& c = out[i];
    nearest.assign(last - first, std::numeric_limits<double>::infinity());
    std::uint32_t next = first;  // farthest-point order, from the node's first point
    while (true) {
      const Vec3 centre = points[next];
      c.centres[c.count++] = centre;
      double farthest = -1;
      for (std::uint32_t p = first; p < last; ++p) {
        double& d = nearest[p - first];
        d = std::min(d, (points[p] - centre).norm());
        if (d > farthest) farthest = d, next = p;
      }
      c.radius = farthest;
      if (c.count == SphereCovering::kCoverSpheres || farthest == 0) break;
    }
    for (std::uint32_t p = first; p < last; ++p) c.margin = std::max(c.margin, kernel_radii[point_ids[p]]);
  }
  return out;
}

SurfaceSigns surface_signs(const PointSurface& surface, std::span<const Vec3> points,
                           const RigidTransform& into, bool stop_at_both) {
  SurfaceSigns out;
  bool positive = false, negative = false;
  for (const Vec3& p : points) {
    const std::optional<double> f = surface.value(into.apply(p));
    if (!f) continue;
    ++out.defined_values;
    positive = positive || *f >= 0;  // a point on the surface (f = 0) touches it: closed, like triangles
    negative = negative || *f <= 0;
    out.smallest = std::min(out.smallest, std::abs(*f));
    if (stop_at_both && positive && negative) break;
  }
  out.both = positive && negative;
  return out;
}

LeafSurfaceTest test_leaf_surfaces(const PointSurface& a, std::span<const Vec3> a_points,
                                   const PointSurface& b, std::span<const Vec3> b_points,
                                   const RigidTransform& b_to_a) {
  const SurfaceSigns a_side = surface_signs(b, a_points, b_to_a.inverse());
  const SurfaceSigns b_side = surface_signs(a, b_points, b_to_a);
  LeafSurfaceTest out;
  out.crossing = a_side.both || b_side.both;
  out.defined_values = a_side.defined_values + b_side.defined_values;
  if (!out.crossing && out.defined_values > 0) out.distance = std::min(a_side.smallest, b_side.smallest);
  return out;
}

}  // namespace bvhlab
