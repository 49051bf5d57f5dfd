#include "bench/pairs/aggregate.hpp"

#include "bench/report_tables.hpp"
#include "engine/policies.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace bvhlab {
namespace {

constexpr double kNotApplicable = std::numeric_limits<double>::quiet_NaN();

/// What a row is: the pair, the hierarchy, the strategy variant, the distance and A's model.
ResultRow series_row(const std::string& label, const HierarchySpec& h, const ModelInfo& model,
                     const StrategyVariant& variant, double distance) {
  ResultRow row;
  row.mesh = label;
  row.hierarchy = h.name;
  row.bv = h.bv;
  row.annotation = model.annotation;
  row.strategy = variant.strategy;
  row.label = variant.label();
  const StrategyInfo& strategy = strategy_info(variant.strategy);
  row.exact_strategy = strategy.exact;
  row.p_min = variant.value_or("p_min", -1);
  row.budget = variant.budget_label();
  row.distance = distance;
  // The bytes the strategy reads: a strategy that needs no density does not read the annotation; a wide walk
  // reads the wide layout and the binary tree's leaves (both forms counted, as bench_wide counts them).
  row.model_bytes = strategy.needs_density ? model.model_bytes : model.model_bytes - model.density_bytes;
  if (variant.wide) row.model_bytes += model.wide_bytes;
  row.bytes_per_triangle = model.triangles ? row.model_bytes / double(model.triangles) : 0;
  return row;
}

/// Per pose of the slice, the reference distance: the first exact distance series of the plan, bvhlab's
/// before FCL's; empty when there is none.
std::vector<double> reference_distances(const RunPlan& plan, const PoseSlice& slice,
                                        const PairRecords& records) {
  for (const bool fcl : {false, true})
    for (std::size_t i = 0; i < plan.hierarchies.size(); ++i) {
      if (plan.hierarchies[i].hierarchy->is_fcl() != fcl) continue;
      for (std::size_t v = 0; v < plan.hierarchies[i].variants.size(); ++v) {
        const StrategyVariant& variant = plan.hierarchies[i].variants[v];
        if (!strategy_info(variant.strategy).exact || slice.poses.empty()) continue;
        const auto& [g0, k0] = slice.poses.front();
        if (std::isnan(records[g0][i][v][k0].distance)) continue;
        std::vector<double> out;
        for (const auto& [g, k] : slice.poses) out.push_back(records[g][i][v][k].distance);
        return out;
      }
    }
  return {};
}

/// A distance series' intervals against the reference (ResultRow::distance_error and what follows it).
void tally_distances(const std::vector<QueryRecord>& records, const std::vector<double>& reference,
                     ResultRow& row) {
  if (records.empty() || reference.empty() || std::isnan(records.front().distance)) return;
  constexpr double kRounding = 1e-9;  // relative: what two exact computations of one distance may differ by
  double error = 0;
  std::vector<double> widths;
  std::size_t tenth = 0;
  for (std::size_t k = 0; k < records.size(); ++k) {
    const double truth = reference[k], upper = records[k].distance, lower = records[k].lower_bound;
    error = std::max(error, std::fabs(upper - truth) / (truth > 0 ? truth : 1));
    const double slack = kRounding * truth;
    row.interval_misses += lower > truth + slack || upper < truth - slack;
    if (truth <= 0) continue;
    widths.push_back((upper - lower) / truth);
    tenth += upper - lower <= 0.1 * truth;
  }
  row.distance_error = error;
  if (widths.empty()) return;
  row.width_median = report_tables::median(widths);
  row.width_tenth_rate = double(tenth) / double(widths.size());
}

}  // namespace

TruthSummary summarize_truth(const std::string& label, const PoseSlice& slice, const Truth& truth) {
  TruthSummary summary{label, slice.distance, slice.poses.size(), 0};
  for (const auto& [g, k] : slice.poses) summary.colliding += truth[g][k];
  return summary;
}

void Aggregation::add_slice(const PreparedPair& pair, const RunPlan& plan, const PoseSlice& slice,
                            const Truth& truth, const PairRecords& records, RunOutput& output,
                            const SeriesMaps& maps) {
  std::vector<std::uint8_t> slice_truth;
  for (const auto& [g, k] : slice.poses) slice_truth.push_back(truth[g][k]);
  const std::vector<double> reference = reference_distances(plan, slice, records);
  std::vector<QueryRecord> slice_records;
  for (std::size_t i = 0; i < plan.hierarchies.size(); ++i) {
    const HierarchySpec& h = *plan.hierarchies[i].hierarchy;
    const PreparedHierarchy& hierarchy = *pair.hierarchies[i];
    for (std::size_t v = 0; v < plan.hierarchies[i].variants.size(); ++v) {
      slice_records.clear();
      for (const auto& [g, k] : slice.poses) slice_records.push_back(records[g][i][v][k]);
      const StrategyVariant& variant = plan.hierarchies[i].variants[v];
      ResultRow row = series_row(pair.label, h, hierarchy.model, variant, slice.distance);
      const std::string key = pair.label + "\x1f" + h.name + "\x1f" + variant.label();
      tally(slice_records, slice_truth, key, hierarchy.has_counters(), row, output.stats);
      tally_distances(slice_records, reference, row);
      const CalibrationBin series{pair.label, h.name, row.strategy, row.budget, row.p_min};
      if (!row.exact_strategy) register_series(key, series);
      if (i < maps.size() && v < maps[i].size() && maps[i][v]) {
        const std::string calibrated_key = key + "\x1f" + "calibrated";
        CalibrationBin calibrated = series;
        calibrated.calibrated = true;
        register_series(calibrated_key, calibrated);
        for (std::size_t k = 0; k < slice_records.size(); ++k)
          bin(calibrated_key, (*maps[i][v])(slice_records[k].probability), slice_truth[k] != 0);
      }
      if (per_pose_ != PerPose::none)
        keep_poses(slice_records, slice_truth, slice, output.rows.size(), hierarchy.has_counters(),
                   output.poses);
      output.rows.push_back(std::move(row));
    }
  }
}

