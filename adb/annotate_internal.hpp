// Internal to the ADB annotation (adb/annotate*.cpp), not installed: a node's grid, how a triangle meets it,
// and the entry points of the certified areas (annotate_area.cpp) and of the exact decisions
// (annotate_exact.cpp) that the per-node count (annotate.cpp) uses.
#pragma once

#include "../volumes/geometry.hpp"

#include <CGAL/Interval_nt.h>

#include <algorithm>
#include <array>
#include <span>

namespace bvhlab::annotate_detail {

using Interval = CGAL::Interval_nt<false>;  // needs Protect_FPU_rounding around its arithmetic

constexpr int kMaxGrid = 6;

/// A certified enclosure [lo, hi] of a nonnegative area.
struct Bounds {
  double lo = 0;
  double hi = 0;
};

struct TriangleInfo {
  std::array<double, 3> min{};
  std::array<double, 3> max{};
  Bounds area;
  bool degenerate = false;
};

/// The box a triangle is clipped against: per axis the two cell planes, or `open` for a face that cannot cut
/// the triangle (it is then placed well outside the triangle when the cuboid is built).
struct ClipBox {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
  std::array<bool, 3> open_lo{};
  std::array<bool, 3> open_hi{};
};

/// Inclusive range of cell indices along one axis; empty when first > last.
struct AxisCells {
  int first = 0;
  int last = -1;
  [[nodiscard]] bool empty() const { return first > last; }
};

/// Cell boundaries of one node: c[axis][0..g], nondecreasing, c[axis][0] = lo, c[axis][g] = hi.
struct Grid {
  int g = 0;
  std::array<std::array<double, kMaxGrid + 1>, 3> c{};

  Grid(const Box& box, int cells_per_axis) : g(cells_per_axis) {
    for (int a = 0; a < 3; ++a) {
      const double lo = box.min[a], hi = box.max[a];
      c[a][0] = lo;
      for (int i = 1; i < g; ++i) c[a][i] = std::min(hi, lo + (hi - lo) * i / g);
      c[a][g] = hi;
    }
  }

  /// Cells whose closed slab meets [mn, mx] along `axis`.
  [[nodiscard]] AxisCells touched(int axis, double mn, double mx) const {
    AxisCells r{g, -1};
    for (int i = 0; i < g; ++i)
      if (c[axis][i + 1] >= mn) {
        r.first = i;
        break;
      }
    for (int i = g - 1; i >= 0; --i)
      if (c[axis][i] <= mx) {
        r.last = i;
        break;
      }
    return r;
  }

