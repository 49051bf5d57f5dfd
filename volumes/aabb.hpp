// Axis-aligned bounding box. Under a relative rotation B's box is re-boxed in A's frame
// (centre R c + t, half-extents |R| h): about 15 multiply-adds per test and no refit of the tree per
// query. Corners are stored as floats rounded outwards: 24 bytes a node, still conservative.
#pragma once

#include "concept.hpp"
#include "storage.hpp"

#include <algorithm>
#include <cmath>

namespace bvhlab {

struct Aabb {
  Float3 lo{1, 1, 1};  // lo > hi: empty
  Float3 hi{-1, -1, -1};

  struct PairContext {
    PlainMat3 rotation;      // B -> A
    PlainMat3 abs_rotation;  // |R|, widened by a few ulps so re-boxed extents stay conservative
    Double3 translation;
    double translation_magnitude;  // max |t_i|
  };

  static constexpr std::string_view name() { return "aabb"; }

  static Aabb from_box(const Box& box) {
    if (box.empty()) return {};
    return {float3_down(box.min), float3_up(box.max)};
  }
  static Aabb fit(std::span<const Vec3> points) {
    Box box;
    for (const auto& p : points) {
      if (!p.allFinite()) throw std::invalid_argument("aabb::fit: a point has a NaN or infinite coordinate");
      box.extend(p);
    }
    return from_box(box);
  }
  static Aabb merge(const Aabb& a, const Aabb& b) {
    Box box = a.bounding_box();
    box.extend(b.bounding_box());
    return from_box(box);
  }
  static PairContext make_context(const RigidTransform& pose) {
    const Mat3 abs_r = pose.rotation.cwiseAbs().array() + Scalar(4) * std::numeric_limits<Scalar>::epsilon();
    return {PlainMat3::from(pose.rotation), PlainMat3::from(abs_r), to_double3(pose.translation),
            pose.translation.cwiseAbs().maxCoeff()};
  }
  static bool overlap(const Aabb& a, const Aabb& b, const PairContext& c) {
    const Placed p = place(a, b, c);
    return p.gap.maxCoeff() <= p.slack;
  }

  /// DistanceVolume: the widest gap on the six unit axes of A and B, less a rounding slack at least
  /// overlap()'s. Projection onto a unit axis does not increase distances, so each gap (B re-boxed on A's
  /// axes, as overlap() computes it; A re-boxed on B's) is a lower bound on the distance. 0 where overlap()
  /// is true, even if B's axes would separate: the two tests agree.
  static double distance_lower_bound(const Aabb& a, const Aabb& b, const PairContext& c) {
    const Placed p = place(a, b, c);
    if (p.gap.maxCoeff() <= p.slack) return 0;
    // A's box in B's frame: centre R^T (c_a - t), half-extents |R|^T h_a.
    const Vec3 b_own_center = (to_vec(b.lo) + to_vec(b.hi)) * Scalar(0.5);
    const Vec3 b_own_half = (to_vec(b.hi) - to_vec(b.lo)) * Scalar(0.5);
    const Vec3 a_center_in_b = c.rotation.map().transpose() * (p.a_center - to_vec(c.translation));
    const Vec3 a_half_in_b = c.abs_rotation.map().transpose() * p.a_half;
    const Vec3 gap_on_b = (a_center_in_b - b_own_center).cwiseAbs() - b_own_half - a_half_in_b;
    // Overlap's slack covers A's axes; the terms in B's frame and the translation, which cancel in c_b's
    // image when B lies far from its own origin, have rounding errors of their own.
    const Scalar slack = p.slack + Scalar(16) * std::numeric_limits<Scalar>::epsilon() *
                                       (to_vec(c.translation).cwiseAbs().maxCoeff() +
                                        b_own_center.cwiseAbs().maxCoeff() + a_half_in_b.maxCoeff());
    // Per frame, the gaps along its three axes separate one box from the box around the other: their
    // Euclidean length bounds the distance, and closes in on it as the boxes shrink, where the largest gap
    // alone stays short by the cosine to the nearest axis at every depth.
    const double on_a = (p.gap.array() - slack).max(Scalar(0)).matrix().norm();
    const double on_b = (gap_on_b.array() - slack).max(Scalar(0)).matrix().norm();
    return std::max(on_a, on_b) * (1 - 4 * std::numeric_limits<double>::epsilon());
  }

  [[nodiscard]] bool empty() const { return lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2]; }

  /// For loaders of raw node bytes: a stored node is finite and not empty.
  [[nodiscard]] bool valid() const {
    for (int k = 0; k < 3; ++k)
      if (!(std::isfinite(lo[k]) && std::isfinite(hi[k]) && lo[k] <= hi[k])) return false;
    return true;
  }
  [[nodiscard]] Scalar volume() const { return empty() ? 0 : (to_vec(hi) - to_vec(lo)).prod(); }
  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    return {to_vec(lo), to_vec(hi)};
  }
  [[nodiscard]] bool contains(const Vec3& p) const { return !empty() && bounding_box().contains(p); }

 private:
  // B's box re-boxed in A's frame against A's: the signed gaps on A's axes and their rounding slack, as
  // overlap() compares them; distance_lower_bound() starts from the same numbers.
  struct Placed {
    Vec3 a_center, a_half, gap;
    Scalar slack;
  };
  [[gnu::always_inline]] static Placed place(const Aabb& a, const Aabb& b, const PairContext& c) {
    const Vec3 a_lo = to_vec(a.lo), a_hi = to_vec(a.hi), b_lo = to_vec(b.lo), b_hi = to_vec(b.hi);
    const Vec3 a_center = (a_lo + a_hi) * Scalar(0.5), a_half = (a_hi - a_lo) * Scalar(0.5);
    const Vec3 b_own_center = (b_lo + b_hi) * Scalar(0.5);
    const Vec3 b_center = c.rotation.map() * b_own_center + to_vec(c.translation);
    const Vec3 b_half = c.abs_rotation.map() * ((b_hi - b_lo) * Scalar(0.5));
    const Vec3 gap = (b_center - a_center).cwiseAbs() - a_half - b_half;
    // Slack for the rounding of these few operations, relative to the magnitudes involved: R c_b + t rounds
    // relative to |c_b| and |t|, not to its own size (B far from its origin, brought back by the pose).
    const Scalar slack = Scalar(16) * std::numeric_limits<Scalar>::epsilon() *
                         (2 * b_own_center.cwiseAbs().maxCoeff() + c.translation_magnitude +
                          a_center.cwiseAbs().maxCoeff() + a_half.maxCoeff() + b_half.maxCoeff());
    return {a_center, a_half, gap, slack};
  }
};

static_assert(BoundingVolume<Aabb> && DistanceVolume<Aabb>);

}  // namespace bvhlab
