// The ADB probability model for one (grid, tau): the estimate for a BV pair from the nodes' bounding boxes,
// their overlap volume and their possible-collision-cell counts (adb/README.md, section 2).
//
// Decisions (the paper states only the case of two equally sized nodes; AdbRule names the choices):
//   * Cells: each node's grid lies on its bounding box, so its cells are boxes of extent / g. Differently
//     sized BVs are put on one grid. A surface crosses about area / F cells of mean face area F, so a
//     node's expected count moves between cell sizes by the ratio of the cells' mean face areas (for cubic
//     cells the square of the side ratio, 1 for equal sizes: the paper's case). The same mean face area
//     defines the annotation's threshold tau, and the ratio needs no roots.
//       - AdbRule::Cells::Finer (the default, density "adb"): the finer node's cells. s = Vol(A ∩ B) /
//         c_fine <= g^3, and the coarser node's expected count is scaled up by F_coarse / F_fine. A small
//         node inside a large node's cell then sees the large node's surface with a probability that falls
//         like the size ratio k (a sheet through a cell of side k c meets a given sub-box of side c about
//         one time in k), as it should.
//       - AdbRule::Cells::Coarser (density "adb_paper", the rule of earlier versions): the coarser node's
//         cells, the finer count scaled down by F_fine / F_coarse. The expected number of collision cells
//         then falls like k^2: a small object next to a large one looked almost never in contact (measured:
//         every collision of an 82:1 pair missed, see adb/README.md).
//   * Empty counts: a node holding polygons whose area stays below tau F in every cell has pc = 0.
//     AdbRule::count_at_least_one reads such a count as 1 (its surface lies in some cell), so that a pair
//     whose volumes overlap and whose nodes hold polygons never gets the probability 0. The paper's rule
//     (count_at_least_one = false) returns 0 for it.
//   * Rounding: s is rounded up (at least 1 when the volumes overlap, at most g^3); the fractional s_A, s_B
//     are interpolated bilinearly between the table's integer entries, so a query still does no
//     transcendental math and a small expected count is not rounded away to a probability of 0.
#pragma once

#include "../volumes/geometry.hpp"
#include "lb_table.hpp"
#include "probability.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <memory>

namespace bvhlab {

/// The choices of the estimate that the paper leaves open (header comment).
struct AdbRule {
  /// Which node's cells a differently sized pair is counted on.
  enum class Cells : std::uint8_t { Finer, Coarser } cells = Cells::Finer;
  /// Read pc = 0 of a node holding polygons as 1: never the probability 0 for overlapping volumes.
  bool count_at_least_one = true;
};
/// The default ("adb"): finer cells, no empty count.
inline constexpr AdbRule kAdbSizedRule{AdbRule::Cells::Finer, true};
/// The paper's literal rule ("adb_paper"), with the coarser-cell mapping for differently sized nodes.
inline constexpr AdbRule kAdbPaperRule{AdbRule::Cells::Coarser, false};

/// The probability model for one (grid, tau): the lookup table over (s, s_A, s_B). Built once, shared
/// read-only by any number of queries and threads.
class AdbModel {
 public:
  AdbModel(int grid, double tau) : grid_(grid), tau_(tau), table_(grid * grid * grid, lb_for_tau(tau)) {}

  [[nodiscard]] int grid() const { return grid_; }
  [[nodiscard]] double tau() const { return tau_; }
  [[nodiscard]] const ProbabilityTable& table() const { return table_; }