  /// Cells whose closed slab contains [mn, mx] along `axis` (two when [mn, mx] is a shared boundary).
  [[nodiscard]] AxisCells containing(int axis, AxisCells touch, double mn, double mx) const {
    AxisCells r{g, -1};
    for (int i = touch.first; i <= touch.last; ++i)
      if (c[axis][i] <= mn && mx <= c[axis][i + 1]) {
        r.first = std::min(r.first, i);
        r.last = i;
      }
    return r;
  }
};

/// How a triangle meets a node's grid.
struct Placement {
  bool outside = false;  ///< misses the grid (cannot happen for a valid tree)
  bool inside_cell = true;
  std::array<AxisCells, 3> candidate{};  ///< per axis: containing cells if any, else touched cells
  std::array<bool, 3> contained{};       ///< per axis: the candidates contain the triangle's extent
};

inline Placement place(const Grid& grid, const TriangleInfo& t) {
  Placement p;
  for (int a = 0; a < 3; ++a) {
    const AxisCells touch = grid.touched(a, t.min[a], t.max[a]);
    if (touch.empty()) {
      p.outside = true;
      return p;
    }
    const AxisCells contain = grid.containing(a, touch, t.min[a], t.max[a]);
    p.contained[a] = !contain.empty();
    // A touched cell that does not contain the extent while another one does meets the triangle in a
    // zero-thickness slab only: no area there, so it is not a candidate.
    p.candidate[a] = p.contained[a] ? contain : touch;
    p.inside_cell = p.inside_cell && p.contained[a];
  }
  return p;
}

/// The box to clip against for cell (i, j, k). A face that cannot cut the triangle is left open: both faces
/// along an axis where the cell contains the triangle's extent, and the grid's outer faces when the triangle
/// lies on their inner side (always, in a valid tree). The clipped polygon is the same, a zero-width slab
/// (flat node) never reaches CGAL as a degenerate cuboid, and, above all, a vertex lying exactly on the node
/// box (the box is fitted to the vertices, so every node has such vertices) does not make an interval
/// decision uncertain. Returns false when the cell meets the triangle in zero area: a zero-width slab that
/// does not contain the triangle's extent.
inline bool make_clip_box(const Grid& grid, const TriangleInfo& t, const Placement& p,
                          const std::array<int, 3>& cell, ClipBox& out) {
  for (int a = 0; a < 3; ++a) {
    const int g = grid.g;
    out.lo[a] = grid.c[a][cell[a]];
    out.hi[a] = grid.c[a][cell[a] + 1];
    if (p.contained[a]) {
      out.open_lo[a] = out.open_hi[a] = true;
    } else {
      if (!(out.lo[a] < out.hi[a])) return false;
      out.open_lo[a] = cell[a] == 0 && t.min[a] >= out.lo[a];
      out.open_hi[a] = cell[a] == g - 1 && t.max[a] <= out.hi[a];
    }
  }
  return true;
}

inline Bounds to_bounds(const Interval& x) {
  return {std::max(0.0, x.inf()), x.sup()};
}

template <class K>
typename K::Point_3 point(const Vec3& v) {
  return typename K::Point_3(v.x(), v.y(), v.z());
}

/// A clip problem in concrete coordinates.
struct ClipProblem {
  TrianglePoints triangle;
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
};

/// The clip problem translated, per axis, by the triangle's smallest coordinate whenever every subtraction
/// involved is exact (Sterbenz: values within a factor 2 of each other), so it is the same problem with
/// small coordinates: a leaf of the 871k dragon is 1e-4 wide at coordinates near 1, and interval arithmetic
/// on the raw coordinates loses four more digits in every clipping step. Open faces are placed one triangle
/// extent outside the triangle.
ClipProblem shifted(const TrianglePoints& t, const ClipBox& box);

/// Bounds on the area, and whether the triangle is degenerate (exactly collinear: area 0).
TriangleInfo make_info(const TrianglePoints& t);

/// Certified area of triangle ∩ box.
/// Interval decisions are uncertain in one frequent structural case: a leaf's box is its triangle's bounding
/// box, so when the mesh coordinates are floats the mid-planes of two axes meet exactly on the edge that
/// spans the box diagonally, and the clipped vertex on one plane lies exactly on the next. Recomputing such a
/// clip in rationals (Epeck's fallback) costs about 100 times more. Instead the area is bracketed: the area
/// inside a box is monotone under inclusion, so the clips against the box shrunk and grown by a hair (about
/// 2^-26 of the cell, at least 2^-40 of its coordinates) bound it from below and above. The bracket is
/// narrower than any realistic margin to the threshold; cells it leaves undecided go to the exact decision.
/// Only if the bracketing clips are uncertain too does Epeck compute the exact polygon.
Bounds clipped_area_bounds(const TrianglePoints& t, const ClipBox& box);

/// Whether cell `cell` of a node's grid holds area >= tau * its mean face area, decided in exact arithmetic
/// (for the ties and near-ties the certified bounds leave open). `triangles` and `infos` are the node's.
bool cell_counts_exactly(const Grid& grid, const std::array<int, 3>& cell, const Box& node_box, double tau,
                         std::span<const TrianglePoints> triangles, std::span<const TriangleInfo> infos);

}  // namespace bvhlab::annotate_detail
