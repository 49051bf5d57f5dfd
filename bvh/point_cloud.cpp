// Point clouds: validation, sampling from meshes, k-neighbour areas. Reading and writing cloud files is in
// bvh/io/point_cloud_files.cpp.
#include "bvh/point_cloud.hpp"

#include "bvh/mesh_io.hpp"

#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace bvhlab {

namespace {

[[noreturn]] void fail(std::string_view name, const std::string& what) {
  throw PointCloudError("point cloud '" + std::string(name) + "': " + what);
}

void check_finite(std::string_view name, std::span<const Vec3> v, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite()) fail(name, std::string(what) + " " + std::to_string(i) + " is not finite");
}

// ---- sampling ----

/// SplitMix64: a small generator whose output is fixed by its integer arithmetic on every platform.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1), 53 bits.
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

Vec3 cross(const Vec3& a, const Vec3& b) {  // spelled out: no library-chosen evaluation order
  return Vec3(a.y() * b.z() - a.z() * b.y(), a.z() * b.x() - a.x() * b.z(), a.x() * b.y() - a.y() * b.x());
}
double length(const Vec3& v) {
  return std::sqrt(v.x() * v.x() + v.y() * v.y() + v.z() * v.z());
}

double triangle_area(const TrianglePoints& p) {
  return 0.5 * length(cross(p[1] - p[0], p[2] - p[0]));
}

/// Area-weighted triangle choice and uniform points in triangles.
class MeshSampler {
 public:
  explicit MeshSampler(const Mesh& mesh) : mesh_(mesh) {
    cumulative_.reserve(mesh.triangle_count());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      total_ += triangle_area(mesh.triangle(t));
      cumulative_.push_back(total_);
    }
    if (!(total_ > 0) || !std::isfinite(total_))
      throw std::invalid_argument("sample: mesh '" + mesh.name + "' has no finite positive area");
  }
  [[nodiscard]] double area() const { return total_; }
  /// A point and its triangle's unit normal.
  std::pair<Vec3, Vec3> sample(Random& random) const {
    const double u = random.uniform() * total_;
    auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), u);
    if (it == cumulative_.end()) --it;  // u rounded up to the total: the last triangle with area
    while (it != cumulative_.begin() && *it == *(it - 1)) --it;
    const TrianglePoints p = mesh_.triangle(std::size_t(it - cumulative_.begin()));
    const double s = std::sqrt(random.uniform()), r = random.uniform();
    const Vec3 point = (1 - s) * p[0] + (s * (1 - r)) * p[1] + (s * r) * p[2];
    const Vec3 n = cross(p[1] - p[0], p[2] - p[0]);
    return {point, n / length(n)};
  }

 private:
  const Mesh& mesh_;
  std::vector<double> cumulative_;
  double total_ = 0;
};

}  // namespace

void validate(const PointCloud& cloud, std::size_t min_points) {
  const std::string name = cloud.name.empty() ? "<unnamed>" : cloud.name;
  if (cloud.positions.empty()) fail(name, "has no points");
  if (cloud.size() < min_points)
    fail(name, "has " + std::to_string(cloud.size()) + " points, the kernel needs at least " +
                   std::to_string(min_points));
  check_finite(name, cloud.positions, "point");
  for (std::size_t i = 0; i < cloud.size(); ++i)  // the meshes' limit: beyond it a double spaces by 0.1
    if (cloud.positions[i].cwiseAbs().maxCoeff() > MeshPrecisionLimits::max_abs_coordinate)
      fail(name, "point " + std::to_string(i) +
                     " has a coordinate beyond 1e15 (the queries' precision ends there)");
  if (cloud.has_normals()) {
    if (cloud.normals.size() != cloud.size())
      fail(name,
           std::to_string(cloud.normals.size()) + " normals for " + std::to_string(cloud.size()) + " points");
    check_finite(name, cloud.normals, "normal");
  }
  if (cloud.has_areas()) {
    if (cloud.areas.size() != cloud.size())
      fail(name,
           std::to_string(cloud.areas.size()) + " areas for " + std::to_string(cloud.size()) + " points");
    for (std::size_t i = 0; i < cloud.areas.size(); ++i)
      if (!std::isfinite(cloud.areas[i]) || cloud.areas[i] < 0)
        fail(name, "area " + std::to_string(i) + " is negative or not finite");
  }
  if (cloud.size() > 1 && std::all_of(cloud.positions.begin(), cloud.positions.end(),
                                      [&](const Vec3& p) { return p == cloud.positions[0]; }))
    fail(name, "all " + std::to_string(cloud.size()) + " points are coincident");
}

