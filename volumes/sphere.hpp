// Bounding sphere: centre and radius as floats (16 bytes); the overlap test is one distance comparison.
//
// Fit: the smallest of three cheap candidates, each a sphere around a centre with the largest distance to
// the points as radius: the bounding-box centre, the centroid, and Ritter's grown sphere (from an
// approximate diameter, enlarged for every point outside). Not the minimal sphere, typically within a few
// percent of it. The radius is widened by a bound on the centre's rounding to float and rounded up, so the
// stored sphere holds every point.
#pragma once

#include "concept.hpp"
#include "storage.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bvhlab {

struct Sphere {
  Float3 center{0, 0, 0};
  float radius = -1;  // negative: empty

  struct PairContext {
    PlainMat3 rotation;  // B -> A
    Double3 translation;
    double translation_magnitude;  // max |t_i|
  };

  static constexpr std::string_view name() { return "sphere"; }

  static Sphere fit(std::span<const Vec3> points);

  static Sphere merge(const Sphere& a, const Sphere& b);

  static PairContext make_context(const RigidTransform& pose) {
    return {PlainMat3::from(pose.rotation), to_double3(pose.translation),
            pose.translation.cwiseAbs().maxCoeff()};
  }

  static bool overlap(const Sphere& a, const Sphere& b, const PairContext& c) {
    const Placed p = place(a, b, c);
    return p.squared_distance <= p.reach * p.reach;
  }

  /// DistanceVolume. Every point of a is within r_a of c_a and every placed point of b within r_b of
  /// R c_b + t, so the triangle inequality bounds their distance below by |c_a - (R c_b + t)| - r_a - r_b;
  /// `reach` holds overlap()'s rounding slack too. 0 exactly where overlap() is true: sqrt is monotone and
  /// sqrt(reach * reach) rounds back to reach.
  static double distance_lower_bound(const Sphere& a, const Sphere& b, const PairContext& c) {
    const Placed p = place(a, b, c);
    return std::max(0.0, std::sqrt(p.squared_distance) - p.reach);
  }

  [[nodiscard]] bool empty() const { return radius < 0; }

  /// For loaders of raw node bytes: a finite centre and a finite, non-negative radius.
  [[nodiscard]] bool valid() const {
    return std::isfinite(center[0]) && std::isfinite(center[1]) && std::isfinite(center[2]) &&
           std::isfinite(radius) && radius >= 0;
  }
  [[nodiscard]] Scalar volume() const {
    return empty() ? 0 : 4.0 / 3.0 * std::numbers::pi * double(radius) * radius * radius;
  }
  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    const Vec3 c = to_vec(center);
    // c +- r in double is exact for all but extreme exponent gaps; the margin covers those.
    const Vec3 reach = Vec3::Constant(radius + 4 * std::numeric_limits<double>::epsilon() *
                                                   (c.cwiseAbs().maxCoeff() + radius));
    return {c - reach, c + reach};
  }
  [[nodiscard]] bool contains(const Vec3& p) const;

 private:
  // The centres' squared distance as the pair lies, and the radii plus the rounding slack: what overlap()
  // compares, computed once for it and distance_lower_bound.
  struct Placed {
    double squared_distance;
    double reach;
  };
  static Placed place(const Sphere& a, const Sphere& b, const PairContext& c) {
    const Vec3 ca = to_vec(a.center), cb = to_vec(b.center);
    const Vec3 offset = c.rotation.map() * cb + to_vec(c.translation) - ca;
    const double slack = 32 * std::numeric_limits<double>::epsilon() *
                         (ca.cwiseAbs().maxCoeff() + cb.cwiseAbs().maxCoeff() + c.translation_magnitude +
                          double(a.radius) + double(b.radius));
    return {offset.squaredNorm(), double(a.radius) + double(b.radius) + slack};
  }

  // One expression for fit and contains, so a fitted point always tests as contained.
  static double distance(const Vec3& c, const Vec3& p);

  static Sphere around(std::span<const Vec3> points, const Vec3& center, double margin);

  // The stored sphere for an exact one: the centre moves by at most one float rounding (half an ulp,
  // <= 2^-24 |c|), so the radius grows by that bound and a few ulps for the arithmetic. Bounding the move
  // instead of measuring it also keeps this correct under GCC 12's -O2 SLP vectoriser, which folds
  // double(float(x)) back to x.
  static Sphere rounded(const Vec3& center, double radius);

  static Vec3 ritter_center(std::span<const Vec3> points);
};

static_assert(BoundingVolume<Sphere> && DistanceVolume<Sphere>);

}  // namespace bvhlab
