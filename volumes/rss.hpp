// Rectangle swept sphere (RSS): the points within `radius` of a rectangle, the volume PQP and FCL use for
// proximity queries. Its overlap test and its distance bound are one computation, the distance between the
// two rectangles, so the bound is the distance between the volumes themselves (less the rounding slack), not
// the gap on a few projection axes.
//
// Storage (40 bytes), as the OBB's: the frame as a float quaternion (columns 0 and 1 of Obb::axes_of span the
// rectangle, column 2 is its normal), the centre, the two half-lengths and the radius as floats. The fit
// measures the radius in double, then widens it by what rounding the frame and the centre to float can move
// the rectangle (2^-21 of its half-diagonal, 2^-24 of |c|) and rounds it up, so the stored volume holds every
// point; the half-lengths are rounded up, which only grows the rectangle.
//
// Fit: a frame from the points' covariance, or the coordinate axes when they give a smaller volume (as the
// OBB's). The frame axis along which the points are thinnest is the normal and the radius spans their
// thickness along it. The rectangle need not reach every point: one inside the slab may lie beyond an edge by
// up to sqrt(r^2 - z^2) (z: its height over the mid-plane), so the sides are drawn in that far, and pushed
// out again where a point beyond a corner needs it. The radius is then measured, so these choices affect the
// volume's size only, never whether it holds the points.
// Merge fits, the same way, the 8 corners of the two rectangles, each a ball of its volume's radius.
//
// No oriented_box() (FramedVolume): an RSS is no box, and the ADB estimate in the nodes' frames would take
// the box around it, corners included, for the node; whether that is worth it is for when the RSS is
// registered. Until then the ADB grid lies on bounding_box(), as for spheres and DOPs.
//
// Overlap and distance: in A's rectangle frame, the minimum over the 8 edges (4 per rectangle) of the edge's
// distance to the other rectangle. That is the rectangles' distance: where they are apart some nearest pair
// has a point on an edge (two nearest points interior to both rectangles are joined by a common normal, and
// sliding both along the then parallel planes reaches an edge); where they meet, an edge of one meets the
// other (an end of the segment both share on the planes' common line, or, coplanar, a crossing edge or a
// vertex inside). A zero half-length makes a rectangle a segment or a point: its "edges" then cover it.
// The squared distance from a point of an edge to the other rectangle is, along the edge, convex and
// piecewise quadratic: its minimum is the best of a few stationary points, one per cell of the rectangle's
// plane the edge crosses, each evaluated whole. An ill-conditioned one (an edge nearly parallel to the plane
// or to a side) errs only where the function is flat, so parallel, coplanar and degenerate rectangles need no
// special case, and the distance comes out within a few ulps of the coordinates (tests/volumes/test_rss.cpp
// checks it against CGAL's exact distance).
// That costs up to a few thousand instructions a pair, so the distance bound first looks for a separating
// direction (detail::separation, a hundred or so): one step of alternating projection between the rectangles
// gives a pair of points, and the gap along the line through them bounds the distance from below. Where that
// gap exceeds the radii (and the slack) the volumes are apart and the gap, less the radii, is the bound; only
// the other pairs (near contact, about one in fifty tested far apart on the protocol) take the edges. The
// bound is then within a small share of the distance rather than equal to it (tests/volumes/test_rss.cpp
// measures it).
#pragma once

#include "concept.hpp"
#include "obb.hpp"
#include "storage.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>

