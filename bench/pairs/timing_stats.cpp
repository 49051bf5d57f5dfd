#include "bench/pairs/timing_stats.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

namespace bvhlab {

std::size_t representative_sample(std::span<const double> samples, TimingSpec::Statistic statistic) {
  if (samples.empty()) return 0;
  std::vector<std::size_t> order(samples.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return samples[a] < samples[b]; });
  return statistic == TimingSpec::Statistic::Min ? order.front() : order[samples.size() / 2];
}

void Disturbance::add(std::span<const double> pose_samples) {
  if (pose_samples.empty()) return;
  const double median = pose_samples[representative_sample(pose_samples, TimingSpec::Statistic::Median)];
  for (double t : pose_samples) {
    ++samples;
    timed_us += t;
    if (pose_samples.size() > 1 && t > kStallFactor * median + kStallMarginUs) {
      ++stalled;
      lost_us += t - median;
    }
  }
}

namespace {

double mean_of(std::span<const double> v, const std::vector<std::size_t>* picks) {
  double sum = 0;
  if (picks)
    for (std::size_t i : *picks) sum += v[i];
  else
    for (double x : v) sum += x;
  return sum / static_cast<double>(picks ? picks->size() : v.size());
}

void draw(std::vector<std::size_t>& picks, std::size_t n, std::mt19937_64& rng) {
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  picks.resize(n);
  for (std::size_t& i : picks) i = pick(rng);
}

}  // namespace

Interval ratio_of_means(std::span<const double> numerator, std::span<const double> denominator, int resamples,
                        std::uint64_t seed) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (numerator.empty() || denominator.empty()) return {kNaN, kNaN, kNaN};
  const double den = mean_of(denominator, nullptr);
  if (!(den > 0)) return {kNaN, kNaN, kNaN};
  Interval out{mean_of(numerator, nullptr) / den, kNaN, kNaN};
  if (resamples < 2) return out;
  const bool paired = numerator.size() == denominator.size();
  std::mt19937_64 rng(seed);
  std::vector<std::size_t> picks_num, picks_den;
  std::vector<double> ratios;
  ratios.reserve(static_cast<std::size_t>(resamples));
  for (int r = 0; r < resamples; ++r) {
    draw(picks_num, numerator.size(), rng);
    if (!paired) draw(picks_den, denominator.size(), rng);
    const double d = mean_of(denominator, paired ? &picks_num : &picks_den);
    if (d > 0) ratios.push_back(mean_of(numerator, &picks_num) / d);
  }
  if (ratios.empty()) return out;
  std::sort(ratios.begin(), ratios.end());
  auto at = [&](double q) {
    return ratios[std::min(ratios.size() - 1,
                           static_cast<std::size_t>(q * static_cast<double>(ratios.size())))];
  };
  out.lo = at(0.025);
  out.hi = at(0.975);
  return out;
}

}  // namespace bvhlab
