// The report folder: results.csv / results.json / calibration.csv from a run, five PNG figures drawn by
// bench/plot_report.py (matplotlib), and a README.md with the tables, the figures and the operating point.
#pragma once

#include "bench/pairs/timing_stats.hpp"
#include "bench/report_folder.hpp"
#include "bench/run.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace bvhlab {

/// The figures plot_report.py draws, in order, with the README's caption for each.
struct FigureSpec {
  std::string file, caption;
};
const std::vector<FigureSpec>& report_figures();

/// One (mesh, hierarchy, strategy, p_min, budget) series aggregated over a range of distances, weighting each
/// distance by its number of queries.
struct SeriesSummary {
  std::string mesh, hierarchy, bv, annotation, strategy, label, budget;
  bool exact_strategy = true;
  double p_min = -1;
  std::size_t queries = 0;
  double mean_time_us = 0, median_time_us = 0, p99_time_us = 0, max_time_us = 0, fp_rate = 0, fn_rate = 0;
  double bv_tests_per_query = 0, triangle_tests_per_query = 0, estimates_per_query = 0,
         bytes_per_triangle = 0;
  std::vector<double> pose_times_us;  ///< its rows' per-pose times, in row order (bootstrap intervals)
};
/// Series over distances in [lo, hi], in the order the rows first appear.
std::vector<SeriesSummary> summarize(const std::vector<ResultRow>& rows, double lo, double hi);
/// Series over the rows inside their pair's summary band (ResultRow::in_summary).
std::vector<SeriesSummary> summarize_band(const std::vector<ResultRow>& rows);

/// Whether two series did the same work: BV tests, triangle tests and estimates per query each within 1%.
/// Their times then differ by the machine, not by the method: the report calls it no speed-up.
bool same_work(const SeriesSummary& a, const SeriesSummary& b);
/// How `slow` compares with `fast` in time: the ratio of their mean times with its 95% bootstrap interval.
Interval time_ratio(const SeriesSummary& slow, const SeriesSummary& fast);
/// The words for that comparison: "same work", "no measurable difference" when the interval holds 1, else
/// the speed-up (or slow-down) with its interval. `bold` marks the verdict for Markdown.
std::string speedup_text(const Interval& ratio, bool same_work, bool bold = true);

/// One step of a p_min curve (figure 3): a series at two neighbouring p_min, everything else equal, over the
/// pairs' bands. The curve should follow its work: where the BV tests per query change by more than 1%, the
/// time may not move measurably the other way (its ratio's 95% interval entirely on the other side of 1).
struct CurveStep {
  std::string mesh, hierarchy, curve;  ///< curve: the series' label without its p_min
  double p_min = 0, next_p_min = 0;
  double bv_tests = 0, next_bv_tests = 0;  ///< per query
  Interval time_ratio;                     ///< next p_min's time over this one's
  bool same_work = false;                  ///< BV tests, triangle tests and estimates within 1%
  bool against_work = false;               ///< the time moved measurably against the BV tests
};
/// Every step of every p_min curve among `series` (one curve per mesh, hierarchy, and label without its
/// p_min, of two p_min or more), in the order the curves first appear, by rising p_min.
std::vector<CurveStep> pmin_curve_steps(const std::vector<SeriesSummary>& series);

/// The error/time front of one mesh pair over the quality range: the fastest exact series, and the fastest
/// inexact series whose wrong answers (FP + FN) are at most `max_error`. The yardstick: the second
/// at least 3x faster than the first.
struct FrontPoint {
  std::string mesh;
  std::optional<SeriesSummary> fastest_exact, fastest_inexact;
  double speedup = 0;  ///< exact mean time / inexact mean time; 0 when either is missing
  Interval interval;   ///< the speed-up's 95% bootstrap interval over the poses
  bool same_work = false;
};
inline constexpr double kFrontMaxError = 0.04;
std::vector<FrontPoint> error_time_front(const std::vector<SeriesSummary>& series, double max_error);