namespace bvhlab {

namespace rss {

/// A closed rectangle: centre, two orthonormal axes and a half-length along each (0 allowed: then a segment
/// or a point).
struct Rectangle {
  Vec3 center = Vec3::Zero();
  Vec3 axis0 = Vec3::UnitX(), axis1 = Vec3::UnitY();
  double half0 = 0, half1 = 0;
};

namespace detail {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInfinity = std::numeric_limits<double>::infinity();

inline double square(double x) {
  return x * x;
}

/// Squared distance from x to the interval [-h, h].
inline double outside_squared(double x, double h) {
  const double beyond = std::max(0.0, std::abs(x) - h);
  return beyond * beyond;
}

/// Squared distance from the segment p + r d (|r| <= h, d unit) to the rectangle K = [-hx, hx] x [-hy, hy]
/// x {0}, or `best` when it is not smaller. Along the segment it is F(r) = outside(X)^2 + outside(Y)^2 + Z^2:
/// convex, and on each cell of K's plane (X below, within or above [-hx, hx], the same for Y) a quadratic.
/// F's minimum is the stationary point of the cell holding it or an end of the segment, so it is among the
/// cells' stationary points clamped to the segment. F is evaluated whole at each: a cell whose quadratic is
/// nearly flat (a segment nearly parallel to K's plane or to one of its sides) has an ill-conditioned
/// stationary point, but only along its flat direction, where F barely changes; a move that crosses into a
/// neighbouring cell is caught by that cell's own, well-conditioned candidate.
inline double segment_to_rectangle(const Vec3& p, const Vec3& d, double h, double hx, double hy,
                                   double best) {
  const double ex = h * std::abs(d.x()), ey = h * std::abs(d.y()), ez = h * std::abs(d.z());
  // On each axis, the gap between the segment's extent and K's: their squares' sum is at most F.
  const double gx = std::max(0.0, std::abs(p.x()) - ex - hx);
  const double gy = std::max(0.0, std::abs(p.y()) - ey - hy);
  const double gz = std::max(0.0, std::abs(p.z()) - ez);
  if (gx * gx + gy * gy + gz * gz >= best) return best;
  // The cells the segment reaches: on each axis a run of below, within, above. With a tolerance for the
  // extents' rounding, as a cell too many only adds a candidate, and one too few could lose the minimum.
  const double tolerance = 8 * kEps * (std::abs(p.x()) + std::abs(p.y()) + ex + ey + hx + hy);
  const int x_first = p.x() - ex < tolerance - hx ? -1 : std::abs(p.x()) - ex <= hx + tolerance ? 0 : 1;
  const int x_last = p.x() + ex > hx - tolerance ? 1 : std::abs(p.x()) - ex <= hx + tolerance ? 0 : -1;
  const int y_first = p.y() - ey < tolerance - hy ? -1 : std::abs(p.y()) - ey <= hy + tolerance ? 0 : 1;
  const int y_last = p.y() + ey > hy - tolerance ? 1 : std::abs(p.y()) - ey <= hy + tolerance ? 0 : -1;
  const auto at = [&](double r) {
    return outside_squared(p.x() + r * d.x(), hx) + outside_squared(p.y() + r * d.y(), hy) +
           square(p.z() + r * d.z());
  };
  for (int sx = x_first; sx <= x_last; ++sx) {
    // The cell's quadratic a r^2 + 2 b r + c: Z's term, and X's (Y's) where the cell lies beyond K's side.
    const double ax = sx != 0 ? d.x() * d.x() : 0.0, bx = sx != 0 ? (p.x() - sx * hx) * d.x() : 0.0;
    for (int sy = y_first; sy <= y_last; ++sy) {
      const double a = d.z() * d.z() + ax + (sy != 0 ? d.y() * d.y() : 0.0);
      const double b = p.z() * d.z() + bx + (sy != 0 ? (p.y() - sy * hy) * d.y() : 0.0);
      // a == 0: F is constant on the cell; if the minimum lies there, the segment either stays in the cell
      // (any point will do) or leaves it into a cell whose stationary point is the crossing.
      const double r = a > 0 ? std::min(h, std::max(-h, -b / a)) : 0.0;
      best = std::min(best, at(r));
    }
  }
  return best;
}

/// A lower bound on the squared distance from the rectangle c + [-1, 1] u + [-1, 1] v (u, v scaled by the
/// half-lengths) to K (as above): its bounding box's gaps to K's.
inline double box_gap_squared(const Vec3& c, const Vec3& u, const Vec3& v, double hx, double hy) {
  const Vec3 reach = u.cwiseAbs() + v.cwiseAbs();
  return square(std::max(0.0, std::abs(c.x()) - reach.x() - hx)) +
         square(std::max(0.0, std::abs(c.y()) - reach.y() - hy)) +
         square(std::max(0.0, std::abs(c.z()) - reach.z()));
}

/// The squared distance between A = [-ha0, ha0] x [-ha1, ha1] x {0} and B, centred at t with the first two
/// columns of m as axes (m: B's frame in A's, orthonormal) and half-lengths hb0, hb1, or `best` when it is
/// not smaller; stops as soon as the answer is at most `enough`. B's edges are measured against A in A's
/// frame, A's against B in B's frame.
inline double squared_distance(const Vec3& t, const Mat3& m, double ha0, double ha1, double hb0, double hb1,
                               double best, double enough) {
  // In B's frame A is centred at -m^T t, and its axes are the first two rows of m.
  const Vec3 t_in_b = -(m.transpose() * t);
  const Vec3 bu = hb0 * m.col(0), bv = hb1 * m.col(1);
  const Vec3 au = ha0 * m.row(0).transpose(), av = ha1 * m.row(1).transpose();
  // Each box's gaps bound the distance from below: most pairs a test rejects stop here.
  if (std::max(box_gap_squared(t, bu, bv, ha0, ha1), box_gap_squared(t_in_b, au, av, hb0, hb1)) >= best)
    return best;
  // The edges: B's (centre, unit direction, half-length) against A in A's frame, then A's against B in B's.
  struct Edge {
    Vec3 center, direction;
    double half;
  };
  const Vec3 ua = m.row(0).transpose(), va = m.row(1).transpose();
  const Edge edges[8] = {{t + bv, m.col(0), hb0}, {t - bv, m.col(0), hb0}, {t + bu, m.col(1), hb1},
                         {t - bu, m.col(1), hb1}, {t_in_b + av, ua, ha0},  {t_in_b - av, ua, ha0},
                         {t_in_b + au, va, ha1},  {t_in_b - au, va, ha1}};
  for (int i = 0; i < 8; ++i) {
    const Edge& e = edges[i];
    best = i < 4 ? segment_to_rectangle(e.center, e.direction, e.half, ha0, ha1, best)
                 : segment_to_rectangle(e.center, e.direction, e.half, hb0, hb1, best);
    if (best <= enough) return best;
  }
  return best;
}

/// B's axes in A's frame, a^T (rotation b), for the frames (columns) of two volumes and the rotation that
/// places B. Written out, column by column: Eigen evaluated the nested product through a call per
/// coefficient, a sixth of a distance test. (The OBB's tests inline Eigen's product; this form measured no
/// better there.)
[[gnu::always_inline]] inline Mat3 relative_axes(const Mat3& a, const Mat3& rotation, const Mat3& b) {
  Mat3 out;
  for (int j = 0; j < 3; ++j) {
    const Vec3 column = rotation.col(0) * b(0, j) + rotation.col(1) * b(1, j) + rotation.col(2) * b(2, j);
    for (int i = 0; i < 3; ++i) out(i, j) = a.col(i).dot(column);
  }
  return out;
}

/// A lower bound on the distance between A = [-ha0, ha0] x [-ha1, ha1] x {0} and B (placed as in
/// squared_distance): their gap along w = q - p, where p is the point of A nearest B's centre, q the point of
/// B nearest p, and p then moved to the point of A nearest q (one step of alternating projection). The gap
/// along any direction bounds the distance from below, and along a nearest pair's it is the distance; one
/// step comes close to that wherever the rectangles are apart by more than a fraction of their size (more
/// steps cost more than the tighter bounds spare, measured on the protocol). 0: no gap along w.
inline double separation(const Vec3& t, const Mat3& m, double ha0, double ha1, double hb0, double hb1) {
  const Vec3 b0 = m.col(0), b1 = m.col(1);
  const Vec3 from_t = Vec3(std::clamp(t.x(), -ha0, ha0), std::clamp(t.y(), -ha1, ha1), 0.0) - t;
  const Vec3 q = t + std::clamp(from_t.dot(b0), -hb0, hb0) * b0 + std::clamp(from_t.dot(b1), -hb1, hb1) * b1;
  const Vec3 w = q - Vec3(std::clamp(q.x(), -ha0, ha0), std::clamp(q.y(), -ha1, ha1), 0.0);
  // The least of w.y over B less the most of w.x over A.
  const double gap = w.dot(t) - std::abs(w.dot(b0)) * hb0 - std::abs(w.dot(b1)) * hb1 -
                     std::abs(w.x()) * ha0 - std::abs(w.y()) * ha1;
  return gap > 0 ? gap / w.norm() : 0.0;
}

/// B's centre t and axes m (columns) in the frame of A's rectangle, at A's centre.
inline void place_in_a(const Rectangle& a, const Rectangle& b, Vec3& t, Mat3& m) {
  Mat3 to_a;
  to_a.row(0) = a.axis0.transpose();
  to_a.row(1) = a.axis1.transpose();
  to_a.row(2) = a.axis0.cross(a.axis1).transpose();
  m.col(0) = to_a * b.axis0;
  m.col(1) = to_a * b.axis1;
  m.col(2) = m.col(0).cross(m.col(1));
  t = to_a * (b.center - a.center);
}

}  // namespace detail

/// The distance between two closed rectangles, 0 where they meet. Computed in a frame at a's centre, so pairs
/// far from the origin keep the digits of their offset. For tests and tools: Rss computes the same in place.
inline double rectangle_distance(const Rectangle& a, const Rectangle& b) {
  Vec3 t;
  Mat3 m;
  detail::place_in_a(a, b, t, m);
  return std::sqrt(detail::squared_distance(t, m, a.half0, a.half1, b.half0, b.half1, detail::kInfinity, 0));
}

/// The separation step's lower bound on that distance (detail::separation; 0 where it finds no gap), in the
/// same frame. For tests and tools: Rss computes the same in place.
inline double rectangle_separation(const Rectangle& a, const Rectangle& b) {
  Vec3 t;
  Mat3 m;
  detail::place_in_a(a, b, t, m);
  return detail::separation(t, m, a.half0, a.half1, b.half0, b.half1);
}

}  // namespace rss

struct Rss {
  std::array<float, 4> orientation{0, 0, 0, 1};  // quaternion (x, y, z, w), need not be unit
  Float3 center{0, 0, 0};
  std::array<float, 2> half{0, 0};  // the rectangle's half-lengths along the frame's first two axes
  float radius = -1;                // negative: empty

