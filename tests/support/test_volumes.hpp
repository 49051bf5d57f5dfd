// A bounding volume that exists only under tests/: a capsule (segment swept by a ball). It is curved, not a
// polytope, and its pair test is a segment distance, so it checks that nothing in bvh/ or traversal/ assumes
// boxes or DOPs. It must pass the same conformance suite as the library's volumes.
#pragma once

#include "volumes/concept.hpp"
#include "volumes/storage.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <numbers>

namespace bvhlab::testing {

/// Distance from p to the segment [a, b] (a point when a == b).
inline double point_segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double length2 = d.squaredNorm();
  const double s = length2 > 0 ? std::clamp((p - a).dot(d) / length2, 0.0, 1.0) : 0.0;
  return (p - (a + s * d)).norm();
}

/// A lower bound on the distance between segments [p0, p1] and [q0, q1], equal to it up to rounding except
/// for nearly parallel segments whose projections overlap (then at most their divergence along the overlap
/// below it). The minimum of the convex |P(s) - Q(t)| over [0, 1]^2 lies on an edge of the square (one of
/// four point-segment distances, all well conditioned) or at the lines' common perpendicular, which is
/// counted whenever it may fall inside: being the lines' distance, it never exceeds the segments' distance.
inline double segment_distance_lower_bound(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  double best = std::min({point_segment_distance(p0, q0, q1), point_segment_distance(p1, q0, q1),
                          point_segment_distance(q0, p0, p1), point_segment_distance(q1, p0, p1)});
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, w = q0 - p0;
  const double a = d1.squaredNorm(), c = d2.squaredNorm();
  if (a == 0 || c == 0) return best;  // a point: the edge cases are the whole answer
  const Vec3 n = d1.cross(d2);
  const double nn = n.squaredNorm();
  if (nn > 1e-4 * a * c) {
    // Well separated directions (sin > 0.01): the common perpendicular's feet are well conditioned.
    const double s = w.cross(d2).dot(n) / nn, t = w.cross(d1).dot(n) / nn;
    const double tol = 1e-6 * (1 + w.norm() / std::sqrt(std::min(a, c)));
    if (s >= -tol && s <= 1 + tol && t >= -tol && t <= 1 + tol)
      best = std::min(best, std::abs(w.dot(n)) / std::sqrt(nn));
  } else {
    // Nearly parallel: an interior minimum needs the projections on d1 to overlap; then the distance from
    // segment 2 to line 1 (a projection, so well conditioned) is a lower bound.
    const Vec3 u = d1 / std::sqrt(a);
    const double s0 = w.dot(u), s1 = (q1 - p0).dot(u), length = std::sqrt(a);
    const double tol = 1e-9 * (length + std::abs(s0) + std::abs(s1));
    if (std::max(s0, s1) >= -tol && std::min(s0, s1) <= length + tol) {
      const Vec3 r0 = w - s0 * u, r1 = (q1 - p0) - s1 * u;
      best = std::min(best, point_segment_distance(Vec3::Zero(), r0, r1));
    }
  }
  return best;
}

struct Capsule {
  Float3 a{0, 0, 0};
  Float3 b{0, 0, 0};
  float radius = -1;  // negative: empty

  struct PairContext {
    PlainMat3 rotation;
    Double3 translation;
    double translation_magnitude;
  };

  static constexpr std::string_view name() { return "capsule"; }

  static Capsule fit(std::span<const Vec3> points) {
    if (std::any_of(points.begin(), points.end(), [](const Vec3& p) { return !p.allFinite(); }))
      throw std::invalid_argument("capsule::fit: a point has a NaN or infinite coordinate");
    if (points.empty()) return {};
    Vec3 mean = Vec3::Zero();
    for (const Vec3& p : points) mean += p;
    mean /= double(points.size());
    Mat3 covariance = Mat3::Zero();
    for (const Vec3& p : points) covariance += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3> solver(covariance);
    const Vec3 axis = solver.info() == Eigen::Success ? Vec3(solver.eigenvectors().col(2)) : Vec3::UnitX();
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, spread = 0;
    for (const Vec3& p : points) {
      const double s = (p - mean).dot(axis);
      lo = std::min(lo, s);
      hi = std::max(hi, s);
      spread = std::max(spread, ((p - mean) - s * axis).norm());
    }
    // Full-length axis, or shortened by the radius so the caps do the work; keep the smaller.
    const Capsule full = around(points, mean + lo * axis, mean + hi * axis, 0);
    const double inset = std::min(spread, (hi - lo) / 2);
    const Capsule shortened = around(points, mean + (lo + inset) * axis, mean + (hi - inset) * axis, 0);
    return shortened.volume() < full.volume() ? shortened : full;
  }

