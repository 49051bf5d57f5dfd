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
#pragma once

#include "volumes/geometry.hpp"

#include <concepts>
#include <span>
#include <string_view>
#include <type_traits>

namespace bvhlab {

template <class BV>
concept BoundingVolume =
    std::is_trivially_copyable_v<BV> && std::is_standard_layout_v<BV> &&
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

namespace detail {
inline const Vec3 kAxisDirections[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
}

/// The builder's split directions for BV: its own hint if it has one, else the coordinate axes.
template <class BV>
std::span<const Vec3> split_directions_of() {
  if constexpr (requires { { BV::split_directions() } -> std::convertible_to<std::span<const Vec3>>; })
    return BV::split_directions();
  else
    return std::span<const Vec3>(detail::kAxisDirections);
}

}  // namespace bvhlab