  struct PairContext {
    PlainMat3 rotation;  // B -> A
    Double3 translation;
    double translation_magnitude;  // max |t_i|
  };

  static constexpr std::string_view name() { return "rss"; }

  static Rss fit(std::span<const Vec3> points);

  static Rss merge(const Rss& a, const Rss& b);

  static PairContext make_context(const RigidTransform& pose) {
    return {PlainMat3::from(pose.rotation), to_double3(pose.translation),
            pose.translation.cwiseAbs().maxCoeff()};
  }

  /// The volume with its frame as a matrix (UnpackedVolume): trees keep it beside the stored one, since
  /// turning the two quaternions into frames is part of every test, as for the OBB.
  struct Unpacked {
    Mat3 axes;
    Vec3 center;
    double half0, half1, radius;  // radius < 0: empty
    double magnitude;
  };
  static Unpacked unpack(const Rss& v) {
    return {Obb::axes_of(v.orientation), to_vec(v.center), v.half[0], v.half[1], v.radius, v.magnitude()};
  }

  /// True when the rectangles are at most ra + rb (and the rounding slack) apart.
  [[gnu::flatten]] static bool overlap(const Rss& a, const Rss& b, const PairContext& c) {
    return overlap(unpack(a), unpack(b), c);
  }
  [[gnu::flatten]] static bool overlap(const Unpacked& a, const Unpacked& b, const PairContext& c) {
    if (a.radius < 0 || b.radius < 0) return false;
    return overlapping(a, b, place(a, b, c));
  }

