// The distances a report's summary covers, per mesh pair: the scene's "quality_distances" when it names
// them, else the band where the pair's ground truth has between 5% and 95% colliding poses, found from the
// run itself. A summary over poses that all collide, or none, compares nothing: the report says so instead.
#pragma once

#include "bench/run.hpp"

#include <string>
#include <vector>

namespace bvhlab {

/// The share of colliding poses that makes a distance informative for the summary.
inline constexpr double kBandMinColliding = 0.05, kBandMaxColliding = 0.95;

struct SummaryBand {
  std::string mesh;
  double lo = -1e300, hi = 1e300;        ///< the smallest and largest distance of the run inside the band
  bool all = false;                      ///< every distance of the run
  std::size_t poses = 0, colliding = 0;  ///< the ground truth inside the band
  std::string text;                      ///< "distances 1.2–1.6 (...)", said in the report
  [[nodiscard]] bool contains(double distance) const {
    return all || (distance >= lo - 1e-12 && distance <= hi + 1e-12);
  }
  /// Both colliding and apart poses: only then can the band compare strategies.
  [[nodiscard]] bool informative() const { return colliding > 0 && colliding < poses; }
};

/// "distance", "separation" or "pose group": what the report's distance column holds for this scene.
std::string axis_word(const Scene& scene);

/// One band per mesh pair of the run's ground truth, in order of first appearance.
std::vector<SummaryBand> summary_bands(const RunOutput& run);
/// The band of `mesh`, or nullptr.
const SummaryBand* band_of(const std::vector<SummaryBand>& bands, const std::string& mesh);

}  // namespace bvhlab