double surface_area(const Mesh& mesh) {
  double total = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) total += triangle_area(mesh.triangle(t));
  return total;
}

PointCloud sample_uniform(const Mesh& mesh, std::size_t n, std::uint64_t seed) {
  if (n == 0) throw std::invalid_argument("sample_uniform: n must be at least 1");
  const MeshSampler sampler(mesh);
  Random random(seed);
  PointCloud cloud;
  cloud.name = mesh.name;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto [p, normal] = sampler.sample(random);
    cloud.positions.push_back(p);
    cloud.normals.push_back(normal);
  }
  cloud.areas.assign(n, sampler.area() / double(n));
  return cloud;
}

PointCloud sample_varying(const Mesh& mesh, std::size_t n, std::uint64_t seed, double ratio) {
  if (n == 0) throw std::invalid_argument("sample_varying: n must be at least 1");
  if (!(ratio >= 1 && ratio <= 1000))
    throw std::invalid_argument("sample_varying: ratio must be in [1, 1000], got " + std::to_string(ratio));
  const MeshSampler sampler(mesh);
  const Box box = mesh.bounds();
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (box.extent()[a] > box.extent()[axis]) axis = a;
  const double lo = box.min[axis], extent = box.extent()[axis];
  Random random(seed);
  PointCloud cloud;
  cloud.name = mesh.name;
  cloud.positions.reserve(n);
  cloud.normals.reserve(n);
  while (cloud.size() < n) {
    const auto [p, normal] = sampler.sample(random);
    const double t = extent > 0 ? (p[axis] - lo) / extent : 1.0;
    // Accept with probability proportional to 1 + (ratio - 1) t: density 1 at lo, ratio at lo + extent.
    if (random.uniform() * ratio < 1 + (ratio - 1) * t) {
      cloud.positions.push_back(p);
      cloud.normals.push_back(normal);
    }
  }
  return cloud;
}

std::vector<double> kth_neighbour_distances(std::span<const Vec3> points, std::size_t k) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Search_traits_3<Kernel>;
  using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
  if (k == 0) throw std::invalid_argument("kth_neighbour_distances: k must be at least 1");
  check_finite("<points>", points, "point");
  if (points.size() < k + 1)
    fail("<points>", std::to_string(points.size()) + " points, the k-th neighbour (k = " + std::to_string(k) +
                         ") needs at least " + std::to_string(k + 1));
  std::vector<Kernel::Point_3> cgal_points;
  cgal_points.reserve(points.size());
  for (const Vec3& p : points) cgal_points.emplace_back(p.x(), p.y(), p.z());
  Search::Tree tree(cgal_points.begin(), cgal_points.end());
  tree.build();
  std::vector<double> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    // k + 1 neighbours: the point itself (or a copy of it) comes first at distance 0.
    Search search(tree, cgal_points[i], unsigned(k + 1));
    double farthest = 0;
    for (const auto& [point, squared] : search) farthest = std::max(farthest, squared);
    out[i] = std::sqrt(farthest);
  }
  return out;
}

void assign_knn_areas(PointCloud& cloud, std::size_t k) {
  const std::vector<double> r = kth_neighbour_distances(cloud.positions, k);
  cloud.areas.resize(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) cloud.areas[i] = std::numbers::pi * r[i] * r[i] / double(k);
}

}  // namespace bvhlab
