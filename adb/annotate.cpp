// ADB density annotation. See adb/annotate.hpp for the definitions and the exactness argument.
#include "adb/annotate.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Interval_nt.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace bvhlab {
namespace {

using Epeck = CGAL::Epeck;
using Epick = CGAL::Epick;
// The rare exact decisions use plain rationals: Epeck's exact number type depends on CGAL's configuration,
// GMP's mpq is what the sqrt-sum comparison below needs.
using RationalKernel = CGAL::Simple_cartesian<CGAL::Gmpq>;
using Interval = CGAL::Interval_nt<false>;  // needs Protect_FPU_rounding around its arithmetic

constexpr int kMaxGrid = 6;
constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

/// A certified enclosure [lo, hi] of a nonnegative area.
struct Bounds {
  double lo = 0;
  double hi = 0;
};

struct TriangleInfo {
  std::array<double, 3> min{};
  std::array<double, 3> max{};
  Bounds area;
  bool degenerate = false;
};

/// The box a triangle is clipped against: per axis the two cell planes, or `open` for a face that cannot cut
/// the triangle (it is then placed well outside the triangle when the cuboid is built).
struct ClipBox {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
  std::array<bool, 3> open_lo{};
  std::array<bool, 3> open_hi{};
};

/// Inclusive range of cell indices along one axis; empty when first > last.
struct AxisCells {
  int first = 0;
  int last = -1;
  [[nodiscard]] bool empty() const { return first > last; }
};

/// Cell boundaries of one node: c[axis][0..g], nondecreasing, c[axis][0] = lo, c[axis][g] = hi.
struct Grid {
  int g = 0;
  std::array<std::array<double, kMaxGrid + 1>, 3> c{};

  Grid(const Box& box, int cells_per_axis) : g(cells_per_axis) {
    for (int a = 0; a < 3; ++a) {
      const double lo = box.min[a], hi = box.max[a];
      c[a][0] = lo;
      for (int i = 1; i < g; ++i) c[a][i] = std::min(hi, lo + (hi - lo) * i / g);
      c[a][g] = hi;
    }
  }

  /// Cells whose closed slab meets [mn, mx] along `axis`.
  [[nodiscard]] AxisCells touched(int axis, double mn, double mx) const {
    AxisCells r{g, -1};
    for (int i = 0; i < g; ++i)
      if (c[axis][i + 1] >= mn) {
        r.first = i;
        break;
      }
    for (int i = g - 1; i >= 0; --i)
      if (c[axis][i] <= mx) {
        r.last = i;
        break;
      }
    return r;
  }