  /// DistanceVolume: less both radii and overlap()'s slack, the separating gap where that exceeds them by a
  /// further slack, else the rectangles' distance; 0 exactly where overlap() is true. The further slack is
  /// what keeps the two consistent: the gap and the edges' distance each round by a few ulps of the
  /// coordinates in A's frame (about 40 eps of the magnitudes the slack is 128 eps of), so a gap past it
  /// proves the edges' distance past the radii too, and overlap() false. One pass over the edges answers
  /// the rest: it stops as soon as the distance is within the radii (overlap) and skips every edge whose
  /// gaps alone rule out a nearer point. With a `cutoff` (the distance the caller already has), a pair whose
  /// bound is at least that far is answered `cutoff` as soon as its gaps show it: the caller drops it.
  /// overlap() itself does not look for the gap: in a collision query most pairs tested overlap, and the
  /// step cost 10% more instructions there (callgrind, bunny and jeep1 at protocol distances 0.8 to 1.6).
  [[gnu::flatten]] static double distance_lower_bound(const Rss& a, const Rss& b, const PairContext& c) {
    return distance_lower_bound(unpack(a), unpack(b), c);
  }
  [[gnu::flatten]] static double distance_lower_bound(const Unpacked& a, const Unpacked& b,
                                                      const PairContext& c,
                                                      double cutoff = rss::detail::kInfinity) {
    if (a.radius < 0 || b.radius < 0) return 0;
    const Placement p = place(a, b, c);
    if (const double gap = separated(a, b, p); gap > p.reach + p.slack) return gap - p.reach;
    const double limit = p.reach * p.reach;
    // Past `far` the bound is at least the cutoff; never at or below `limit`, so a pair answered `far`
    // does not overlap.
    const double far = std::max(rss::detail::square(cutoff + p.reach), next_above(limit));
    const double squared = squared_gap(a, b, p, far, limit);
    if (squared <= limit) return 0;
    if (squared >= far) return cutoff;
    return std::max(0.0, std::sqrt(squared) - p.reach);
  }

