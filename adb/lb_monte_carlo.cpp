#include "adb/lb_monte_carlo.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bvhlab {
namespace {

Point3d operator-(const Point3d& a, const Point3d& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Point3d operator*(double k, const Point3d& a) {
  return {k * a[0], k * a[1], k * a[2]};
}
double dot(const Point3d& a, const Point3d& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
Point3d cross(const Point3d& a, const Point3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

struct PlanePoint {  // coordinates in the projection plane of a section
  double u;
  double v;
};

// Sutherland-Hodgman step: keeps the part of the convex polygon `in` where the affine function
// `inside` is >= 0, writing it to `out`.
template <class Inside>
int clip_polygon(const std::array<PlanePoint, 6>& in, int count, std::array<PlanePoint, 6>& out,
                 const Inside& inside) {
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const PlanePoint& a = in[static_cast<std::size_t>(i)];
    const PlanePoint& b = in[static_cast<std::size_t>((i + 1) % count)];
    const double fa = inside(a);
    const double fb = inside(b);
    if (fa >= 0.0) out[static_cast<std::size_t>(kept++)] = a;
    if ((fa >= 0.0) != (fb >= 0.0)) {
      const double t = fa / (fa - fb);
      out[static_cast<std::size_t>(kept++)] = {a.u + t * (b.u - a.u), a.v + t * (b.v - a.v)};
    }
  }
  return kept;
}

}  // namespace

CubeSection clip_plane_to_unit_cube(const CellPlane& plane) {
  // Project along the normal's dominant axis k (|n_k| >= 1/sqrt 3): the section is the graph
  // p_k = (offset - n_i u - n_j v) / n_k over the part of the unit square in (u, v) = (p_i, p_j) where
  // that height lies in [0, 1]. Two 2D clips of a square instead of six 3D clips of a big polygon.
  const Point3d& n = plane.normal;
  std::size_t k = 0;
  for (std::size_t axis = 1; axis < 3; ++axis) {
    if (std::fabs(n[axis]) > std::fabs(n[k])) k = axis;
  }
  const std::size_t i = (k + 1) % 3;
  const std::size_t j = (k + 2) % 3;
  const double sign = n[k] > 0.0 ? 1.0 : -1.0;
  const double n_k_abs = std::fabs(n[k]);
  // |n_k| times the height p_k: must lie in [0, |n_k|].
  const auto scaled_height = [&](const PlanePoint& p) {
    return sign * (plane.offset - n[i] * p.u - n[j] * p.v);
  };

  std::array<PlanePoint, 6> square{{{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}}};
  std::array<PlanePoint, 6> above_floor{};
  const int count_above = clip_polygon(square, 4, above_floor, scaled_height);
  const int count = clip_polygon(above_floor, count_above, square,
                                 [&](const PlanePoint& p) { return n_k_abs - scaled_height(p); });
  CubeSection section;
  if (count < 3) return section;
  section.count = count;
  for (int m = 0; m < count; ++m) {
    const PlanePoint& p = square[static_cast<std::size_t>(m)];
    Point3d& vertex = section.vertices[static_cast<std::size_t>(m)];
    vertex[i] = p.u;
    vertex[j] = p.v;
    vertex[k] = scaled_height(p) / n_k_abs;
  }
  return section;
}

double section_area(const CubeSection& section, const Point3d& unit_normal) {
  if (section.count < 3) return 0.0;
  const Point3d& origin = section.vertices[0];
  double twice_area = 0.0;
  for (int i = 1; i + 1 < section.count; ++i) {
    const Point3d e1 = section.vertices[static_cast<std::size_t>(i)] - origin;
    const Point3d e2 = section.vertices[static_cast<std::size_t>(i + 1)] - origin;
    twice_area += dot(cross(e1, e2), unit_normal);
  }
  return 0.5 * std::fabs(twice_area);
}

bool patch_meets_plane(const CubeSection& patch, const CellPlane& plane) {
  if (patch.count < 1) return false;
  bool below = false;
  bool above = false;
  for (int i = 0; i < patch.count; ++i) {
    const double side = dot(plane.normal, patch.vertices[static_cast<std::size_t>(i)]) - plane.offset;
    below = below || side <= 0.0;
    above = above || side >= 0.0;
  }
  return below && above;
}

CellPlane random_plane_hitting_unit_cube(std::mt19937_64& rng) {
  // The invariant measure is uniform in (direction, offset) jointly, so among planes hitting the cube a
  // direction is drawn in proportion to the cube's width along it. Drawing the offset uniformly over the
  // circumscribed sphere's range (the same for every direction) and rejecting misses does exactly that.
  static const double kCircumradius = 0.5 * std::sqrt(3.0);
  CellPlane plane;
  for (;;) {
    Point3d v;
    double r2 = 0.0;
    do {  // uniform in the unit ball, then projected: uniform on the sphere
      for (double& c : v) c = 2.0 * unit_uniform(rng) - 1.0;
      r2 = dot(v, v);
    } while (r2 > 1.0 || r2 < 1e-8);
    plane.normal = (1.0 / std::sqrt(r2)) * v;
    const double centre = 0.5 * (plane.normal[0] + plane.normal[1] + plane.normal[2]);
    plane.offset = centre + (2.0 * unit_uniform(rng) - 1.0) * kCircumradius;
    double lowest = 0.0;  // extent of the cube along the normal: sums of the negative / positive components
    double highest = 0.0;
    for (double c : plane.normal) (c < 0.0 ? lowest : highest) += c;
    if (plane.offset >= lowest && plane.offset <= highest) return plane;
  }
}

double LbMonteCarloResult::probability() const {
  return pairs == 0 ? 0.0 : static_cast<double>(hits) / static_cast<double>(pairs);
}

double LbMonteCarloResult::standard_error() const {
  if (pairs == 0) return 0.0;
  const double p = probability();
  return std::sqrt(p * (1.0 - p) / static_cast<double>(pairs));
}

LbMonteCarloResult run_lb_monte_carlo(double tau, std::uint64_t pairs, std::uint64_t seed) {
  if (!(tau >= 0.0 && tau <= 1.4)) {
    throw std::invalid_argument("LB Monte Carlo: area threshold tau = " + std::to_string(tau) +
                                " is outside [0, 1.4] (plane sections of a unit cube have area <= sqrt 2)");
  }
  if (pairs == 0) throw std::invalid_argument("LB Monte Carlo: zero sample pairs");
  std::mt19937_64 rng(seed);
  LbMonteCarloResult result{tau, seed, pairs, 0, 0};
  auto draw_patch = [&](CellPlane& plane, CubeSection& section) {
    do {
      plane = random_plane_hitting_unit_cube(rng);
      section = clip_plane_to_unit_cube(plane);
      ++result.planes_drawn;
    } while (section.count < 3 || section_area(section, plane.normal) < tau);
  };
  CellPlane plane_a;
  CellPlane plane_b;
  CubeSection section_a;
  CubeSection section_b;
  for (std::uint64_t i = 0; i < pairs; ++i) {
    draw_patch(plane_a, section_a);
    draw_patch(plane_b, section_b);
    if (patch_meets_plane(section_b, plane_a)) ++result.hits;
  }
  return result;
}

}  // namespace bvhlab
