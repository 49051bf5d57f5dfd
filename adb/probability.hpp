// The ADB probability model (Klein & Zachmann 2003): how likely a BV pair (A, B) holds intersecting
// polygons, from cell counts alone. Pure math: no geometry, no trees.
//
//   s    cells in the overlap A ∩ B,
//   s_a  possible collision cells of A expected in the overlap (0 <= s_a <= s),
//   s_b  the same for B (0 <= s_b <= s).
//
// cc, the number of collision cells (cells that are possible collision cells of both), is hypergeometric
// when each object's possible collision cells are a uniformly random subset of the s cells:
//   Pr[cc >= x] = sum_{i >= x} C(s_b, i) C(s - s_b, s_a - i) / C(s, s_a),
// and, with LB the probability that the polygons in one collision cell really intersect,
//   estimate = max over x >= 1 of Pr[cc >= x] * (1 - (1 - LB)^x).
#pragma once

#include <algorithm>
#include <cassert>
#include <cstddef>
#include <vector>

namespace bvhlab {

/// Largest cell count the direct (non-table) functions accept. The binomial ratios are formed from products
/// of two cell counts, which stay exact in a double up to here; work per call is O(min(s_a, s_b)).
inline constexpr int kMaxProbabilityCells = 10'000'000;

/// Pr[cc >= x]: the hypergeometric upper tail. Both tails are summed directly as positive terms
/// (no "1 - big sum"), so tiny tails keep their relative accuracy and the result lies in [0, 1].
/// Returns 1 for x <= max(0, s_a + s_b - s) and 0 for x > min(s_a, s_b).
/// Throws std::invalid_argument unless 0 <= s_a <= s, 0 <= s_b <= s and s <= kMaxProbabilityCells:
/// more distinct possible collision cells than cells cannot be counted, so a caller that rounds scaled
/// counts must clamp them to s itself (its rounding is its model decision, not hidden here).
double pr_collision_cells_at_least(int s, int s_a, int s_b, int x);

/// 1 - (1 - lb)^x, evaluated as -expm1(x log1p(-lb)) so that lb near 0 keeps its digits (x * lb).
/// Throws std::invalid_argument for lb outside [0, 1] (or NaN) and x < 0.
double hit_probability(double lb, int x);

struct ProbabilityEstimate {
  double probability = 0.0;  ///< max over x of Pr[cc >= x] * (1 - (1 - lb)^x), in [0, 1]
  int best_x = 0;            ///< the maximising x (smallest one on ties); 0 when no collision cell can exist
};

/// The ADB estimate, maximised over every feasible x in [max(1, s_a + s_b - s), min(s_a, s_b)] (below that
/// range Pr[cc >= x] = 1 and the hit term only grows with x; above it Pr = 0). x is not capped: one pass
/// over the support gives all tails, so a cap would save nothing, and the maximum is not always at small x
/// (it sits near the forced minimum s_a + s_b - s; at s_a = s_b = s it is x = s). Capping x at 2 lowers
/// some estimates by up to 0.23 at LB = 0.52 (s <= 64), at 4 by up to 0.05.
/// Same preconditions as pr_collision_cells_at_least, plus lb in [0, 1].
ProbabilityEstimate estimate_probability_detailed(int s, int s_a, int s_b, double lb);
inline double estimate_probability(int s, int s_a, int s_b, double lb) {
  return estimate_probability_detailed(s, s_a, s_b, lb).probability;
}

/// estimate_probability for every (s, s_a, s_b) with 0 <= s_a, s_b <= s <= s_max, for one LB, computed
/// once so that a query is one index computation and one load.
///
/// The estimate is symmetric in (s_a, s_b) (swapping the colours of the balls), so only s_a >= s_b is
/// stored: (s_max + 1)(s_max + 2)(s_max + 3) / 6 doubles; s_max = 64 takes 375 KiB, s_max = 8 (the paper's
/// 2x2x2 grid) 1.3 KiB. Choose s_max >= g^3 for a g x g x g cell grid: the overlap of two equally sized
/// BVs, or of differently sized ones mapped onto the coarser cells, never holds more than g^3 cells.
/// s_max is capped at kMaxTableCells (27 MiB) to keep the table a cache, not a data set.
class ProbabilityTable {
 public:
  static constexpr int kMaxTableCells = 256;

  /// Throws std::invalid_argument for s_max outside [0, kMaxTableCells] or lb outside [0, 1].
  ProbabilityTable(int s_max, double lb);

  [[nodiscard]] int s_max() const noexcept { return s_max_; }
  [[nodiscard]] double lb() const noexcept { return lb_; }
  [[nodiscard]] std::size_t entries() const noexcept { return values_.size(); }
  [[nodiscard]] std::size_t memory_bytes() const noexcept { return values_.size() * sizeof(double); }

  /// Hot path. Precondition (asserted in debug builds only): 0 <= s_a, s_b <= s <= s_max().
  [[nodiscard]] double lookup(int s, int s_a, int s_b) const noexcept {
    assert(s >= 0 && s <= s_max_ && s_a >= 0 && s_a <= s && s_b >= 0 && s_b <= s);
    return at(layer(s), s_a, s_b);
  }

  /// The entries of one s, for several lookups at the same s (AdbModel's interpolation): at(layer(s), ...)
  /// is lookup(s, ...). Precondition as lookup's.
  [[nodiscard]] const double* layer(int s) const noexcept {
    assert(s >= 0 && s <= s_max_);
    return values_.data() + layer_start(s);
  }
  [[nodiscard]] static double at(const double* layer, int s_a, int s_b) noexcept {
    const auto [lo, hi] = std::minmax(s_a, s_b);
    return layer[in_layer(hi, lo)];
  }

  /// Checked query. Inside the table it returns lookup(); for s > s_max it computes the estimate directly
  /// (same value the table would hold, at the cost of transcendental math), rather than rescaling the
  /// counts: shrinking s, s_a, s_b by s_max / s shrinks the expected number of collision cells
  /// s_a s_b / s by the same factor and would bias the estimate low. Throws like estimate_probability.
  [[nodiscard]] double estimate(int s, int s_a, int s_b) const;

 private:
  // Layer s starts at the tetrahedral number s(s+1)(s+2)/6; inside it, row hi holds hi + 1 entries.
  static std::size_t layer_start(int s) noexcept {
    const auto su = static_cast<std::size_t>(s);
    return su * (su + 1) * (su + 2) / 6;
  }
  static std::size_t in_layer(int hi, int lo) noexcept {
    const auto hu = static_cast<std::size_t>(hi);
    return hu * (hu + 1) / 2 + static_cast<std::size_t>(lo);
  }
  static std::size_t index(int s, int hi, int lo) noexcept { return layer_start(s) + in_layer(hi, lo); }

  int s_max_;
  double lb_;
  std::vector<double> values_;
};

}  // namespace bvhlab