  [[nodiscard]] bool empty() const { return radius < 0; }

  /// For loaders of raw node bytes: finite, non-negative half-lengths and radius, and a quaternion that is
  /// close to unit length (fit stores unit ones; axes_of divides by the squared norm).
  [[nodiscard]] bool valid() const;

  /// Steiner's formula for a flat convex set swept by a ball: 2 r area + (pi r^2 / 2) perimeter + 4/3 pi r^3.
  [[nodiscard]] Scalar volume() const {
    if (empty()) return 0;
    const double r = radius, a = half[0], b = half[1];
    return 8 * r * a * b + 2 * std::numbers::pi * r * r * (a + b) + 4.0 / 3.0 * std::numbers::pi * r * r * r;
  }

  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    const Mat3 axes = Obb::axes_of(orientation);
    const Vec3 reach = axes.col(0).cwiseAbs() * double(half[0]) + axes.col(1).cwiseAbs() * double(half[1]) +
                       Vec3::Constant(double(radius) + kFrameRounding * magnitude());
    return {to_vec(center) - reach, to_vec(center) + reach};
  }

  [[nodiscard]] bool contains(const Vec3& p) const;

  /// The rectangle (the frame's first two axes, centre, half-lengths): what the volume sweeps.
  [[nodiscard]] rss::Rectangle rectangle() const {
    const Mat3 axes = Obb::axes_of(orientation);
    return {to_vec(center), axes.col(0), axes.col(1), half[0], half[1]};
  }

 private:
  // Frame and centre rounding, as for the OBB (obb.hpp, box_in_frame): the stored frame is within angle
  // 2^-22 of the fitted one, so it moves a point of the rectangle by at most 2^-21 of the half-diagonal.
  static constexpr double kFrameRounding = 0x1p-21;
  static constexpr double kEps = std::numeric_limits<double>::epsilon();