/// The operating point of one mesh pair: ADB at the scene's chosen (hierarchy, p_min) against the baseline.
struct OperatingPoint {
  std::string mesh;
  SeriesSummary adb, baseline;
  double speedup = 0;  ///< baseline mean time / ADB mean time
  Interval interval;   ///< the speed-up's 95% bootstrap interval over the poses
  bool same_work = false;
};
std::vector<OperatingPoint> operating_points(const RunOutput& run);
/// How far one ADB-type series' reported probabilities are from what happens, over the deciles of
/// calibration.csv that hold enough answers to say (a decile with few answers is mostly noise).
struct CalibrationSummary {
  std::string mesh, hierarchy, strategy, label, budget;
  double p_min = -1;
  bool calibrated = false;                 ///< the series' probabilities through its calibration map
  std::size_t answers = 0;                 ///< over all deciles
  std::size_t qualifying_bins = 0;         ///< deciles holding at least min_answers
  std::size_t qualifying_above_tenth = 0;  ///< of those, the deciles above 0.1
  double max_gap = 0;                      ///< largest |mean reported - observed| over those; NaN if none
  double worst_reported = 0, worst_observed = 0;  ///< the decile of max_gap
  double worst_low = 0, worst_high = 0;
  /// Enough spread to judge: at least kCalibrationMinDeciles qualifying deciles, one of them above 0.1.
  bool judgeable = false;
  bool meets = false;  ///< judgeable, and every qualifying decile within the tolerance
};
constexpr std::size_t kCalibrationMinAnswers = 50;
constexpr std::size_t kCalibrationMinDeciles = 3;
constexpr double kCalibrationTolerance = 0.05;
/// One summary per series, in the order the bins first appear; `rows` supplies the series' labels. Throws
/// std::invalid_argument on a bin holding answers without a finite probability or frequency.
std::vector<CalibrationSummary> calibration_summary(const std::vector<CalibrationBin>& bins,
                                                    const std::vector<ResultRow>& rows,
                                                    std::size_t min_answers = kCalibrationMinAnswers,
                                                    double tolerance = kCalibrationTolerance);

/// The x-axis label of the figures over distance, in the scene's own terms (normalised units, scene units,
/// or a pose file's groups).
std::string distance_label(const Scene& scene);

struct ReportOptions {
  bool figures = true;           ///< run the plot script
  std::filesystem::path python;  ///< empty: $BVHLAB_PYTHON, /usr/bin/python3, python3 (first with matplotlib)
  std::filesystem::path plot_script;  ///< empty: bench/plot_report.py in the source tree
};

/// Runs bench/SCRIPT_NAME (or options.plot_script) with Python on `dir` and `arguments` (already quoted);
/// returns why it failed, or "" when it exited with status 0.
std::string run_plot_script(const ReportOptions& options, const std::string& script_name,
                            const std::filesystem::path& dir, const std::string& arguments);

struct ReportFiles {
  std::filesystem::path dir, results_csv, results_json, calibration_csv, readme;
  std::vector<std::filesystem::path> figures;  ///< the PNGs that exist after plotting
  std::string plot_error;                      ///< why the figures are missing, if they are
};

/// What a pairs run's report folder holds: results.csv, results.json, calibration.csv (and poses.csv when
/// the run kept per-pose rows), figures 1 to 5 and the README. `run` must outlive it.
ReportFolder report_folder(const RunOutput& run);

/// Writes everything into `dir` (created if needed). Plotting problems are reported in plot_error and in the
/// README, never thrown: the numbers stay usable without matplotlib.
ReportFiles write_report(const RunOutput& run, const std::filesystem::path& dir,
                         const ReportOptions& options = {});

/// The README's text (exposed for tests). `figures_ok` says whether the figures were drawn.
std::string report_readme(const RunOutput& run, bool figures_ok, const std::string& plot_error = {});

/// A short results section for the project README: the operating point and the figure list.
std::string report_snippet(const RunOutput& run, const std::filesystem::path& report_dir);

}  // namespace bvhlab
