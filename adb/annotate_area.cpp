// ADB annotation, certified areas: the area of a triangle inside a cell as an interval, by clipping in
// interval arithmetic, by brackets, and by Epeck only where both are uncertain. See adb/annotate.hpp.
#include "adb/annotate.hpp"
#include "adb/annotate_internal.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <vector>

namespace bvhlab {
namespace annotate_detail {
namespace {

using Epeck = CGAL::Epeck;
using Epick = CGAL::Epick;

/// a - b, and whether that double is the exact difference (TwoSum's error term is zero).
bool exact_difference(double a, double b, double& difference) {
  difference = a - b;
  const double b_virtual = difference - a;
  const double a_virtual = difference - b_virtual;
  return (a - a_virtual) + (-b - b_virtual) == 0.0;
}

}  // namespace

ClipProblem shifted(const TrianglePoints& t, const ClipBox& box) {
  ClipProblem out;
  double largest_extent = 0;
  for (int a = 0; a < 3; ++a) {
    const double lo = std::min({t[0][a], t[1][a], t[2][a]}), hi = std::max({t[0][a], t[1][a], t[2][a]});
    largest_extent = std::max(largest_extent, hi - lo);
  }
  for (int a = 0; a < 3; ++a) {
    const double shift = std::min({t[0][a], t[1][a], t[2][a]});
    std::array<double, 3> v{};
    double lo = 0, hi = 0;
    bool exact = true;
    for (int k = 0; k < 3; ++k) exact = exact_difference(t[k][a], shift, v[k]) && exact;
    if (!box.open_lo[a]) exact = exact_difference(box.lo[a], shift, lo) && exact;
    if (!box.open_hi[a]) exact = exact_difference(box.hi[a], shift, hi) && exact;
    if (!exact) {
      for (int k = 0; k < 3; ++k) v[k] = t[k][a];
      lo = box.lo[a];
      hi = box.hi[a];
    }
    for (int k = 0; k < 3; ++k) out.triangle[k][a] = v[k];
    const double t_lo = std::min({v[0], v[1], v[2]}), t_hi = std::max({v[0], v[1], v[2]});
    const double margin = std::max({largest_extent, std::abs(t_lo), std::abs(t_hi)});
    out.lo[a] = box.open_lo[a] ? t_lo - margin : lo;
    out.hi[a] = box.open_hi[a] ? t_hi + margin : hi;
  }
  return out;
}

namespace {

/// Certified area of a planar polygon given by interval points: |sum of fan cross products| / 2.
template <class IntervalPoint>
Bounds polygon_area_bounds(std::span<const IntervalPoint> pts) {
  if (pts.size() < 3) return {};
  CGAL::Protect_FPU_rounding<true> guard;
  Interval v[3] = {Interval(0), Interval(0), Interval(0)};
  const auto& p0 = pts[0];
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const Interval ax = pts[i].x() - p0.x(), ay = pts[i].y() - p0.y(), az = pts[i].z() - p0.z();
    const Interval bx = pts[i + 1].x() - p0.x(), by = pts[i + 1].y() - p0.y(), bz = pts[i + 1].z() - p0.z();
    v[0] += ay * bz - az * by;
    v[1] += az * bx - ax * bz;
    v[2] += ax * by - ay * bx;
  }
  const Interval q = CGAL::square(v[0]) + CGAL::square(v[1]) + CGAL::square(v[2]);
  return to_bounds(CGAL::sqrt(q) * Interval(0.5));
}

Bounds triangle_area_bounds(const TrianglePoints& t) {
  using IPoint = CGAL::Simple_cartesian<Interval>::Point_3;
  const IPoint pts[3] = {IPoint(t[0].x(), t[0].y(), t[0].z()), IPoint(t[1].x(), t[1].y(), t[1].z()),
                         IPoint(t[2].x(), t[2].y(), t[2].z())};
  return polygon_area_bounds<IPoint>(pts);
}

}  // namespace

TriangleInfo make_info(const TrianglePoints& t) {
  TriangleInfo info;
  for (int a = 0; a < 3; ++a) {
    info.min[a] = std::min({t[0][a], t[1][a], t[2][a]});
    info.max[a] = std::max({t[0][a], t[1][a], t[2][a]});
  }
  using P = Epick::Point_3;
  info.degenerate = CGAL::collinear(P(t[0].x(), t[0].y(), t[0].z()), P(t[1].x(), t[1].y(), t[1].z()),
                                    P(t[2].x(), t[2].y(), t[2].z()));
  if (!info.degenerate) info.area = triangle_area_bounds(t);
  return info;
}

namespace {

using IntervalKernel = CGAL::Simple_cartesian<Interval>;
using IntervalPoint = IntervalKernel::Point_3;

/// Certified area of a clipping result (point, segment, triangle or polygon) of kernel K; `approx` maps a
/// K point to an interval point.
template <class K, class Result, class Approx>
Bounds result_area_bounds(const Result& result, Approx&& approx) {
  if (!result) return {};
  std::array<IntervalPoint, 9> points;  // a triangle clipped by 6 planes has at most 9 vertices
  std::size_t n = 0;
  if (const auto* piece = boost::get<typename K::Triangle_3>(&*result)) {
    for (int i = 0; i < 3; ++i) points[n++] = approx(piece->vertex(i));
  } else if (const auto* polygon = boost::get<std::vector<typename K::Point_3>>(&*result)) {
    if (polygon->size() > points.size()) {  // cannot happen for a convex clip; stay certified anyway
      std::vector<IntervalPoint> many;
      for (const auto& p : *polygon) many.push_back(approx(p));
      return polygon_area_bounds<IntervalPoint>(many);
    }
    for (const auto& p : *polygon) points[n++] = approx(p);
  } else {
    return {};  // a point or a segment
  }
  return polygon_area_bounds<IntervalPoint>(std::span<const IntervalPoint>(points.data(), n));
}

/// CGAL::intersection in interval arithmetic (what Epeck does first internally, without building its lazy
/// DAG). Empty when one of its decisions is uncertain: a vertex on or very near a clipping plane.
std::optional<Bounds> interval_clip(const ClipProblem& problem) {
  try {
    CGAL::Protect_FPU_rounding<true> guard;
    using P = IntervalPoint;
    const TrianglePoints& t = problem.triangle;
    const IntervalKernel::Triangle_3 tri(P(t[0].x(), t[0].y(), t[0].z()), P(t[1].x(), t[1].y(), t[1].z()),
                                         P(t[2].x(), t[2].y(), t[2].z()));
    const IntervalKernel::Iso_cuboid_3 cuboid(P(problem.lo[0], problem.lo[1], problem.lo[2]),
                                              P(problem.hi[0], problem.hi[1], problem.hi[2]));
    const auto result = CGAL::intersection(tri, cuboid);
    return result_area_bounds<IntervalKernel>(result, [](const P& p) { return p; });
  } catch (const CGAL::Uncertain_conversion_exception&) {
    return std::nullopt;
  }
}

}  // namespace

Bounds clipped_area_bounds(const TrianglePoints& t, const ClipBox& box) {
  if (const auto area = interval_clip(shifted(t, box))) return *area;
  ClipBox inner = box, outer = box;
  bool inner_empty = false;
  // One length for all axes, times a different factor per axis: a hair proportional to each cell's own
  // width would move the two planes through a box-diagonal edge by the same edge parameter and rebuild the
  // very coincidence it is meant to break.
  double length = 0;
  for (int a = 0; a < 3; ++a)
    if (!box.open_lo[a] || !box.open_hi[a]) length = std::max(length, box.hi[a] - box.lo[a]);
  constexpr double kFactor[3] = {1.0, 1.3819660112501051, 1.6180339887498949};
  for (int a = 0; a < 3; ++a) {
    const double hair =
        kFactor[a] * std::max(length * 0x1p-26, (std::abs(box.lo[a]) + std::abs(box.hi[a])) * 0x1p-40);
    if (!box.open_lo[a]) inner.lo[a] += hair, outer.lo[a] -= hair;
    if (!box.open_hi[a]) inner.hi[a] -= hair, outer.hi[a] += hair;
    inner_empty = inner_empty || !(inner.lo[a] < inner.hi[a]);
  }
  const std::optional<Bounds> lower =
      inner_empty ? std::optional<Bounds>(Bounds{}) : interval_clip(shifted(t, inner));
  const std::optional<Bounds> upper = interval_clip(shifted(t, outer));
  if (lower && upper) return {lower->lo, upper->hi};

  using P = Epeck::Point_3;
  const ClipProblem problem = shifted(t, box);
  const TrianglePoints& s = problem.triangle;
  const Epeck::Triangle_3 tri(point<Epeck>(s[0]), point<Epeck>(s[1]), point<Epeck>(s[2]));
  const Epeck::Iso_cuboid_3 cuboid(P(problem.lo[0], problem.lo[1], problem.lo[2]),
                                   P(problem.hi[0], problem.hi[1], problem.hi[2]));
  const auto result = CGAL::intersection(tri, cuboid);
  return result_area_bounds<Epeck>(result, [](const P& p) { return CGAL::approx(p); });
}

}  // namespace annotate_detail

double triangle_area_in_box(const TrianglePoints& triangle, const Box& cell) {
  using namespace annotate_detail;
  for (const auto& v : triangle)
    if (!v.allFinite()) throw std::invalid_argument("triangle_area_in_box: non-finite vertex");
  if (cell.empty()) return 0;
  const TriangleInfo info = make_info(triangle);
  if (info.degenerate) return 0;
  const Grid grid(cell, 1);
  const Placement p = place(grid, info);
  if (p.outside) return 0;
  if (p.inside_cell) return 0.5 * (info.area.lo + info.area.hi);
  ClipBox clip;
  if (!make_clip_box(grid, info, p, {0, 0, 0}, clip)) return 0;
  const Bounds area = clipped_area_bounds(triangle, clip);
  return 0.5 * (area.lo + area.hi);
}

}  // namespace bvhlab