  // B's rectangle in A's frame, and the sum of the radii and the rounding slack.
  struct Placement {
    Mat3 m;        // B's frame (columns) in A's
    Vec3 t;        // B's centre in A's frame
    double reach;  // ra + rb + slack
    double slack;
  };
  // The slack covers the rounding of the placement (absolute, so it grows with the centres' and the
  // translation's magnitudes, not only with the rectangles') and of the rectangle distance (a few ulps of the
  // coordinates in A's frame, which those magnitudes bound).
  [[gnu::always_inline]] static Placement place(const Unpacked& a, const Unpacked& b, const PairContext& c) {
    const Mat3 rotation = c.rotation.map();  // as in Obb::place: products with the row-major map are slower
    const Mat3 m = rss::detail::relative_axes(a.axes, rotation, b.axes);
    const Vec3 t = a.axes.transpose() * (rotation * b.center + to_vec(c.translation) - a.center);
    const double slack = 128 * kEps * (a.magnitude + b.magnitude + c.translation_magnitude);
    return {m, t, a.radius + b.radius + slack, slack};
  }
  // Whether the rectangles are at most `reach` apart. Starting just above the limit lets every edge whose
  // gaps exceed it be skipped.
  [[gnu::always_inline]] static bool overlapping(const Unpacked& a, const Unpacked& b, const Placement& p) {
    const double limit = p.reach * p.reach;
    return squared_gap(a, b, p, next_above(limit), limit) <= limit;
  }
  [[gnu::always_inline]] static double separated(const Unpacked& a, const Unpacked& b, const Placement& p) {
    return rss::detail::separation(p.t, p.m, a.half0, a.half1, b.half0, b.half1);
  }
  [[gnu::always_inline]] static double squared_gap(const Unpacked& a, const Unpacked& b, const Placement& p,
                                                   double best, double enough) {
    return rss::detail::squared_distance(p.t, p.m, a.half0, a.half1, b.half0, b.half1, best, enough);
  }

  // The next double above x (finite, >= 0): std::nextafter without the library call.
  static double next_above(double x) { return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) + 1); }

  [[nodiscard]] double magnitude() const {
    return to_vec(center).cwiseAbs().maxCoeff() + double(half[0]) + double(half[1]) + double(radius);
  }

  void write_corners(Vec3* out) const;
  // The radius a corner carries into a merge: the volume's own, widened by the float rounding of its frame
  // and centre (which the GCC 12 folding, see rounded(), may undo when the volume was just stored) and by the
  // corners' own rounding.
  [[nodiscard]] double corner_radius() const;

  // One expression for fit and contains, so a fitted point always tests as contained.
  static double distance_to_rectangle(const Mat3& axes, const Vec3& center, double h0, double h1,
                                      const Vec3& p);

  // The RSS holding every ball (points[i], radii[i]; no radii: points), in the better of two frames.
  static Rss fit_balls(std::span<const Vec3> points, std::span<const double> radii);

  // The RSS in the frame's axes (orthonormal columns), one of which becomes its normal. Coordinates are
  // taken relative to `origin` (the points' mean), which keeps the digits of a small set far from the origin.
  static Rss fit_in_frame(std::span<const Vec3> points, std::span<const double> radii, const Vec3& origin,
                          const Mat3& frame);

  // The stored volume for the exact one (frame `axes`, a rotation; every point within `reach` of the
  // rectangle). A point's nearest point on the rectangle, c + axes (x, y, 0), has its twin c' + axes' (x, y,
  // 0) on the stored rectangle (the half-lengths are rounded up), at most 2^-24 |c| + 2^-21 |(h0, h1)| away;
  // the radius grows by that and by a few ulps for contains()'s arithmetic. Bounding the rounding instead of
  // re-measuring against the stored floats also keeps this correct under GCC 12's -O2 SLP vectoriser, which
  // folds double(float(x)) back to x.
  static Rss rounded(const Mat3& axes, const Vec3& center, double h0, double h1, double reach);

  // Smaller volume wins; for (nearly) flat volumes, the smaller rectangle, then the smaller sizes.
  static bool smaller(const Rss& a, const Rss& b);
};

static_assert(BoundingVolume<Rss> && DistanceVolume<Rss> && UnpackedVolume<Rss>);

}  // namespace bvhlab
