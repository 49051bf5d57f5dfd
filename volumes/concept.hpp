// The BoundingVolume concept: what a bounding-volume policy must provide to plug into bvh/ and traversal/.
//
// Concept `BoundingVolume<BV>` (in the manner of a CGAL concept page)
// ---------------------------------------------------------------------
// A model is a plain-data type (trivially copyable, standard layout), so a tree can be saved and loaded
// as raw node arrays without polygons. Every volume lives in the local frame of its own object.
//
// Types
//   BV::PairContext   Per-query data derived once from the relative pose of the two objects
//                     (e.g. |R| for boxes, the re-alignment tables of a DOP). Cheap to copy, immutable.
//
// Operations (a, b: BV; pts: std::span<const Vec3>; pose: RigidTransform mapping B's frame into A's)
//   BV::name()                  Short stable identifier ("aabb", "dop24", ...), used in reports and files.
//   BV::fit(pts)                A volume containing every point (triangles are convex hulls of their
//                               vertices, so containing the vertices contains the triangles). O(|pts|).
//   BV::merge(a, b)             A volume containing a and b. O(1).
//   BV::make_context(pose)      Precomputes the PairContext. Called once per query, never per node pair.
//   BV::overlap(a, b, ctx)      a in A's frame, b in B's frame. Must be *conservative*: it may answer true
//                               for volumes that are apart, but never false when the point sets they
//                               contain (after applying pose to b's) share a point. O(1); the hot path.
//   a.volume()                  Lebesgue measure of the volume (tightness reports, descent order).
//   a.bounding_box()            An axis-aligned box in the volume's own frame containing it
//                               (the ADB grid is laid on it).
//   a.contains(p)               Whether point p (own frame) lies in the closed volume; for tests.
//
// Optional
//   BV::split_directions()      std::span<const Vec3>: directions the builder may split along
//                               (defaults to x, y, z); the DOP-tree uses its own orientations.
//   a.oriented_box()            OrientedBox (geometry.hpp): the volume as a box in a frame of its own (an
//                               OBB's axes, centre and half-extents). A volume that has one is a
//                               `FramedVolume`; the default ADB density lays its grid there instead of on
//                               bounding_box() (adb/README.md, section 1).
//   BV::overlap(a, b, ctx, pl)  With oriented_box(): overlap(a, b, ctx) that also writes to `pl`
//                               (PlacedBoxes&, geometry.hpp) the two boxes as the pair lies, which the test
//                               computes anyway. A volume that has it is a `FramePlacingVolume`: the ADB
//                               estimate in the nodes' frames reads that placement instead of its own.
//   BV::distance_lower_bound(a, b, ctx)
//                               double: a lower bound, >= 0, on the distance between any point contained in
//                               a and any point contained in b after applying the pose (a in A's frame, b in
//                               B's, ctx from make_context(pose) as for overlap). Conservative like
//                               overlap(), rounding included: never larger than the true distance (each
//                               model subtracts at least the slack its overlap() allows). 0 is always a
//                               valid answer, and it is the answer wherever overlap(a, b, ctx) is true; a
//                               positive bound proves separation, so overlap(a, b, ctx) is then false. It is
//                               meant to be useful, not only valid: the separation the overlap test measures
//                               (the widest gap on its separating axes, normalised to unit axes), at the
//                               same order of cost. For an empty volume any value >= 0 is allowed (the
//                               distance to an empty set is infinite). Assumes, as overlap() does, that the
//                               pose's rotation is orthonormal to rounding. A volume that has it is a
//                               `DistanceVolume` (proximity queries, issue #38). Hierarchical volumes
//                               (below) have none.
//   BV::distance_lower_bound(a, b, ctx, cutoff)
//                               Optional for a DistanceVolume: the same bound where it is below `cutoff`,
//                               else any valid bound of at least `cutoff`, so that a pair the caller will
//                               drop costs less. The traversals call it through distance_lower_bound_below
//                               (below), which falls back to the three-argument form.
//   BV::Unpacked, BV::unpack(a) A form of the volume that is faster to test and larger to keep (an OBB's
//                               axes as a matrix, not a quaternion). A volume that has it is an
//                               `UnpackedVolume`: a tree keeps each node's unpacked form beside the stored
//                               one (Bvh::tested_volume; in memory only, saved trees hold the stored form),
//                               and the traversals call BV::overlap on the unpacked forms (also the
//                               4-argument one of a FramePlacingVolume, and a DistanceVolume's
//                               distance_lower_bound), which must answer exactly as on the stored.
#pragma once

#include "geometry.hpp"

#include <concepts>
#include <span>
#include <string_view>
#include <type_traits>

