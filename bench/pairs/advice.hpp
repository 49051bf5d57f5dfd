// "The right tool, said out loud": where a scene or a query asks a strategy to work outside what it was made
// for, the words that say so and name the strategy made for the case, with the measured reason.
#pragma once

#include "bvh/mesh.hpp"

#include <cstddef>
#include <string>
#include <string_view>

namespace bvhlab {

/// Objects whose root volumes differ by more than this are "of different size" for ADB.
inline constexpr double kSizeRatioForLarger = 10;

/// The ratio of the larger to the smaller bounding-box volume (each side at least 1e-3 of the box's longest,
/// so a flat object has a volume).
double root_volume_ratio(const Mesh& a, const Mesh& b);

/// For `strategy` on objects `a` and `b` (labelled `pair`): the advice, or "" when there is none.
std::string size_advice(std::string_view strategy, const std::string& pair, const Mesh& a, const Mesh& b);

/// What one frame-budget series of a world run left without a root test, over the run's frames.
struct RootRoundShortfall {
  std::string series;                  ///< the series' name ("frame adb_probability bv_tests=50 p_min=0.9")
  std::string hierarchy;               ///< the hierarchy it ran on
  bool counts_tests = true;            ///< its budget caps BV tests (otherwise it is a deadline)
  int frames = 0, frames_short = 0;    ///< frames of the run; frames whose root round did not finish
  std::size_t candidates = 0;          ///< candidate pairs over the run
  std::size_t most_candidates = 0;     ///< the most in one frame
  std::size_t untested = 0;            ///< candidate pairs the budget left without any test
  std::size_t untested_colliding = 0;  ///< of those, colliding in truth
  std::size_t colliding = 0,
              missed = 0;  ///< colliding candidate pairs over the run; of those, answered apart
  /// The same schedule at the smallest budget of the same kind that covered every root round of the run, if
  /// the run has one: its series and its colliding and missed pairs.
  std::string covered_series;
  std::size_t covered_colliding = 0, covered_missed = 0;
};

/// For a frame budget that ended before every candidate pair had its root test (untested > 0): the advice,
/// with the run's own counts; "" otherwise.
std::string root_round_advice(const RootRoundShortfall& shortfall);

}  // namespace bvhlab
