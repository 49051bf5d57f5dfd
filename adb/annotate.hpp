// ADB cell counting (adb/README.md, section 1), the work behind AdbDensity (adb/adb_density.hpp): for every
// node V, the number pc(V) of "possible collision cells" among the g x g x g cells laid on V's bounding box.
//
// Definitions (the open points of the method, decided here)
// - Grid: V's bounding box (BV::bounding_box(), so a non-box BV uses its bounding box), cut into g cells per
//   axis; or, for the default density on a volume with a frame of its own (an OBB), V's box in that frame
//   (annotate_counts_in_frames). Cell boundaries are the doubles lo + (hi - lo) * i / g (clamped to hi; the
//   last one is hi itself).
// - Cells are CLOSED boxes. A polygon lying exactly in a face shared by two cells counts in full for both,
//   one along an edge shared by four cells counts for all four: both neighbours' closures contain it, and an
//   object touching it from either side collides with it, so counting it twice errs on the safe side
//   (more possible collision cells, a higher estimate, fewer false negatives). Consequence: the cell areas of
//   a triangle add up to its area unless the triangle lies in a cell plane. A node box that is flat in one
//   axis has g identical layers, and a polygon in that plane counts in every layer (pc / g^3 is then the
//   fraction of the flat box's cells that are full, as for a solid box).
// - Threshold: a cell is a possible collision cell when the area A of V's triangles inside it satisfies
//   A > 0 and A >= tau * F, where F = (ab + bc + ca) / 3 is the mean face area of a cell with sides
//   a, b, c = extent / g (F = c^2 for cubic cells, matching the LB table's "fraction of c^2").
// - Default tau = 0.25 (kDefaultAdbTau), one of the LB table's rows. Measured, not derived: bench_adb on
//   the protocol (300 steps per distance, p_min sweep 0.5..0.99, ADB on AABB g = 2 against exact trees in
//   the same run) gave the better error/time front with 0.25 than with 0.5 on both meshes measured: the
//   housing reached total error <= 4% at 3.3x the exact 24-DOP's speed (0.5: 1.6x), the pipes 12.7x
//   (0.5: 12.2x); 0.1 and 1.0 were worse on the housing. For scale (Crofton, random planes in a cubic cell):
//   a flat surface of area A gets about 1.12 / 0.92 / 0.74 / 0.54 times A / c^2 possible collision cells
//   for tau = 0.25 / 0.5 / 0.75 / 1, so 0.25 counts nearly every cell a surface really crosses and ignores
//   only the cells it nicks at a corner.
//
// Exactness ("exact where it matters": only the thresholded count is stored, so every cell decision is
// certified, and arithmetic is exact only where a decision needs it)
// - Every area is carried as a certified interval. A triangle whose bounding box lies inside one closed cell
//   contributes its whole area, no clipping (most triangle-node pairs: in every node above the last few
//   levels a triangle is small against the cells).
// - Otherwise it is clipped by CGAL::intersection(Triangle_3, Iso_cuboid_3) on an interval-arithmetic
//   kernel (Simple_cartesian<Interval_nt>: what Epeck evaluates first, without its lazy DAG), in coordinates
//   translated exactly to the triangle, with every face that cannot cut it moved out of the way. When an
//   interval decision is uncertain (a vertex on a clipping plane; frequent in leaves of float meshes, where
//   the mid-planes pass through edge midpoints), the area is bracketed by clips against the cell shrunk and
//   grown by a hair (area is monotone under inclusion); only if that fails too does Epeck clip exactly.
//   Measured on the 871k dragon: 18.66M clips, 971 brackets, 670 Epeck clips. Epeck for every clip measured
//   2-3 times slower, and its rational fallbacks are some 100 times slower than an interval clip.
// - A cell is decided as soon as its bounds allow (area certainly >= tau F, or certainly below it even if all
//   pending triangles fell inside in full); the last open candidate cell of a triangle gets the triangle's
//   area minus the others'. Cells whose bounds still straddle the threshold (ties, near-ties: exact ones in
//   axis-aligned test meshes, a handful in real meshes) are decided exactly: polygon areas squared as exact
//   rationals (Simple_cartesian<Gmpq>), and sum sqrt(q_i) >= T decided with GMP/MPFR (an exact rational sum
//   when every q_i is a perfect square; otherwise the sum is irrational, hence differs from the rational T,
//   and interval refinement terminates).
// - Degenerate (exactly collinear) triangles have area 0 and are skipped. A cell with area 0 never counts.
#pragma once

#include "tree.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

namespace bvhlab {

inline constexpr double kDefaultAdbTau = 0.25;

struct AnnotateOptions {
  double tau = kDefaultAdbTau;  ///< threshold as a fraction of the cell's mean face area; finite, > 0
  unsigned threads = 0;         ///< 0: hardware concurrency
  /// Called now and then with (triangle-node pairs processed, total pairs), from worker threads but never
  /// concurrently, and once at the end with (total, total).
  std::function<void(std::size_t, std::size_t)> progress;
};

struct CellCounts {
  std::vector<std::uint8_t> counts;  ///< pc per node
  AnnotateStats stats;
};

/// The annotation without templates: node i has box node_boxes[i] and the triangles
/// triangles[node_ranges[i].first .. node_ranges[i].second) (tree order, bvh/topology.hpp
/// node_triangle_ranges). grid in [1, 6] (g^3 must fit a byte).
/// Throws std::invalid_argument for a bad grid or tau, mismatched sizes, a range outside `triangles`, or a
/// node box that is empty or not finite while holding triangles.
CellCounts annotate_counts(std::span<const Box> node_boxes,
                           std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                           std::span<const TrianglePoints> triangles, int grid,
                           const AnnotateOptions& options);

/// The same with each node's grid in the node's own frame (`node_frames[i]`, an OBB's box): the node's
/// triangles are mapped into the frame (OrientedBox::local, rounded to doubles; the counts are exact for the
/// mapped triangles) and counted on the box [-half, half], grown to hold the mapped vertices should rounding
/// put one outside. An axis thinner than kMinRelativeThickness of the longest (a flat node: one triangle's
/// OBB is as thin as its rounding margin) is flattened to the plane 0, so its polygons count in every layer,
/// as in a flat axis-aligned box; the query thickens the same boxes (adb/pair_geometry.hpp).
/// Throws as annotate_counts does (an empty or non-finite frame box for a node that holds triangles).
CellCounts annotate_counts_in_frames(std::span<const OrientedBox> node_frames,
                                     std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                                     std::span<const TrianglePoints> triangles, int grid,
                                     const AnnotateOptions& options);

/// Area of the part of `triangle` inside the closed box `cell` (CGAL clipping, Epeck), to double precision.
/// 0 for degenerate triangles, boxes that miss the triangle, and empty boxes.
double triangle_area_in_box(const TrianglePoints& triangle, const Box& cell);

}  // namespace bvhlab