  static Capsule merge(const Capsule& x, const Capsule& y) {
    if (x.empty()) return y;
    if (y.empty()) return x;
    const std::array<Vec3, 4> ends = {to_vec(x.a), to_vec(x.b), to_vec(y.a), to_vec(y.b)};
    Capsule out = fit(ends);
    // A capsule is its segment plus a ball; distance to a segment is convex, so its maximum over the old
    // segment is at an end.
    double r = 0;
    for (int k = 0; k < 4; ++k)
      r = std::max(
          r, point_segment_distance(ends[k], to_vec(out.a), to_vec(out.b)) + (k < 2 ? x.radius : y.radius));
    out.radius = float_up(r * (1 + 1e-12) + 0x1p-22 * (x.magnitude() + y.magnitude()));
    return out;
  }

  static PairContext make_context(const RigidTransform& pose) {
    return {PlainMat3::from(pose.rotation), to_double3(pose.translation),
            pose.translation.cwiseAbs().maxCoeff()};
  }

  static bool overlap(const Capsule& x, const Capsule& y, const PairContext& c) {
    const auto rotation = c.rotation.map();
    const Vec3 t = to_vec(c.translation);
    const Vec3 ya = rotation * to_vec(y.a) + t, yb = rotation * to_vec(y.b) + t;
    const double distance = segment_distance_lower_bound(to_vec(x.a), to_vec(x.b), ya, yb);
    const double slack = 1e-10 * (x.magnitude() + y.magnitude() + c.translation_magnitude);
    return distance <= double(x.radius) + double(y.radius) + slack;
  }

  [[nodiscard]] bool empty() const { return radius < 0; }
  [[nodiscard]] Scalar volume() const {
    if (empty()) return 0;
    const double r = radius, length = (to_vec(b) - to_vec(a)).norm();
    return std::numbers::pi * r * r * (length + 4.0 / 3.0 * r);
  }
  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    const Vec3 reach = Vec3::Constant(radius * (1 + 1e-12) + 0x1p-22 * magnitude());
    return {to_vec(a).cwiseMin(to_vec(b)) - reach, to_vec(a).cwiseMax(to_vec(b)) + reach};
  }
  [[nodiscard]] bool contains(const Vec3& p) const {
    return !empty() && point_segment_distance(p, to_vec(a), to_vec(b)) <= radius;
  }

 private:
  [[nodiscard]] double magnitude() const {
    return to_vec(a).cwiseAbs().maxCoeff() + to_vec(b).cwiseAbs().maxCoeff() + std::abs(radius);
  }
  // Radius measured against the exact segment, widened by a bound on the endpoints' rounding to float (the
  // segment moves by at most the larger endpoint move), so nothing relies on reading the floats back.
  static Capsule around(std::span<const Vec3> points, const Vec3& from, const Vec3& to, double margin) {
    Capsule out;
    out.a = {float(from.x()), float(from.y()), float(from.z())};
    out.b = {float(to.x()), float(to.y()), float(to.z())};
    double r = 0;
    for (const Vec3& p : points) r = std::max(r, point_segment_distance(p, from, to));
    const double moved = 0x1p-24 * std::max(from.norm(), to.norm()) + 1e-44;
    out.radius = float_up((r + moved + margin) * (1 + 1e-12));
    return out;
  }
};

static_assert(BoundingVolume<Capsule>);

}  // namespace bvhlab::testing
