// ADB annotation, exact decisions: a cell whose certified area bounds straddle the threshold is decided with
// exact rational areas and an exact comparison of a sum of square roots (GMP, MPFR). See adb/annotate.hpp.
#include "adb/annotate_internal.hpp"

#include <CGAL/Gmpq.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/intersections.h>
#include <gmp.h>
#include <mpfr.h>

#include <algorithm>
#include <array>
#include <stdexcept>
#include <vector>

namespace bvhlab::annotate_detail {
namespace {

// The rare exact decisions use plain rationals: Epeck's exact number type depends on CGAL's configuration,
// GMP's mpq is what the sqrt-sum comparison below needs.
using RationalKernel = CGAL::Simple_cartesian<CGAL::Gmpq>;
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

}  // namespace

bool cell_counts_exactly(const Grid& grid, const std::array<int, 3>& cell, const Box& node_box, double tau,
                         std::span<const TrianglePoints> triangles, std::span<const TriangleInfo> infos) {
  std::vector<Rational> squares;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const TriangleInfo& info = infos[t];
    if (info.degenerate) continue;
    const Placement p = place(grid, info);
    if (p.outside) continue;
    bool candidate = true;
    for (int a = 0; a < 3; ++a)
      candidate = candidate && p.candidate[a].first <= cell[a] && cell[a] <= p.candidate[a].last;
    if (!candidate) continue;
    Rational q;
    if (p.inside_cell) {
      q = triangle_squared_area_exact(triangles[t]);
    } else {
      ClipBox box;
      if (!make_clip_box(grid, info, p, cell, box)) continue;
      q = clipped_squared_area_exact(triangles[t], box);
    }
    if (CGAL::sign(q) > 0) squares.push_back(std::move(q));
  }
  if (squares.empty()) return false;  // zero area never counts
  return sqrt_sum_at_least(squares, exact_threshold(node_box, grid.g, tau));
}

}  // namespace bvhlab::annotate_detail
