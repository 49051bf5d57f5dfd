// The aggregate stage of the bench pipeline (parse -> plan -> prepare -> measure -> aggregate -> write): per
// series and distance, the answers against the ground truth, the times and the work counters as one
// results row; per inexact series, the calibration of its probabilities. Internal to the runner.
#pragma once

#include "bench/pairs/measure.hpp"
#include "bench/pairs/slices.hpp"

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

namespace bvhlab {

/// The ground truth's colliding fraction of one slice, for one pair.
TruthSummary summarize_truth(const std::string& label, const PoseSlice& slice, const Truth& truth);

/// The aggregate stage of one run.
class Aggregation {
 public:
  /// Every query time is reduced by the clock's own cost (clamped at 0). `per_pose` says which queries are
  /// also kept one by one in RunOutput::poses.
  explicit Aggregation(double clock_overhead_us, PerPose per_pose = PerPose::none)
      : clock_overhead_us_(clock_overhead_us), per_pose_(per_pose) {}
  /// One row per planned series of the pair on the poses of `slice` (`truth`: the workload's ground
  /// truth; `records`: the groups' timed records), appended to output.rows in plan order; the queries and
  /// their time are added to output.stats, and the queries per_pose asks for to output.poses. A series with
  /// a map in `maps` is also binned a second time, its probabilities through the map (a calibrated series:
  /// calibration bins only, since its answers, times and counters are the raw series').
  void add_slice(const PreparedPair& pair, const RunPlan& plan, const PoseSlice& slice, const Truth& truth,
                 const PairRecords& records, RunOutput& output, const SeriesMaps& maps = {});
  /// Ten probability bins per inexact series, series in the order they first appeared.
  [[nodiscard]] std::vector<CalibrationBin> calibration() const;

 private:
  /// Per bin of the probability: queries, their summed probability, and how many truly collide.
  struct Bins {
    std::array<std::size_t, 10> count{};
    std::array<double, 10> probability_sum{};
    std::array<std::size_t, 10> colliding{};
  };
  /// The answers and times of one series, against the truth, into `row`; probabilities into the series'
  /// bins if it is inexact.
  void tally(const std::vector<QueryRecord>& records, const std::vector<std::uint8_t>& truth,
             const std::string& series_key, bool has_counters, ResultRow& row, RunStats& stats);
  /// Adds one answer to a series' bins.
  void bin(const std::string& series_key, double probability, bool truly);
  /// Registers a binned series (once), in order of first appearance.
  void register_series(const std::string& key, const CalibrationBin& series);

  /// The queries of one series that per_pose_ asks for, as rows of poses.csv for output row `row`.
  void keep_poses(const std::vector<QueryRecord>& records, const std::vector<std::uint8_t>& truth,
                  const PoseSlice& slice, std::size_t row, bool has_counters,
                  std::vector<PoseRecord>& out) const;

  double clock_overhead_us_;
  PerPose per_pose_;
  std::map<std::string, Bins> bins_;
  std::map<std::string, CalibrationBin> series_;  ///< what each binned series is, by key
  std::vector<std::string> order_;
};

}  // namespace bvhlab
