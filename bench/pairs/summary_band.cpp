#include "bench/pairs/summary_band.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace bvhlab {
namespace {

std::string range_text(const std::string& axis, double lo, double hi) {
  return lo == hi ? fmt::format("{} {:g}", axis, lo) : fmt::format("{}s {:g}–{:g}", axis, lo, hi);
}

/// The band of one mesh: given, found from its truth, or every distance when none qualifies.
SummaryBand band_for(const RunOutput& run, const std::string& mesh) {
  const ReportSpec& spec = run.scene.report;
  const std::string axis = axis_word(run.scene);
  SummaryBand band;
  band.mesh = mesh;
  std::vector<double> inside;
  for (const TruthSummary& t : run.truth) {
    if (t.mesh != mesh || t.poses == 0) continue;
    const double share = double(t.colliding) / double(t.poses);
    const bool in = spec.quality_given
                        ? t.distance >= spec.quality_min - 1e-12 && t.distance <= spec.quality_max + 1e-12
                        : share >= kBandMinColliding && share <= kBandMaxColliding;
    if (in) inside.push_back(t.distance);
  }
  std::sort(inside.begin(), inside.end());
  if (inside.empty()) {
    band.all = true;
    band.text = fmt::format("all {}s (no {} of the run has between {:g}% and {:g}% colliding poses)", axis,
                            axis, 100 * kBandMinColliding, 100 * kBandMaxColliding);
  } else {
    band.lo = inside.front();
    band.hi = inside.back();
    band.text =
        range_text(axis, band.lo, band.hi) +
        (spec.quality_given ? std::string(" (the scene's quality_distances)")
                            : fmt::format(" (where the ground truth has {:g}% to {:g}% colliding poses)",
                                          100 * kBandMinColliding, 100 * kBandMaxColliding));
  }
  for (const TruthSummary& t : run.truth)
    if (t.mesh == mesh && band.contains(t.distance)) {
      band.poses += t.poses;
      band.colliding += t.colliding;
    }
  return band;
}

}  // namespace

std::string axis_word(const Scene& scene) {
  switch (scene.workload.axis) {
    case WorkloadSpec::Axis::Separation:
      return "separation";
    case WorkloadSpec::Axis::Group:
      return "pose group";
    case WorkloadSpec::Axis::Distance:
      break;
  }
  return "distance";
}

std::vector<SummaryBand> summary_bands(const RunOutput& run) {
  std::vector<SummaryBand> bands;
  for (const TruthSummary& t : run.truth)
    if (!band_of(bands, t.mesh)) bands.push_back(band_for(run, t.mesh));
  return bands;
}

const SummaryBand* band_of(const std::vector<SummaryBand>& bands, const std::string& mesh) {
  for (const SummaryBand& b : bands)
    if (b.mesh == mesh) return &b;
  return nullptr;
}

}  // namespace bvhlab