  /// The estimate for a BV pair from the nodes' own-frame bounding boxes, the overlap volume and the pc
  /// counts, under `rule` (header comment). Only arithmetic and four table loads: no transcendental math on
  /// the query path.
  template <AdbRule rule = kAdbSizedRule>
  [[nodiscard]] double estimate(const Box& box_a, const Box& box_b, double overlap, int pc_a,
                                int pc_b) const {
    if constexpr (rule.count_at_least_one) {
      pc_a = std::max(pc_a, 1);
      pc_b = std::max(pc_b, 1);
    }
    if (!(overlap > 0) || pc_a == 0 || pc_b == 0) return 0;
    const Vec3 ea = box_a.extent(), eb = box_b.extent();
    const double volume_a = ea.prod(), volume_b = eb.prod();
    // Mean face area of a cell, times 3 g^2 (the common factor cancels in the ratio).
    const double face_a = ea.x() * ea.y() + ea.y() * ea.z() + ea.z() * ea.x();
    const double face_b = eb.x() * eb.y() + eb.y() * eb.z() + eb.z() * eb.x();
    const int cells = grid_ * grid_ * grid_;
    const bool a_coarse = volume_a >= volume_b;
    // Expected possible-collision cells in the overlap, in each node's own cells...
    double s_a = volume_a > 0 ? pc_a * std::min(1.0, overlap / volume_a) : pc_a;
    double s_b = volume_b > 0 ? pc_b * std::min(1.0, overlap / volume_b) : pc_b;
    // ...one of them moved onto the other's cells by the ratio of cell face areas.
    const bool move_a = (rule.cells == AdbRule::Cells::Finer) == a_coarse;
    if (move_a)
      s_a *= face_ratio<rule.cells>(face_a, face_b);
    else
      s_b *= face_ratio<rule.cells>(face_b, face_a);
    const double cell_volume = (move_a ? volume_b : volume_a) / cells;
    const double s_real = cell_volume > 0 ? overlap / cell_volume : cells;
    const int s = !(s_real < cells) ? cells : std::clamp(ceil_to_int(s_real - 1e-9), 1, cells);
    s_a = std::min(s_a, double(s));
    s_b = std::min(s_b, double(s));
    return interpolate(s, s_a, s_b);
  }

 private:
  /// From cells of mean face area `from` to cells of `to`: up (at least 1) onto finer cells, down (at most 1)
  /// onto coarser ones. Capped, so that 0 * inf cannot make a NaN.
  template <AdbRule::Cells target>
  static double face_ratio(double from, double to) {
    if (!(from > 0 && to > 0)) return 1;
    const double ratio = from / to;
    return target == AdbRule::Cells::Finer ? std::clamp(ratio, 1.0, kMaxFaceRatio) : std::min(ratio, 1.0);
  }

  /// std::ceil for |x| < 2^31, without the library call a baseline x86-64 build makes for it.
  static int ceil_to_int(double x) {
    const int truncated = static_cast<int>(x);
    return truncated + (x > truncated ? 1 : 0);
  }

  [[nodiscard]] double interpolate(int s, double s_a, double s_b) const {
    const int a0 = static_cast<int>(s_a), b0 = static_cast<int>(s_b);
    const int a1 = std::min(a0 + 1, s), b1 = std::min(b0 + 1, s);
    const double fa = s_a - a0, fb = s_b - b0;
    assert(s >= 0 && s <= table_.s_max() && s_a >= 0 && s_a <= s && s_b >= 0 && s_b <= s);
    const double* layer = table_.layer(s);
    const double p00 = ProbabilityTable::at(layer, a0, b0), p10 = ProbabilityTable::at(layer, a1, b0);
    const double p01 = ProbabilityTable::at(layer, a0, b1), p11 = ProbabilityTable::at(layer, a1, b1);
    return (1 - fa) * ((1 - fb) * p00 + fb * p01) + fa * ((1 - fb) * p10 + fb * p11);
  }

  static constexpr double kMaxFaceRatio = 1e30;

  int grid_;
  double tau_;
  ProbabilityTable table_;
};

/// The shared model for (grid, tau): built once per process and parameter pair, then shared read-only by
/// every tree annotated with them. Thread-safe. Throws std::invalid_argument for a grid outside [1, 6] or a
/// tau without an LB value.
std::shared_ptr<const AdbModel> shared_adb_model(int grid, double tau);

}  // namespace bvhlab