namespace bvhlab {

template <class BV>
concept BoundingVolume = std::is_trivially_copyable_v<BV> && std::is_standard_layout_v<BV> &&
    std::is_trivially_copyable_v<typename BV::PairContext> &&
    requires(const BV& a, const BV& b, std::span<const Vec3> points, const RigidTransform& pose,
             const typename BV::PairContext& context, const Vec3& p) {
  { BV::name() } -> std::convertible_to<std::string_view>;
  { BV::fit(points) } -> std::same_as<BV>;
  { BV::merge(a, b) } -> std::same_as<BV>;
  { BV::make_context(pose) } -> std::same_as<typename BV::PairContext>;
  { BV::overlap(a, b, context) } -> std::same_as<bool>;
  { a.volume() } -> std::convertible_to<Scalar>;
  { a.bounding_box() } -> std::same_as<Box>;
  { a.contains(p) } -> std::same_as<bool>;
};

/// A volume that is a box in a frame of its own (the optional `oriented_box()` above).
template <class BV>
concept FramedVolume = BoundingVolume<BV> && requires(const BV& a) {
  { a.oriented_box() } -> std::same_as<OrientedBox>;
};

/// A volume with a form that is faster to test (the optional `Unpacked` above).
template <class BV>
concept UnpackedVolume = BoundingVolume<BV> &&
    requires(const BV& a, const typename BV::Unpacked& u, const typename BV::PairContext& context) {
  { BV::unpack(a) } -> std::same_as<typename BV::Unpacked>;
  { BV::overlap(u, u, context) } -> std::same_as<bool>;
};

/// A framed volume whose overlap test hands on the boxes' placement (the optional 4-argument overlap above).
template <class BV>
concept FramePlacingVolume = FramedVolume<BV> &&
    requires(const BV& a, const BV& b, const typename BV::PairContext& context, PlacedBoxes& placed) {
  { BV::overlap(a, b, context, placed) } -> std::same_as<bool>;
};

/// A volume with a conservative distance bound between two placed volumes (the optional
/// `distance_lower_bound` above).
template <class BV>
concept DistanceVolume = BoundingVolume<BV> &&
    requires(const BV& a, const BV& b, const typename BV::PairContext& context) {
  { BV::distance_lower_bound(a, b, context) } -> std::same_as<double>;
};

/// A DistanceVolume's bound for a caller that drops every pair at least `cutoff` apart: a volume may take the
/// cutoff as a fourth argument and stop refining there (BV::distance_lower_bound(a, b, ctx, cutoff): the
/// same bound where it is below the cutoff, else a valid bound of at least the cutoff). `V` is the volume's
/// stored or unpacked form.
template <DistanceVolume BV, class V>
[[gnu::always_inline]] inline double distance_lower_bound_below(const V& a, const V& b,
                                                                const typename BV::PairContext& context,
                                                                double cutoff) {
  if constexpr (requires { BV::distance_lower_bound(a, b, context, cutoff); })
    return BV::distance_lower_bound(a, b, context, cutoff);
  else
    return BV::distance_lower_bound(a, b, context);
}

/// Concept `HierarchicalVolume<HV>`: a node volume stored relative to its parent's, as in Zachmann's
/// restricted boxtree. Only the root is stored whole (as an `HV::Decoded`, itself a BoundingVolume).
/// The traversal walks the tree top-down carrying an `HV::Working` state per side, so a node's volume is
/// never re-derived from the root.
///
/// Types
///   HV::Decoded      The full volume of a node, in its own frame (fitting, ADB grid, tightness).
///   HV::Frame        How one side's volumes map into the frame where overlaps are tested: built from a
///                    RigidTransform (B's side) or the identity (A's side). Trivially copyable.
///   HV::Working      Traversal state of one node on one side. Trivially copyable.
/// Operations (p: Decoded parent; c: Decoded child inside p; s: HV; w: Working; f: Frame)
///   HV::encode(p, c)        A stored node whose decode contains c. Conservative: decode(p, encode(p, c)) ⊇
///   c. HV::decode(p, s)        The full volume s stands for, given its parent's. HV::make_frame(pose) Frame
///   for a side whose volumes the pose maps into the test frame. HV::start(root, f)      Working state of the
///   root. HV::descend(w, s, f)    Working state of a child from its parent's: the cheap, incremental step.
///   HV::decoded(w)          The node's Decoded volume (own frame).
///   HV::overlap(wa, wb)     Conservative overlap of two working states (both already in the test frame).
template <class HV>
concept HierarchicalVolume = std::is_trivially_copyable_v<HV> && BoundingVolume<typename HV::Decoded> &&
    std::is_trivially_copyable_v<typename HV::Working> && std::is_trivially_copyable_v<typename HV::Frame> &&
    requires(const HV& stored, const typename HV::Decoded& decoded, const typename HV::Working& w,
             const typename HV::Frame& frame, const RigidTransform& pose) {
  { HV::name() } -> std::convertible_to<std::string_view>;
  { HV::encode(decoded, decoded) } -> std::same_as<HV>;
  { HV::decode(decoded, stored) } -> std::same_as<typename HV::Decoded>;
  { HV::make_frame(pose) } -> std::same_as<typename HV::Frame>;
  { HV::start(decoded, frame) } -> std::same_as<typename HV::Working>;
  { HV::descend(w, stored, frame) } -> std::same_as<typename HV::Working>;
  { HV::decoded(w) } -> std::same_as<typename HV::Decoded>;
  { HV::overlap(w, w) } -> std::same_as<bool>;
};

/// What a Bvh can hold: a self-contained volume, or one stored relative to its parent.
template <class V>
concept TreeVolume = BoundingVolume<V> || HierarchicalVolume<V>;

/// The volume type fitted to a node's triangles: the model itself, or its Decoded form.
template <class V>
struct fitted_volume {
  using type = V;
};
template <HierarchicalVolume V>
struct fitted_volume<V> {
  using type = typename V::Decoded;
};
template <class V>
using fitted_volume_t = typename fitted_volume<V>::type;

/// What a tree keeps beside each stored volume: its Unpacked form, or nothing.
struct NothingUnpacked {};
template <class V>
struct unpacked_volume {
  using type = NothingUnpacked;
};
template <UnpackedVolume V>
struct unpacked_volume<V> {
  using type = typename V::Unpacked;
};
template <class V>
using unpacked_volume_t = typename unpacked_volume<V>::type;

namespace detail {
inline const Vec3 kAxisDirections[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
}

/// The builder's split directions for BV: its own hint if it has one, else the coordinate axes.
template <class BV>
std::span<const Vec3> split_directions_of() {
  if constexpr (requires {
                  { BV::split_directions() } -> std::convertible_to<std::span<const Vec3>>;
                })
    return BV::split_directions();
  else
    return std::span<const Vec3>(detail::kAxisDirections);
}

}  // namespace bvhlab
