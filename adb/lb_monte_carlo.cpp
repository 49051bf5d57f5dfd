#include "adb/lb_monte_carlo.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace bvhlab {
namespace {

Point3d operator-(const Point3d& a, const Point3d& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
Point3d operator+(const Point3d& a, const Point3d& b) {
  return {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
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

// Keeps the part of `poly` with sign * (p[axis] - bound) >= 0.
void clip_against(CubeSection& poly, int axis, double bound, double sign) {
  CubeSection out;
  auto inside = [&](const Point3d& p) { return sign * (p[static_cast<std::size_t>(axis)] - bound); };
  for (int i = 0; i < poly.count; ++i) {
    const Point3d& a = poly.vertices[static_cast<std::size_t>(i)];
    const Point3d& b = poly.vertices[static_cast<std::size_t>((i + 1) % poly.count)];
    const double fa = inside(a);
    const double fb = inside(b);
    if (fa >= 0.0) out.vertices[static_cast<std::size_t>(out.count++)] = a;
    if ((fa >= 0.0) != (fb >= 0.0)) {
      const double t = fa / (fa - fb);
      out.vertices[static_cast<std::size_t>(out.count++)] = a + t * (b - a);
    }
  }
  poly = out;
}

}  // namespace

CubeSection clip_plane_to_unit_cube(const CellPlane& plane) {
  const Point3d& n = plane.normal;
  // An in-plane basis (u, w): cross n with the axis it is least aligned with.
  int least = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::fabs(n[static_cast<std::size_t>(k)]) < std::fabs(n[static_cast<std::size_t>(least)])) least = k;
  }
  Point3d axis{0.0, 0.0, 0.0};
  axis[static_cast<std::size_t>(least)] = 1.0;
  Point3d u = cross(n, axis);
  u = (1.0 / std::sqrt(dot(u, u))) * u;
  const Point3d w = cross(n, u);
  // Every cube point is within sqrt(3) of the origin, so its projection lies within sqrt(3) of the foot
  // point offset * n: a square of half side 2 around the foot covers the whole section.
  const Point3d foot = plane.offset * n;
  CubeSection poly;
  poly.count = 4;
  poly.vertices[0] = foot + (2.0 * u + 2.0 * w);
  poly.vertices[1] = foot + (-2.0 * u + 2.0 * w);
  poly.vertices[2] = foot + (-2.0 * u + -2.0 * w);
  poly.vertices[3] = foot + (2.0 * u + -2.0 * w);
  for (int axis_index = 0; axis_index < 3 && poly.count > 0; ++axis_index) {
    clip_against(poly, axis_index, 0.0, 1.0);
    if (poly.count > 0) clip_against(poly, axis_index, 1.0, -1.0);
  }
  return poly;
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