void Aggregation::tally(const std::vector<QueryRecord>& records, const std::vector<std::uint8_t>& truth,
                        const std::string& series_key, bool has_counters, ResultRow& row, RunStats& stats) {
  row.queries = records.size();
  std::size_t fp = 0, fn = 0, truth_yes = 0, answer_yes = 0, inexact = 0, exhausted = 0;
  double sum_us = 0;
  row.pose_times_us.clear();
  Counters counters;
  const bool calibrate = !row.exact_strategy;
  for (std::size_t k = 0; k < records.size(); ++k) {
    const QueryRecord& r = records[k];
    const bool truly = truth[k] != 0;
    fp += r.collides && !truly;
    fn += !r.collides && truly;
    truth_yes += truly;
    answer_yes += r.collides;
    inexact += !r.exact;
    exhausted += r.budget_exhausted;
    const double micros = net_micros(r.micros, clock_overhead_us_);
    sum_us += micros;
    row.pose_times_us.push_back(micros);
    counters += r.counters;
    if (calibrate) bin(series_key, r.probability, truly);
  }
  const double n = std::max<double>(1.0, double(records.size()));
  row.truth_colliding_rate = double(truth_yes) / n;
  row.answer_colliding_rate = double(answer_yes) / n;
  row.fp_rate = double(fp) / n;
  row.fn_rate = double(fn) / n;
  row.inexact_rate = double(inexact) / n;
  row.budget_exhausted_rate = double(exhausted) / n;
  row.mean_time_us = sum_us / n;
  row.median_time_us = report_tables::median(row.pose_times_us);
  row.p99_time_us = report_tables::quantile(row.pose_times_us, 0.99);
  row.max_time_us = report_tables::quantile(row.pose_times_us, 1);
  if (has_counters) {
    row.bv_tests_per_query = double(counters.bv_tests) / n;
    row.triangle_tests_per_query = double(counters.triangle_tests) / n;
    row.nodes_visited_per_query = double(counters.nodes_visited) / n;
    row.estimates_per_query = double(counters.probability_evaluations) / n;
  } else {
    row.bv_tests_per_query = row.triangle_tests_per_query = row.nodes_visited_per_query =
        row.estimates_per_query = kNotApplicable;
  }
  stats.queries += records.size();
  stats.query_seconds += sum_us * 1e-6;
}

void Aggregation::bin(const std::string& series_key, double probability, bool truly) {
  auto& acc = bins_[series_key];
  const std::size_t b = std::min<std::size_t>(9, static_cast<std::size_t>(std::max(0.0, probability) * 10));
  ++acc.count[b];
  acc.probability_sum[b] += probability;
  acc.colliding[b] += truly;
}

void Aggregation::register_series(const std::string& key, const CalibrationBin& series) {
  if (series_.count(key)) return;
  series_[key] = series;
  order_.push_back(key);
}

void Aggregation::keep_poses(const std::vector<QueryRecord>& records, const std::vector<std::uint8_t>& truth,
                             const PoseSlice& slice, std::size_t row, bool has_counters,
                             std::vector<PoseRecord>& out) const {
  for (std::size_t k = 0; k < records.size(); ++k) {
    const QueryRecord& r = records[k];
    const bool truly = truth[k] != 0;
    if (per_pose_ == PerPose::wrong && r.collides == truly) continue;
    out.push_back({row, slice.poses[k].first, slice.poses[k].second, truly, r.collides, r.exact,
                   r.budget_exhausted, has_counters, r.probability, net_micros(r.micros, clock_overhead_us_),
                   r.counters});
  }
}

std::vector<CalibrationBin> Aggregation::calibration() const {
  std::vector<CalibrationBin> out;
  for (const std::string& key : order_) {
    const Bins& acc = bins_.at(key);
    for (std::size_t bin = 0; bin < 10; ++bin) {
      CalibrationBin b = series_.at(key);
      b.bin_low = double(bin) / 10;
      b.bin_high = double(bin + 1) / 10;
      b.count = acc.count[bin];
      b.mean_probability =
          acc.count[bin] ? acc.probability_sum[bin] / double(acc.count[bin]) : kNotApplicable;
      b.collision_frequency =
          acc.count[bin] ? double(acc.colliding[bin]) / double(acc.count[bin]) : kNotApplicable;
      out.push_back(b);
    }
  }
  return out;
}

}  // namespace bvhlab
