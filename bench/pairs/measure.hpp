// The measure stage of the bench pipeline (parse -> plan -> prepare -> measure -> aggregate -> write): each
// pair's exact ground truth (cached on disk, cross-checked against CGAL on a sample), then every planned
// series timed on the same poses. Internal to the runner (bench/pairs/run.cpp).
#pragma once

#include "adb/calibration.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/pairs/timing_stats.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

namespace bvhlab {

/// What an empty timed region costs: the median of back-to-back clock reads. Subtracted from every query time
/// (clamped at 0), so that sub-microsecond ADB answers are not inflated by the clock itself.
double clock_overhead_us();
/// A timed query's time less the clock's own overhead, clamped at 0: as results.csv and `query --repeat`
/// report it.
inline double net_micros(double micros, double clock_overhead_us) {
  return std::max(0.0, micros - clock_overhead_us);
}

/// Each pose's answer for a query with warm repeats: first(pose) once per pose, timed (cold), with its full
/// result; then `repeat` passes of series(poses, records), each timing every pose once in order (so a pose
/// comes back only after all the others, and the branch predictor cannot learn it), each time net of the
/// clock's overhead.
template <class First, class Series>
std::vector<PoseAnswer> answer_poses(std::span<const RigidTransform> poses, int repeat,
                                     double clock_overhead_us, First&& first, Series&& series) {
  std::vector<PoseAnswer> answers(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto start = Clock::now();
    answers[k].result = first(poses[k]);
    answers[k].micros = std::chrono::duration<double, std::micro>(Clock::now() - start).count();
  }
  std::vector<QueryRecord> records;
  for (int pass = 0; pass < repeat; ++pass) {
    series(poses, records);
    for (std::size_t k = 0; k < poses.size(); ++k)
      answers[k].warm_micros.push_back(net_micros(records[k].micros, clock_overhead_us));
  }
  return answers;
}

/// answer_poses with a prepared query of the run-time layer: its first answer at each pose, then `repeat`
/// timed passes (PreparedQuery::time). A coherent query's first answers run over the poses in order with one
/// state, and each timed pass with a state of its own.
std::vector<PoseAnswer> answer_prepared(const PreparedQuery& query, std::span<const RigidTransform> poses,
                                        int repeat);

using Truth = std::vector<std::vector<std::uint8_t>>;  // [group][pose] -> 0/1

/// Files in one directory, one per key, named by the key's hash: the key's hash again, then the payload.
/// Reading checks that hash, so a file made for another key is stale, not misread. The ground truth and the
/// calibration maps are kept this way, each payload with its own checked encoding. An empty directory:
/// nothing is read or written.
class KeyedFileCache {
 public:
  KeyedFileCache(std::filesystem::path dir, std::string extension, std::string what)
      : dir_(std::move(dir)), extension_(std::move(extension)), what_(std::move(what)) {}

  /// decode(payload) for the file under `key`, or nothing: no file, or one that is stale or does not decode
  /// (decode throws), which `why` then names.
  template <class Decode>
  auto load(const std::string& key, std::string* why, Decode decode) const
      -> std::optional<decltype(decode(std::span<const std::byte>{}))> {
    const std::filesystem::path file = file_of(key);
    if (dir_.empty() || !std::filesystem::exists(file)) return std::nullopt;
    try {
      const std::vector<std::byte> bytes = read(file, key);
      return decode(std::span(bytes).subspan(kKeyBytes));
    } catch (const std::exception& e) {
      *why = file.filename().string() + ": " + e.what();
      return std::nullopt;
    }
  }
  /// Writes `payload` under `key`; a failure is logged ("<what> cache: could not store (...)"), not thrown.
  void store(const std::string& key, std::span<const std::byte> payload, const LogFn& log) const;
  [[nodiscard]] std::filesystem::path file_of(const std::string& key) const;

 private:
  static constexpr std::size_t kKeyBytes = 8;
  /// The file's bytes, key hash included; throws when it was made for another key.
  static std::vector<std::byte> read(const std::filesystem::path& file, const std::string& key);

  std::filesystem::path dir_;
  std::string extension_, what_;
};

/// Progress bar on stderr: redrawn in place on a terminal, a line per tenth otherwise.
class Progress {
 public:
  Progress(bool enabled, std::size_t total);
  void advance(std::size_t done, const std::string& label);

 private:
  bool enabled_;
  std::size_t total_, done_ = 0;
  bool tty_;
  int printed_tenth_ = 0;
  Clock::time_point last_{};
};

/// One pose group's timed records: [planned hierarchy][variant][pose].
using GroupRecords = std::vector<std::vector<std::vector<QueryRecord>>>;
/// The timed records of every pose group of one pair, [group].
using PairRecords = std::vector<GroupRecords>;

/// Per planned series, [hierarchy][variant]: its calibration map, or none (exact series, or no
/// "calibration").
using SeriesMaps = std::vector<std::vector<std::optional<CalibrationMap>>>;

/// The measure stage of one run.
class Measurement {
 public:
  Measurement(const Scene& scene, const RunPlan& plan, const RunOptions& options, RunStats& stats, LogFn log,
              unsigned threads);
  /// The pair's ground truth: from the disk cache, else the exact traversal on the first bvhlab hierarchy
  /// (plain AABB trees from `preparation` if there is none); then the CGAL cross-check.
  Truth ground_truth(const PreparedPair& pair, Preparation& preparation);
  /// Every planned series of every pair on every pose group, [pair][group]: the scene's `timing.repeats`
  /// passes over the whole workload, each (series, pose) kept as the query of its representative sample.
  std::vector<PairRecords> time_workload(const std::vector<PreparedPair>& pairs);
  /// With the scene's "calibration": every inexact series' map, from the disk cache or fitted on the training
  /// poses against their exact truth (itself cached like the workload's). Without: no maps.
  SeriesMaps calibration_maps(const PreparedPair& pair, Preparation& preparation);

 private:
  Truth compute_truth(const PreparedPair& pair, Preparation& preparation, const WorkloadSpec& workload);
  Truth cached_truth(const PreparedPair& pair, Preparation& preparation, const WorkloadSpec& workload);
  void cross_check(const PreparedPair& pair, const Truth& truth);
  /// One pass over pose group `g` of `pair`: each series' records appended to series[s] (flat index).
  void time_pass(const PreparedPair& pair, std::size_t g, std::vector<std::vector<QueryRecord>>& series);
  /// Per pose, the record of its representative pass (passes[pass][pose]); its samples are tallied for the
  /// run's disturbance.
  std::vector<QueryRecord> representatives(const std::vector<std::vector<QueryRecord>>& passes);

  const Scene& scene_;
  const RunPlan& plan_;
  RunStats& stats_;
  LogFn log_;
  unsigned threads_;
  int warmup_;
  KeyedFileCache truth_cache_;        ///< payload: encode_truth
  KeyedFileCache calibration_cache_;  ///< payload: CalibrationMap::encode
  Progress progress_;
  Disturbance disturbance_;
  std::mt19937_64 block_order_{1};  ///< shuffles the series' order in each block (fixed seed)
};

}  // namespace bvhlab