  /// Cells whose closed slab contains [mn, mx] along `axis` (two when [mn, mx] is a shared boundary).
  [[nodiscard]] AxisCells containing(int axis, AxisCells touch, double mn, double mx) const {
    AxisCells r{g, -1};
    for (int i = touch.first; i <= touch.last; ++i)
      if (c[axis][i] <= mn && mx <= c[axis][i + 1]) {
        r.first = std::min(r.first, i);
        r.last = i;
      }
    return r;
  }
};

/// How a triangle meets a node's grid.
struct Placement {
  bool outside = false;  ///< misses the grid (cannot happen for a valid tree)
  bool inside_cell = true;
  std::array<AxisCells, 3> candidate{};  ///< per axis: containing cells if any, else touched cells
  std::array<bool, 3> contained{};       ///< per axis: the candidates contain the triangle's extent
};

Placement place(const Grid& grid, const TriangleInfo& t) {
  Placement p;
  for (int a = 0; a < 3; ++a) {
    const AxisCells touch = grid.touched(a, t.min[a], t.max[a]);
    if (touch.empty()) {
      p.outside = true;
      return p;
    }
    const AxisCells contain = grid.containing(a, touch, t.min[a], t.max[a]);
    p.contained[a] = !contain.empty();
    // A touched cell that does not contain the extent while another one does meets the triangle in a
    // zero-thickness slab only: no area there, so it is not a candidate.
    p.candidate[a] = p.contained[a] ? contain : touch;
    p.inside_cell = p.inside_cell && p.contained[a];
  }
  return p;
}

/// The box to clip against for cell (i, j, k). A face that cannot cut the triangle is left open: both faces
/// along an axis where the cell contains the triangle's extent, and the grid's outer faces when the triangle
/// lies on their inner side (always, in a valid tree). The clipped polygon is the same, a zero-width slab
/// (flat node) never reaches CGAL as a degenerate cuboid, and, above all, a vertex lying exactly on the node
/// box (the box is fitted to the vertices, so every node has such vertices) does not make an interval
/// decision uncertain. Returns false when the cell meets the triangle in zero area: a zero-width slab that
/// does not contain the triangle's extent.
bool make_clip_box(const Grid& grid, const TriangleInfo& t, const Placement& p,
                   const std::array<int, 3>& cell, ClipBox& out) {
  for (int a = 0; a < 3; ++a) {
    const int g = grid.g;
    out.lo[a] = grid.c[a][cell[a]];
    out.hi[a] = grid.c[a][cell[a] + 1];
    if (p.contained[a]) {
      out.open_lo[a] = out.open_hi[a] = true;
    } else {
      if (!(out.lo[a] < out.hi[a])) return false;
      out.open_lo[a] = cell[a] == 0 && t.min[a] >= out.lo[a];
      out.open_hi[a] = cell[a] == g - 1 && t.max[a] <= out.hi[a];
    }
  }
  return true;
}

/// a - b, and whether that double is the exact difference (TwoSum's error term is zero).
bool exact_difference(double a, double b, double& difference) {
  difference = a - b;
  const double b_virtual = difference - a;
  const double a_virtual = difference - b_virtual;
  return (a - a_virtual) + (-b - b_virtual) == 0.0;
}

/// A clip problem in concrete coordinates.
struct ClipProblem {
  TrianglePoints triangle;
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
};

/// The clip problem translated, per axis, by the triangle's smallest coordinate whenever every subtraction
/// involved is exact (Sterbenz: values within a factor 2 of each other), so it is the same problem with
/// small coordinates: a leaf of the 871k dragon is 1e-4 wide at coordinates near 1, and interval arithmetic
/// on the raw coordinates loses four more digits in every clipping step. Open faces are placed one triangle
/// extent outside the triangle.
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

Bounds to_bounds(const Interval& x) {
  return {std::max(0.0, x.inf()), x.sup()};
}

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

template <class K>
typename K::Point_3 point(const Vec3& v) {
  return typename K::Point_3(v.x(), v.y(), v.z());
}

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

/// Certified area of triangle ∩ box.
/// Interval decisions are uncertain in one frequent structural case: a leaf's box is its triangle's bounding
/// box, so when the mesh coordinates are floats the mid-planes of two axes meet exactly on the edge that
/// spans the box diagonally, and the clipped vertex on one plane lies exactly on the next. Recomputing such a
/// clip in rationals (Epeck's fallback) costs about 100 times more. Instead the area is bracketed: the area
/// inside a box is monotone under inclusion, so the clips against the box shrunk and grown by a hair (about
/// 2^-26 of the cell, at least 2^-40 of its coordinates) bound it from below and above. The bracket is
/// narrower than any realistic margin to the threshold; cells it leaves undecided go to the exact decision.
/// Only if the bracketing clips are uncertain too does Epeck compute the exact polygon.
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

// ---- exact decisions -------------------------------------------------------------------------------------

using Rational = CGAL::Gmpq;

template <class Points>
Rational polygon_squared_area(const Points& pts) {
  if (pts.size() < 3) return Rational(0);
  Rational v[3] = {0, 0, 0};
  for (std::size_t i = 1; i + 1 < pts.size(); ++i) {
    const auto a = pts[i] - pts[0];
    const auto b = pts[i + 1] - pts[0];
    const auto c = CGAL::cross_product(a, b);
    v[0] += c.x();
    v[1] += c.y();
    v[2] += c.z();
  }
  return (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / Rational(4);
}

/// Exact squared area of triangle ∩ box.
Rational clipped_squared_area_exact(const TrianglePoints& t, const ClipBox& box) {
  using K = RationalKernel;
  using P = K::Point_3;
  const ClipProblem problem = shifted(t, box);
  const TrianglePoints& s = problem.triangle;
  const K::Triangle_3 tri(point<K>(s[0]), point<K>(s[1]), point<K>(s[2]));
  const K::Iso_cuboid_3 cuboid(P(problem.lo[0], problem.lo[1], problem.lo[2]),
                               P(problem.hi[0], problem.hi[1], problem.hi[2]));
  const auto result = CGAL::intersection(tri, cuboid);
  if (!result) return Rational(0);
  if (const auto* piece = boost::get<K::Triangle_3>(&*result))
    return polygon_squared_area(std::array<P, 3>{piece->vertex(0), piece->vertex(1), piece->vertex(2)});
  if (const auto* polygon = boost::get<std::vector<P>>(&*result)) return polygon_squared_area(*polygon);
  return Rational(0);
}

Rational triangle_squared_area_exact(const TrianglePoints& t) {
  using K = RationalKernel;
  return polygon_squared_area(std::array<K::Point_3, 3>{point<K>(t[0]), point<K>(t[1]), point<K>(t[2])});
}

bool is_perfect_square(const Rational& q) {
  return mpz_perfect_square_p(mpq_numref(q.mpq())) != 0 && mpz_perfect_square_p(mpq_denref(q.mpq())) != 0;
}

/// Whether sum_i sqrt(squares[i]) >= threshold, exactly (squares[i] > 0, threshold >= 0 rational).
/// When every square is a perfect square the sum is rational and compared exactly. Otherwise grouping the
/// terms by the square-free part of their radicands shows the sum is irrational (square roots of distinct
/// square-free integers are linearly independent over Q and every coefficient is positive), so it differs
/// from the rational threshold, and refining MPFR enclosures with growing precision must separate them.
bool sqrt_sum_at_least(const std::vector<Rational>& squares, const Rational& threshold) {
  if (std::all_of(squares.begin(), squares.end(), is_perfect_square)) {
    mpq_t sum, root;
    mpq_init(sum);
    mpq_init(root);
    for (const Rational& q : squares) {
      mpz_sqrt(mpq_numref(root), mpq_numref(q.mpq()));
      mpz_sqrt(mpq_denref(root), mpq_denref(q.mpq()));
      mpq_canonicalize(root);
      mpq_add(sum, sum, root);
    }
    const bool at_least = mpq_cmp(sum, threshold.mpq()) >= 0;
    mpq_clear(sum);
    mpq_clear(root);
    return at_least;
  }
  for (mpfr_prec_t precision = 128; precision <= (mpfr_prec_t{1} << 22); precision *= 2) {
    mpfr_t lo, hi, term, t_lo, t_hi;
    for (mpfr_ptr x : {lo, hi, term, t_lo, t_hi}) mpfr_init2(x, precision);
    mpfr_set_zero(lo, 1);
    mpfr_set_zero(hi, 1);
    for (const Rational& q : squares) {
      mpfr_set_q(term, q.mpq(), MPFR_RNDD);
      mpfr_sqrt(term, term, MPFR_RNDD);
      mpfr_add(lo, lo, term, MPFR_RNDD);
      mpfr_set_q(term, q.mpq(), MPFR_RNDU);
      mpfr_sqrt(term, term, MPFR_RNDU);
      mpfr_add(hi, hi, term, MPFR_RNDU);
    }
    mpfr_set_q(t_lo, threshold.mpq(), MPFR_RNDD);
    mpfr_set_q(t_hi, threshold.mpq(), MPFR_RNDU);
    const int decided = mpfr_cmp(lo, t_hi) >= 0 ? 1 : (mpfr_cmp(hi, t_lo) < 0 ? 0 : -1);
    for (mpfr_ptr x : {lo, hi, term, t_lo, t_hi}) mpfr_clear(x);
    if (decided >= 0) return decided == 1;
  }
  throw std::logic_error("annotate: exact area comparison did not separate at 4M bits");
}

/// tau * mean cell face area, exactly.
Rational exact_threshold(const Box& box, int g, double tau) {
  Rational a[3];
  for (int k = 0; k < 3; ++k) a[k] = (Rational(box.max[k]) - Rational(box.min[k])) / Rational(g);
  return Rational(tau) * (a[0] * a[1] + a[1] * a[2] + a[2] * a[0]) / Rational(3);
}

// ---- the per-node work -----------------------------------------------------------------------------------

struct CellSum {
  double lo = 0;
  double hi = 0;
  std::uint32_t terms = 0;
};

/// Certified bounds of a sum of nonnegative terms accumulated in round-to-nearest: |fl(S) - S| <= gamma S
/// with gamma = (n - 1) u / (1 - (n - 1) u) <= 2 n u; widened generously, then one more ulp for the product.
Bounds certified(const CellSum& s) {
  const double gamma = 4.0 * (static_cast<double>(s.terms) + 1.0) * kUnitRoundoff;
  const double lo = std::nextafter(std::nextafter(s.lo * (1.0 - gamma), 0.0), 0.0);
  const double hi = std::nextafter(std::nextafter(s.hi * (1.0 + gamma), INFINITY), INFINITY);
  return {std::max(0.0, lo), hi};
}

struct ThreadStats {
  std::size_t fast = 0, clipped = 0, clip_calls = 0, skipped_clips = 0, derived_areas = 0, degenerate = 0,
              exact_cells = 0;
};

struct Worker {
  ThreadStats stats;
  std::vector<std::uint32_t> pending;  ///< scratch: the current node's triangles that need clipping
};

struct Job {
  std::span<const Box> boxes;
  std::span<const std::pair<std::uint32_t, std::uint32_t>> ranges;
  std::span<const TrianglePoints> triangles;
  std::span<const TriangleInfo> infos;
  int g = 2;
  double tau = kDefaultAdbTau;
};

template <class F>
void for_each_candidate_cell(const Placement& p, F&& f) {
  for (int i = p.candidate[0].first; i <= p.candidate[0].last; ++i)
    for (int j = p.candidate[1].first; j <= p.candidate[1].last; ++j)
      for (int k = p.candidate[2].first; k <= p.candidate[2].last; ++k) f(std::array<int, 3>{i, j, k});
}

/// Decides one cell of node `node` exactly (ties and near-ties only).
bool cell_counts_exactly(const Job& job, std::uint32_t node, const Grid& grid,
                         const std::array<int, 3>& cell) {
  std::vector<Rational> squares;
  for (std::uint32_t t = job.ranges[node].first; t < job.ranges[node].second; ++t) {
    const TriangleInfo& info = job.infos[t];
    if (info.degenerate) continue;
    const Placement p = place(grid, info);
    if (p.outside) continue;
    bool candidate = true;
    for (int a = 0; a < 3; ++a)
      candidate = candidate && p.candidate[a].first <= cell[a] && cell[a] <= p.candidate[a].last;
    if (!candidate) continue;
    Rational q;
    if (p.inside_cell) {
      q = triangle_squared_area_exact(job.triangles[t]);
    } else {
      ClipBox box;
      if (!make_clip_box(grid, info, p, cell, box)) continue;
      q = clipped_squared_area_exact(job.triangles[t], box);
    }
    if (CGAL::sign(q) > 0) squares.push_back(std::move(q));
  }
  if (squares.empty()) return false;  // zero area never counts
  return sqrt_sum_at_least(squares, exact_threshold(job.boxes[node], grid.g, job.tau));
}

/// What is known about one cell of the node being counted.
struct CellState {
  enum class Decision : std::uint8_t { Open, Counts, DoesNotCount };
  CellSum known;             ///< areas of fast-path triangles and of clipped pieces so far
  double pending = 0;        ///< sum of the area upper bounds of candidate triangles not clipped yet
  double pending_total = 0;  ///< that sum before any was clipped (scales its rounding error)
  std::uint32_t pending_count = 0;
  std::uint32_t pending_ops = 0;  ///< additions and subtractions applied to `pending`
  Decision decision = Decision::Open;

  /// Decides the cell when the bounds allow: counted once its certain area reaches the threshold, not
  /// counted once even the largest possible area (known + every pending triangle in full) stays below it.
  void decide(const Bounds& threshold) {
    const Bounds area = certified(known);
    if (area.lo > 0 && area.lo >= threshold.hi) {
      decision = Decision::Counts;
      return;
    }
    double upper = area.hi;
    if (pending_count > 0) {
      // `pending` went through pending_ops roundings of magnitude at most u * pending_total each.
      const double slack = 4.0 * (pending_ops + 2.0) * kUnitRoundoff * pending_total;
      upper = std::nextafter(upper + std::max(0.0, pending) + slack, INFINITY);
    }
    if (upper <= 0 || upper < threshold.lo) decision = Decision::DoesNotCount;
  }
};

/// pc of one node. Fast-path triangles first; then a clipped triangle is clipped only against candidate
/// cells the bounds have not decided yet (most cells of a large node are decided by their fast-path area).
std::uint8_t count_node(const Job& job, std::uint32_t node, Worker& worker) {
  ThreadStats& stats = worker.stats;
  const auto [begin, end] = job.ranges[node];
  if (begin == end) return 0;
  const Box& box = job.boxes[node];
  if (box.empty() || !box.min.allFinite() || !box.max.allFinite() || !(box.max - box.min).allFinite())
    throw std::invalid_argument("annotate: node " + std::to_string(node) +
                                " has an empty or non-finite bounding box but holds triangles");
  const Grid grid(box, job.g);
  const int g = job.g;

  Bounds threshold;
  {
    CGAL::Protect_FPU_rounding<true> guard;
    Interval a[3];
    for (int k = 0; k < 3; ++k) a[k] = (Interval(box.max[k]) - Interval(box.min[k])) / Interval(g);
    const Interval t = Interval(job.tau) * (a[0] * a[1] + a[1] * a[2] + a[2] * a[0]) / Interval(3);
    threshold = to_bounds(t);
  }

  std::array<CellState, kMaxGrid * kMaxGrid * kMaxGrid> cells{};
  auto index = [g](const std::array<int, 3>& c) { return (c[0] * g + c[1]) * g + c[2]; };
  std::vector<std::uint32_t>& pending = worker.pending;
  pending.clear();

  for (std::uint32_t t = begin; t < end; ++t) {
    const TriangleInfo& info = job.infos[t];
    if (info.degenerate) {
      ++stats.degenerate;
      continue;
    }
    const Placement p = place(grid, info);
    if (p.outside) continue;
    if (p.inside_cell) {
      ++stats.fast;
      for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
        CellSum& s = cells[index(c)].known;
        s.lo += info.area.lo;
        s.hi += info.area.hi;
        ++s.terms;
      });
    } else {
      ++stats.clipped;
      pending.push_back(t);
      for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
        CellState& cell = cells[index(c)];
        cell.pending += info.area.hi;
        ++cell.pending_count;
        ++cell.pending_ops;
      });
    }
  }
  for (CellState& cell : cells) {
    cell.pending_total = cell.pending;
    if (cell.known.terms + cell.pending_count > 0) cell.decide(threshold);
  }

  // The candidate cells of a clipped triangle partition it (they overlap in cell planes only, which a
  // triangle spanning a positive extent across them meets in segments), unless an axis has two containing
  // cells (the triangle lies in their shared plane). So when every candidate is still open, the last one's
  // area is the triangle's minus the others': one clip fewer per triangle.
  std::vector<std::array<int, 3>> candidates;
  for (const std::uint32_t t : pending) {
    const TriangleInfo& info = job.infos[t];
    const Placement p = place(grid, info);
    candidates.clear();
    bool all_open = true;
    for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
      candidates.push_back(c);
      all_open = all_open && cells[index(c)].decision == CellState::Decision::Open;
    });
    bool partition = all_open && candidates.size() >= 2;
    for (int a = 0; a < 3; ++a)
      partition = partition && (!p.contained[a] || p.candidate[a].first == p.candidate[a].last);
    std::array<ClipBox, kMaxGrid * kMaxGrid * kMaxGrid> boxes;
    std::array<bool, kMaxGrid * kMaxGrid * kMaxGrid> has_area{};
    std::size_t derived = candidates.size();  // the candidate whose area is derived, if any
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      has_area[k] = make_clip_box(grid, info, p, candidates[k], boxes[k]);
      if (partition && has_area[k]) derived = k;
    }
    Interval rest(info.area.lo, info.area.hi);
    auto add = [&](CellState& cell, const Bounds& area) {
      if (area.hi > 0) {
        cell.known.lo += area.lo;
        cell.known.hi += area.hi;
        ++cell.known.terms;
      }
      cell.pending -= info.area.hi;
      --cell.pending_count;
      ++cell.pending_ops;
      cell.decide(threshold);
    };
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      CellState& cell = cells[index(candidates[k])];
      if (cell.decision != CellState::Decision::Open) {
        ++stats.skipped_clips;
        continue;
      }
      if (k == derived) continue;
      Bounds area;
      if (has_area[k]) {
        ++stats.clip_calls;
        area = clipped_area_bounds(job.triangles[t], boxes[k]);
        if (derived < candidates.size()) {
          CGAL::Protect_FPU_rounding<true> guard;
          rest -= Interval(area.lo, area.hi);
        }
      }
      add(cell, area);
    }
    if (derived < candidates.size()) {
      ++stats.derived_areas;
      add(cells[index(candidates[derived])], to_bounds(rest));
    }
  }

  int count = 0;
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j)
      for (int k = 0; k < g; ++k) {
        const std::array<int, 3> c{i, j, k};
        const CellState& cell = cells[index(c)];
        if (cell.known.terms + cell.pending_count == 0) continue;
        switch (cell.decision) {
          case CellState::Decision::Counts:
            ++count;
            break;
          case CellState::Decision::DoesNotCount:
            break;
          case CellState::Decision::Open:  // a tie or a near-tie: decide exactly
            ++stats.exact_cells;
            if (cell_counts_exactly(job, node, grid, c)) ++count;
            break;
        }
      }
  return static_cast<std::uint8_t>(count);
}

}  // namespace

