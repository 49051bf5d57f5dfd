#include "adb/point_density.hpp"

#include "adb/annotate.hpp"
#include "adb/pair_geometry.hpp"

#include <algorithm>
#include <cmath>

namespace bvhlab {

namespace {

void check_grid_and_box(const Box& box, int grid, const char* what) {
  if (grid < 1 || grid > 6)
    throw std::invalid_argument(std::string(what) + ": grid must be in [1, 6], got " + std::to_string(grid));
  if (box.empty() || !box.min.allFinite() || !box.max.allFinite())
    throw std::invalid_argument(std::string(what) + ": the box is empty or not finite");
}

/// Boundary i of g along axis a, as the exact annotation lays it (adb/annotate.hpp).
double boundary(const Box& box, int a, int i, int g) {
  return i == g ? box.max[a] : std::min(box.max[a], box.min[a] + (box.max[a] - box.min[a]) * i / g);
}

}  // namespace

std::vector<double> point_cell_areas(const Box& box, int grid, std::span<const Vec3> points,
                                     std::span<const double> areas) {
  check_grid_and_box(box, grid, "point_cell_areas");
  if (points.size() != areas.size())
    throw std::invalid_argument("point_cell_areas: " + std::to_string(areas.size()) + " areas for " +
                                std::to_string(points.size()) + " points");
  const int g = grid;
  std::vector<double> out(std::size_t(g * g * g), 0.0);
  const Vec3 extent = box.extent();
  for (std::size_t p = 0; p < points.size(); ++p) {
    if (!box.contains(points[p])) continue;
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      if (extent[a] > 0) {
        const double x = std::floor((points[p][a] - box.min[a]) / extent[a] * g);
        lo[a] = hi[a] = std::clamp(static_cast<int>(x), 0, g - 1);
      } else {
        lo[a] = 0;
        hi[a] = g - 1;
      }
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) out[std::size_t(x + g * (y + g * z))] += areas[p];
  }
  return out;
}

std::vector<double> triangle_cell_areas(const Box& box, int grid, std::span<const TrianglePoints> triangles) {
  check_grid_and_box(box, grid, "triangle_cell_areas");
  const int g = grid;
  std::vector<double> out(std::size_t(g * g * g), 0.0);
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x) {
        Box cell;
        cell.min = Vec3(boundary(box, 0, x, g), boundary(box, 1, y, g), boundary(box, 2, z, g));
        cell.max = Vec3(boundary(box, 0, x + 1, g), boundary(box, 1, y + 1, g), boundary(box, 2, z + 1, g));
        double& sum = out[std::size_t(x + g * (y + g * z))];
        for (const TrianglePoints& t : triangles) {
          Box b;
          for (const Vec3& v : t) b.extend(v);
          if (b.overlaps(cell)) sum += triangle_area_in_box(t, cell);
        }
      }
  return out;
}

std::uint8_t count_cells(const Box& box, int grid, std::span<const double> cell_areas, double tau) {
  const Vec3 c = box.extent() / double(grid);
  const double threshold = tau * (c.x() * c.y() + c.y() * c.z() + c.z() * c.x()) / 3;
  return static_cast<std::uint8_t>(
      std::count_if(cell_areas.begin(), cell_areas.end(), [&](double a) { return a > 0 && a >= threshold; }));
}

namespace {

/// The checks both count functions share; then count(i, points, areas) for every node holding points.
template <class CountNode>
std::vector<std::uint8_t> count_nodes(const char* what, std::size_t nodes,
                                      std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                                      std::span<const Vec3> points, std::span<const double> areas, double tau,
                                      CountNode&& count) {
  if (nodes != node_ranges.size())
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(nodes) + " boxes for " +
                                std::to_string(node_ranges.size()) + " nodes");
  if (points.size() != areas.size())
    throw std::invalid_argument(std::string(what) + ": areas and points differ in number");
  if (!(tau > 0) || !std::isfinite(tau))
    throw std::invalid_argument(std::string(what) + ": tau must be finite and > 0");
  std::vector<std::uint8_t> out(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i) {
    const auto [first, last] = node_ranges[i];
    if (first > last || last > points.size())
      throw std::invalid_argument(std::string(what) + ": node " + std::to_string(i) +
                                  " has a range past the points");
    if (first == last) continue;
    out[i] = count(i, points.subspan(first, last - first), areas.subspan(first, last - first));
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> point_cell_counts(
    std::span<const Box> node_boxes, std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
    std::span<const Vec3> points, std::span<const double> areas, int grid, double tau) {
  return count_nodes(
      "point_cell_counts", node_boxes.size(), node_ranges, points, areas, tau,
      [&](std::size_t i, std::span<const Vec3> node_points, std::span<const double> node_areas) {
        const auto cells = point_cell_areas(node_boxes[i], grid, node_points, node_areas);
        return count_cells(node_boxes[i], grid, cells, tau);
      });
}

std::vector<std::uint8_t> point_cell_counts_in_frames(
    std::span<const OrientedBox> node_frames,
    std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges, std::span<const Vec3> points,
    std::span<const double> areas, int grid, double tau) {
  std::vector<Vec3> local;
  return count_nodes(
      "point_cell_counts_in_frames", node_frames.size(), node_ranges, points, areas, tau,
      [&](std::size_t i, std::span<const Vec3> node_points, std::span<const double> node_areas) {
        const OrientedBox& frame = node_frames[i];
        Box box;
        if (!frame.empty()) box = {-frame.half, frame.half};
        local.clear();
        for (const Vec3& p : node_points) {
          local.push_back(frame.local(p));
          if (!local.back().allFinite())  // a corrupt frame; Box::extend would skip a NaN silently
            throw std::invalid_argument("point_cell_counts_in_frames: node " + std::to_string(i) +
                                        " has a non-finite frame but holds points");
          box.extend(local.back());  // rounding may put a point just outside [-half, half]
        }
        flatten_thin_axes(box, [&](auto&& set) {  // as the exact annotation in frames
          for (Vec3& v : local) set(v);
        });
        return count_cells(box, grid, point_cell_areas(box, grid, local, node_areas), tau);
      });
}

}  // namespace bvhlab
