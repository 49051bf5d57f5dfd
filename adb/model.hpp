// The ADB probability model for one (grid, tau): the estimate for a BV pair from the nodes' bounding boxes,
// their overlap volume and their possible-collision-cell counts (adb/README.md, section 2).
//
// Decisions:
//   * Cells: each node's grid lies on its bounding box, so its cells are boxes of extent / g. Differently
//     sized BVs are mapped onto the coarser cells (the larger cell volume): s = Vol(A ∩ B) / c_coarse, and
//     the finer side's expected count is scaled by F_fine / F_coarse, the ratio of the cells' mean face
//     areas. Possible collision cells hold surface, and a surface crosses about area / F cells; for cubic
//     cells this is the square of the side ratio, and for equal sizes it is 1: the paper's case. The
//     same mean face area defines the annotation's threshold tau, and the ratio needs no roots.
//   * Rounding: s is rounded up (at least 1 when the volumes overlap, at most g^3); the fractional s_A, s_B
//     are interpolated bilinearly between the table's integer entries, so a query still does no
//     transcendental math and a small expected count is not rounded away to a probability of 0.
#pragma once

#include "../volumes/geometry.hpp"
#include "lb_table.hpp"
#include "probability.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

namespace bvhlab {

/// The probability model for one (grid, tau): the lookup table over (s, s_A, s_B). Built once, shared
/// read-only by any number of queries and threads.
class AdbModel {
 public:
  AdbModel(int grid, double tau) : grid_(grid), tau_(tau), table_(grid * grid * grid, lb_for_tau(tau)) {}

  [[nodiscard]] int grid() const { return grid_; }
  [[nodiscard]] double tau() const { return tau_; }
  [[nodiscard]] const ProbabilityTable& table() const { return table_; }

  /// The estimate for a BV pair from the nodes' own-frame bounding boxes, the overlap volume and the pc
  /// counts. Only arithmetic and four table loads: no transcendental math on the query path.
  [[nodiscard]] double estimate(const Box& box_a, const Box& box_b, double overlap, int pc_a,
                                int pc_b) const {
    if (!(overlap > 0) || pc_a == 0 || pc_b == 0) return 0;
    const Vec3 ea = box_a.extent(), eb = box_b.extent();
    const double volume_a = ea.prod(), volume_b = eb.prod();
    // Mean face area of a cell, times 3 g^2 (the common factor cancels in the ratio).
    const double face_a = ea.x() * ea.y() + ea.y() * ea.z() + ea.z() * ea.x();
    const double face_b = eb.x() * eb.y() + eb.y() * eb.z() + eb.z() * eb.x();
    const int cells = grid_ * grid_ * grid_;
    const bool a_coarse = volume_a >= volume_b;
    const double coarse_cell = (a_coarse ? volume_a : volume_b) / cells;
    // Expected possible-collision cells in the overlap, in each node's own cells...
    double s_a = volume_a > 0 ? pc_a * std::min(1.0, overlap / volume_a) : pc_a;
    double s_b = volume_b > 0 ? pc_b * std::min(1.0, overlap / volume_b) : pc_b;
    // ...with the finer side mapped onto the coarser cells by the ratio of cell face areas.
    if (a_coarse && face_a > 0)
      s_b *= std::min(1.0, face_b / face_a);
    else if (!a_coarse && face_b > 0)
      s_a *= std::min(1.0, face_a / face_b);
    const double s_real = coarse_cell > 0 ? overlap / coarse_cell : cells;
    const int s =
        !(s_real < cells) ? cells : std::clamp(static_cast<int>(std::ceil(s_real - 1e-9)), 1, cells);
    s_a = std::min(s_a, double(s));
    s_b = std::min(s_b, double(s));
    return interpolate(s, s_a, s_b);
  }

 private:
  [[nodiscard]] double interpolate(int s, double s_a, double s_b) const {
    const int a0 = static_cast<int>(s_a), b0 = static_cast<int>(s_b);
    const int a1 = std::min(a0 + 1, s), b1 = std::min(b0 + 1, s);
    const double fa = s_a - a0, fb = s_b - b0;
    const double p00 = table_.lookup(s, a0, b0), p10 = table_.lookup(s, a1, b0);
    const double p01 = table_.lookup(s, a0, b1), p11 = table_.lookup(s, a1, b1);
    return (1 - fa) * ((1 - fb) * p00 + fb * p01) + fa * ((1 - fb) * p10 + fb * p11);
  }

  int grid_;
  double tau_;
  ProbabilityTable table_;
};

/// The shared model for (grid, tau): built once per process and parameter pair, then shared read-only by
/// every tree annotated with them. Thread-safe. Throws std::invalid_argument for a grid outside [1, 6] or a
/// tau without an LB value.
std::shared_ptr<const AdbModel> shared_adb_model(int grid, double tau);

}  // namespace bvhlab
