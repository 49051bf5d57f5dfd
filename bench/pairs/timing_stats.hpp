// The statistics that make a run's times trustworthy on a noisy machine: one time per (series, pose) from k
// warm samples, the share of the timed time lost to stalls, and bootstrap intervals of time ratios. Shared by
// the runner (measure.cpp), the report (report.cpp) and `bvhlab query --repeat`.
#pragma once

#include "bench/core/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <span>

namespace bvhlab {

/// Which of a pose's k samples stands for it: the median (nearest rank: the upper middle one for an even k)
/// or the minimum. Its index, so that the answer reported is the one of the query whose time is reported.
std::size_t representative_sample(std::span<const double> samples, TimingSpec::Statistic statistic);

/// A sample is a stall when it exceeds its pose's median by this factor and this margin: preemption, an
/// interrupt or a page fault, not the query's own work, which the other passes over the pose repeat.
inline constexpr double kStallFactor = 3, kStallMarginUs = 1;
/// A run that lost at least this share of its timed time to stalls says so in its report.
inline constexpr double kDisturbedShare = 0.01;

/// What stalls cost a run: every timed sample, and the time the stalled ones spent beyond their pose's
/// median.
struct Disturbance {
  std::size_t samples = 0, stalled = 0;
  double timed_us = 0, lost_us = 0;
  /// Adds one pose's k samples (raw, clock included).
  void add(std::span<const double> samples);
  [[nodiscard]] double share() const { return timed_us > 0 ? lost_us / timed_us : 0; }
};

/// A value with its 95% interval.
struct Interval {
  double value = 0, lo = 0, hi = 0;
  [[nodiscard]] bool contains(double v) const { return lo <= v && v <= hi; }
};
/// mean(numerator) / mean(denominator), with a 95% percentile interval from `resamples` bootstrap resamples
/// of the poses (fixed seed: the same data give the same interval). Paired when both hold one time per pose
/// of the same poses (equal sizes), each resampled alone otherwise. NaN for an empty side or a zero mean.
Interval ratio_of_means(std::span<const double> numerator, std::span<const double> denominator,
                        int resamples = 1000, std::uint64_t seed = 1);

}  // namespace bvhlab
