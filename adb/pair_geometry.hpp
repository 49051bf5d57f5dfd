// What the ADB estimate reads of a node pair besides the counts: each node's box (extents only) and an upper
// bound of the volume of their overlap (adb/README.md, section 2). Two geometries, chosen by the density:
//   * the nodes' axis-aligned bounding boxes in their trees' frames (every BV; "adb_paper" on every BV);
//   * the nodes' own frames, for a volume that is a box in a frame of its own (FramedVolume: the OBB) and a
//     density that counts its cells there (D::cells_in_node_frames, "adb"). A slanted triangle's OBB is a
//     thin slab; its axis-aligned box is as deep as it is wide, so a small node that the OBB test found
//     inside the slab looked, in the axis-aligned box, like a random sub-box that rarely meets the surface.
// Both bound the overlap the same way: each box re-boxed in the other's frame, the smaller intersection.
// Both thicken flat boxes (kMinRelativeThickness), and the annotation flattens the same boxes (annotate.cpp).
#pragma once

#include "../volumes/concept.hpp"
#include "../volumes/geometry.hpp"

#include <algorithm>

namespace bvhlab {

/// Thinnest side of a box the estimate sees, relative to its longest side. A node of polygons in one plane
/// has a box of thickness 0 (or, in an OBB's frame, of rounding noise): volume 0, overlap 0 with anything.
inline constexpr double kMinRelativeThickness = 1e-3;

/// `box`, each side at least kMinRelativeThickness times its longest one (same centre).
[[gnu::always_inline]] inline Box with_min_thickness(const Box& box) {
  if (box.empty()) return box;
  const Vec3 extent = box.extent();
  const Vec3 grow = (Vec3::Constant(kMinRelativeThickness * extent.maxCoeff()) - extent).cwiseMax(0.0) * 0.5;
  return {box.min - grow, box.max + grow};
}

/// The annotation's side of the same rule, for a node's grid box in its own frame: every axis of `box`
/// thinner than kMinRelativeThickness of its longest becomes the plane 0, and so does that coordinate of each
/// point `for_each_point(set)` hands to `set(Vec3&)`, so a flat node's polygons count in every layer along
/// it.
template <class ForEachPoint>
void flatten_thin_axes(Box& box, ForEachPoint&& for_each_point) {
  const Vec3 extent = box.extent();
  for (int axis = 0; axis < 3; ++axis) {
    if (!(extent[axis] < kMinRelativeThickness * extent.maxCoeff())) continue;
    box.min[axis] = box.max[axis] = 0;
    for_each_point([axis](Vec3& v) { v[axis] = 0; });
  }
}

/// Volume of `box` ∩ (`other` re-boxed through rotation/translation): an upper bound of the overlap; 0 when
/// they are apart. Boxes that touch meet in a face, an edge or a corner, of volume 0, although polygons in
/// them may touch there (a resting contact): each side of the intersection counts as at least
/// kMinRelativeThickness of the smaller box's longest side, as flat boxes are thickened.
inline double reboxed_overlap(const Box& box, const Box& other, const Mat3& rotation,
                              const Mat3& abs_rotation, const Vec3& translation) {
  const Vec3 center = rotation * other.center() + translation;
  const Vec3 half = abs_rotation * (other.extent() * 0.5);
  const Vec3 lo = box.min.cwiseMax(center - half), hi = box.max.cwiseMin(center + half);
  if (!(hi.array() >= lo.array()).all()) return 0;
  const double thinnest = kMinRelativeThickness * std::min(box.extent().maxCoeff(), 2 * half.maxCoeff());
  return (hi - lo).cwiseMax(thinnest).prod();
}

/// A pose as re-boxing reads it in both directions: B into A's frame (R, |R|, t) and A into B's (R^T, |R|^T,
/// -R^T t). A traversal makes it once per pose: the inverse is the same for every node pair. It refers to
/// the pose (R and t are not copied): the pose must outlive it.
struct ReboxPose {
  /// Out of line (pair_geometry.cpp): it is made at most once a query, and inlined at each place an ADB loop
  /// estimates, it made the engine's density query files compile 5% to 7% more (bench/RESULTS.md).
  explicit ReboxPose(const RigidTransform& b_to_a);

