// Zachmann's restricted boxtree: a child's box is its parent's box with the two faces of one axis moved
// inwards, stored as that axis and the two new offsets (12 bytes a node against the AABB's 24).
//
// The overlap test is incremental, as in the paper: each side carries its box's centre and half-extents
// in the test frame (A's), and descending to a child changes them along one of the node's own axes only:
// centre += R e_k dc, half += |R| e_k dh. That is 6 multiply-adds per descent instead of re-boxing (15),
// and the test itself is 6 comparisons. Rounding errors of the incremental updates accumulate with depth,
// so the comparison allows a slack of a few ulps of the magnitudes per level (see `overlap`).
#pragma once

#include "aabb.hpp"
#include "concept.hpp"
#include "storage.hpp"

#include <cstdint>

namespace bvhlab {

struct RestrictedBox {
  float lo = 0;  ///< the child's interval on `axis`
  float hi = 0;
  std::uint32_t axis = 0;  ///< 0, 1 or 2

  using Decoded = Aabb;

  struct Frame {
    PlainMat3 rotation;      ///< this side's frame into the test frame
    PlainMat3 abs_rotation;  ///< |R|, widened by a few ulps as in Aabb
    Double3 translation;
  };

  /// Traversal state of one node: its own-frame box (to decode children) and its re-boxed image in the
  /// test frame, updated incrementally.
  struct Working {
    Aabb own;
    Double3 center;  ///< in the test frame
    Double3 half;    ///< in the test frame
    std::uint32_t depth = 0;
    /// What the root's image R c + t rounds relative to: |c| and |t|, large when the tree lies far from its
    /// own origin and the pose brings it back. Kept in what was padding.
    float image_magnitude = 0;
  };

  static constexpr std::string_view name() { return "rbox"; }

  /// For loaders of raw node bytes: a stored node must name an axis and a finite, ordered interval.
  [[nodiscard]] bool valid() const { return axis < 3 && std::isfinite(lo) && std::isfinite(hi) && lo <= hi; }

  static RestrictedBox encode(const Aabb& parent, const Aabb& child) {
    // Keep the axis whose restriction removes the most volume, i.e. the smallest extent ratio.
    RestrictedBox best;
    double best_ratio = std::numeric_limits<double>::infinity();
    for (std::uint32_t k = 0; k < 3; ++k) {
      const float lo = std::max(child.lo[k], parent.lo[k]), hi = std::min(child.hi[k], parent.hi[k]);
      const double parent_extent = double(parent.hi[k]) - double(parent.lo[k]);
      const double ratio = parent_extent > 0 ? (double(hi) - double(lo)) / parent_extent : 1.0;
      if (ratio < best_ratio) best_ratio = ratio, best = {lo, hi, k};
    }
    // Child boxes are fitted to a subset of the parent's points, so they lie inside it; an empty child
    // (never produced by the builder) keeps the parent's box.
    if (child.empty()) best = {parent.lo[0], parent.hi[0], 0};
    return best;
  }
  static Aabb decode(const Aabb& parent, const RestrictedBox& node) {
    Aabb out = parent;
    out.lo[node.axis] = node.lo;
    out.hi[node.axis] = node.hi;
    return out;
  }

  static Frame make_frame(const RigidTransform& pose) {
    const Mat3 abs_r = pose.rotation.cwiseAbs().array() + Scalar(4) * std::numeric_limits<Scalar>::epsilon();
    return {PlainMat3::from(pose.rotation), PlainMat3::from(abs_r), to_double3(pose.translation)};
  }
  static Working start(const Aabb& root, const Frame& frame) {
    const Vec3 lo = to_vec(root.lo), hi = to_vec(root.hi);
    const Vec3 center = frame.rotation.map() * ((lo + hi) * 0.5) + to_vec(frame.translation);
    const Vec3 half = frame.abs_rotation.map() * ((hi - lo) * 0.5);
    const double image_magnitude =
        2 * ((lo + hi) * 0.5).cwiseAbs().maxCoeff() + to_vec(frame.translation).cwiseAbs().maxCoeff();
    return {root, to_double3(center), to_double3(half), 0, float_up(image_magnitude)};
  }
  static Working descend(const Working& parent, const RestrictedBox& node, const Frame& frame) {
    Working out;
    out.own = decode(parent.own, node);
    out.depth = parent.depth + 1;
    out.image_magnitude = parent.image_magnitude;
    const std::uint32_t k = node.axis;
    const double dc =
        0.5 * ((double(node.lo) + double(node.hi)) - (double(parent.own.lo[k]) + double(parent.own.hi[k])));
    const double dh =
        0.5 * ((double(node.hi) - double(node.lo)) - (double(parent.own.hi[k]) - double(parent.own.lo[k])));
    const auto r = frame.rotation.map();
    const auto abs_r = frame.abs_rotation.map();
    for (int i = 0; i < 3; ++i) {
      out.center[i] = parent.center[i] + r(i, k) * dc;
      out.half[i] = parent.half[i] + abs_r(i, k) * dh;
    }
    return out;
  }
  static Aabb decoded(const Working& w) { return w.own; }

  static bool overlap(const Working& a, const Working& b) {
    const Vec3 ca = to_vec(a.center), ha = to_vec(a.half), cb = to_vec(b.center), hb = to_vec(b.half);
    const Vec3 gap = (cb - ca).cwiseAbs() - ha - hb;
    // Each incremental level adds at most a few ulps of these magnitudes; allow 8 per level and side.
    const double magnitude = ca.cwiseAbs().maxCoeff() + cb.cwiseAbs().maxCoeff() + ha.maxCoeff() +
                             hb.maxCoeff() + double(a.image_magnitude) + double(b.image_magnitude);
    const double slack =
        8.0 * double(a.depth + b.depth + 2) * std::numeric_limits<double>::epsilon() * magnitude;
    return gap.maxCoeff() <= slack;
  }
};

static_assert(HierarchicalVolume<RestrictedBox>);
static_assert(sizeof(RestrictedBox) == 12);
static_assert(sizeof(RestrictedBox::Working) == 80, "the traversal state fills its padding, no more");

}  // namespace bvhlab
