// LB, the probability that the polygons in one collision cell really intersect, as a function of the
// annotation's area threshold tau (fraction of the cell face area c^2). The values come from the Monte
// Carlo experiment in adb/lb_monte_carlo.hpp, run once by bvhlab_generate_lb_table and stored in
// adb/lb_table_data.hpp; tests/adb/test_lb_table.cpp re-runs it and requires the same counts.
#pragma once

#include <cstdint>
#include <span>

namespace bvhlab {

struct LbTableRow {
  double tau;             ///< area threshold, fraction of c^2
  std::uint64_t seed;     ///< std::mt19937_64 seed of this row's run
  std::uint64_t pairs;    ///< patch pairs sampled
  std::uint64_t hits;     ///< pairs that intersect
  double standard_error;  ///< sqrt(p (1 - p) / pairs), printed by the generator
  [[nodiscard]] constexpr double lb() const { return static_cast<double>(hits) / static_cast<double>(pairs); }
};

/// The tabulated rows, ascending in tau.
std::span<const LbTableRow> lb_table();

/// LB for a threshold tau: the tabulated value, linearly interpolated between neighbouring rows (LB is
/// smooth and increasing in tau; the interpolation error is far below the model's own uncertainty).
/// Throws std::invalid_argument for tau outside the tabulated range.
double lb_for_tau(double tau);

}  // namespace bvhlab