  const Mat3& rotation;
  const Vec3& translation;
  Mat3 abs_rotation;
  Mat3 inverse_rotation, inverse_abs_rotation;
  Vec3 inverse_translation;
};

/// An upper bound of Vol(A ∩ B): re-boxing either box in the other's frame bounds the overlap from above,
/// so the smaller bound is used. B re-boxed in A's frame by (rotation, abs_rotation, translation) first;
/// `a_in_b()`, A re-boxed in B's frame, only where that is positive.
template <class AInB>
[[gnu::always_inline]] inline double smaller_reboxed_overlap(const Box& a, const Box& b, const Mat3& rotation,
                                                             const Mat3& abs_rotation,
                                                             const Vec3& translation, AInB&& a_in_b) {
  if (a.empty() || b.empty()) return 0;
  const double in_a = reboxed_overlap(a, b, rotation, abs_rotation, translation);
  if (!(in_a > 0)) return 0;
  return std::min(in_a, a_in_b());
}

/// The bound for boxes a and b whose frames `pose` relates, the inverse made beforehand.
inline double overlap_volume(const Box& a, const Box& b, const ReboxPose& pose) {
  return smaller_reboxed_overlap(a, b, pose.rotation, pose.abs_rotation, pose.translation, [&] {
    return reboxed_overlap(b, a, pose.inverse_rotation, pose.inverse_abs_rotation, pose.inverse_translation);
  });
}
/// The same for one pair (abs_rotation = |R|): the inverse made only where it is needed.
inline double overlap_volume(const Box& a, const Box& b, const RigidTransform& b_to_a,
                             const Mat3& abs_rotation) {
  return smaller_reboxed_overlap(a, b, b_to_a.rotation, abs_rotation, b_to_a.translation, [&] {
    const Mat3 r_t = b_to_a.rotation.transpose();
    return reboxed_overlap(b, a, r_t, abs_rotation.transpose(), -(r_t * b_to_a.translation));
  });
}

/// The estimate's inputs for one node pair.
struct PairGeometry {
  Box a;           ///< A's box, thickened; only its extents are read
  Box b;           ///< B's box, thickened
  double overlap;  ///< upper bound of Vol(a ∩ b), the boxes placed as the pair lies
};

/// The inputs from axis-aligned boxes in the trees' frames (b_to_a maps B's tree frame into A's).
[[gnu::always_inline]] inline PairGeometry tree_frame_geometry(const Box& a, const Box& b,
                                                               const ReboxPose& pose) {
  PairGeometry g{with_min_thickness(a), with_min_thickness(b), 0};
  g.overlap = overlap_volume(g.a, g.b, pose);
  return g;
}

/// The inputs from boxes in their own frames, placed as the pair lies: each box is [-half, half] there.
[[gnu::always_inline]] inline PairGeometry node_frame_geometry(const PlacedBoxes& placed) {
  if (placed.empty()) return {{}, {}, 0};
  PairGeometry g{with_min_thickness({-placed.half_a, placed.half_a}),
                 with_min_thickness({-placed.half_b, placed.half_b}), 0};
  g.overlap = overlap_volume(g.a, g.b, placed.b_in_a, placed.b_in_a.rotation.cwiseAbs());
  return g;
}

/// The same from the two boxes and the pose: B's frame is related to A's through both frames and the pose.
[[gnu::always_inline]] inline PairGeometry node_frame_geometry(const OrientedBox& a, const OrientedBox& b,
                                                               const RigidTransform& b_to_a) {
  if (a.empty() || b.empty()) return {{}, {}, 0};
  const Mat3 to_a = a.axes.transpose();
  PlacedBoxes placed{a.half, b.half, {}};
  placed.b_in_a.rotation = to_a * (b_to_a.rotation * b.axes);
  placed.b_in_a.translation = to_a * (b_to_a.apply(b.center) - a.center);
  return node_frame_geometry(placed);
}

/// Density D counts its cells in the nodes' own frames on trees of BV: D says so
/// (`static constexpr bool cells_in_node_frames`) and BV is a box in a frame of its own, stored whole.
template <class D, class BV>
inline constexpr bool estimates_in_node_frames = [] {
  if constexpr (requires { D::cells_in_node_frames; })
    return D::cells_in_node_frames && FramedVolume<BV> && !HierarchicalVolume<BV>;
  else
    return false;
}();

}  // namespace bvhlab