double triangle_area_in_box(const TrianglePoints& triangle, const Box& cell) {
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

CellCounts annotate_counts(std::span<const Box> node_boxes,
                           std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                           std::span<const TrianglePoints> triangles, int grid,
                           const AnnotateOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (grid < 1 || grid > kMaxGrid)
    throw std::invalid_argument("annotate: grid must be 1..6 cells per axis, got " + std::to_string(grid));
  if (!std::isfinite(options.tau) || !(options.tau > 0))
    throw std::invalid_argument("annotate: tau must be finite and > 0, got " + std::to_string(options.tau));
  if (node_boxes.size() != node_ranges.size())
    throw std::invalid_argument("annotate: " + std::to_string(node_boxes.size()) + " node boxes but " +
                                std::to_string(node_ranges.size()) + " node ranges");
  std::size_t total_pairs = 0;
  for (std::size_t i = 0; i < node_ranges.size(); ++i) {
    const auto [b, e] = node_ranges[i];
    if (b > e || e > triangles.size())
      throw std::invalid_argument("annotate: node " + std::to_string(i) + " has triangle range [" +
                                  std::to_string(b) + ", " + std::to_string(e) + ") outside the " +
                                  std::to_string(triangles.size()) + " triangles");
    total_pairs += e - b;
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const auto& v : triangles[t])
      if (!v.allFinite())
        throw std::invalid_argument("annotate: triangle " + std::to_string(t) + " has a non-finite vertex");

  unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  threads =
      static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, node_boxes.size() / 64)));

  std::vector<TriangleInfo> infos(triangles.size());
  std::vector<std::uint8_t> counts(node_boxes.size(), 0);
  std::vector<Worker> workers(threads);
  const Job job{node_boxes, node_ranges, triangles, infos, grid, options.tau};

  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done_pairs{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex mutex;  // guards `error` and the progress callback
  std::atomic<std::size_t> reported{0};
  const std::size_t report_step = std::max<std::size_t>(1, total_pairs / 200);

  auto run_parallel = [&](auto&& body, std::size_t items, std::size_t chunk) {
    next = 0;
    auto worker = [&](unsigned id) {
      try {
        for (;;) {
          if (failed) return;
          const std::size_t first = next.fetch_add(chunk);
          if (first >= items) return;
          body(id, first, std::min(items, first + chunk));
        }
      } catch (...) {
        std::lock_guard lock(mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    };
    std::vector<std::thread> pool;
    for (unsigned id = 1; id < threads; ++id) pool.emplace_back(worker, id);
    worker(0);
    for (auto& th : pool) th.join();
    if (error) std::rethrow_exception(error);
  };

  run_parallel(
      [&](unsigned, std::size_t first, std::size_t last) {
        for (std::size_t t = first; t < last; ++t) infos[t] = make_info(triangles[t]);
      },
      triangles.size(), 4096);

  run_parallel(
      [&](unsigned id, std::size_t first, std::size_t last) {
        std::size_t pairs = 0;
        for (std::size_t n = first; n < last; ++n) {
          counts[n] = count_node(job, static_cast<std::uint32_t>(n), workers[id]);
          pairs += node_ranges[n].second - node_ranges[n].first;
        }
        const std::size_t done = done_pairs.fetch_add(pairs) + pairs;
        if (options.progress && done >= reported.load() + report_step) {
          std::lock_guard lock(mutex);
          if (done > reported.load()) {
            reported = done;
            options.progress(done, total_pairs);
          }
        }
      },
      node_boxes.size(), 16);
  if (options.progress) options.progress(total_pairs, total_pairs);

  CellCounts out;
  out.counts = std::move(counts);
  AnnotateStats& s = out.stats;
  s.threads = threads;
  s.nodes = node_boxes.size();
  s.triangle_node_pairs = total_pairs;
  for (const Worker& w : workers) {
    const ThreadStats& t = w.stats;
    s.fast_path_triangles += t.fast;
    s.clipped_triangles += t.clipped;
    s.clip_calls += t.clip_calls;
    s.skipped_clips += t.skipped_clips;
    s.derived_areas += t.derived_areas;
    s.degenerate_triangles += t.degenerate;
    s.exact_cells += t.exact_cells;
  }
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace bvhlab
