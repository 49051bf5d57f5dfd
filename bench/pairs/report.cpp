#include "bench/pairs/report.hpp"

#include "bench/pairs/report_internal.hpp"
#include "bench/pairs/slices.hpp"
#include "bench/pairs/summary_band.hpp"
#include "bench/pairs/write.hpp"
#include "bench/report_folder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace bvhlab {
namespace {

using namespace report_detail;

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string find_python() {
  std::vector<std::string> candidates;
  if (const char* env = std::getenv("BVHLAB_PYTHON"); env && *env) candidates.emplace_back(env);
  candidates.emplace_back("/usr/bin/python3");  // Debian's python3-matplotlib lives here
  candidates.emplace_back("python3");
  for (const auto& c : candidates)
    if (std::system((shell_quote(c) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) return c;
  return {};
}

}  // namespace

const std::vector<FigureSpec>& report_figures() {
  static const std::vector<FigureSpec> figures{
      {"fig1_time_vs_distance.png",
       "Mean time per query against distance, every hierarchy (exact strategies, and "
       "ADB at the operating p_min), with the work beside it: BV tests per query, same colours."},
      {"fig2_errors_vs_distance.png",
       "False-positive and false-negative rates of the inexact strategies against "
       "distance."},
      {"fig3_error_vs_time.png",
       "Error (false positives + false negatives) against mean time per query over each pair's summary band, "
       "one point per p_min (labelled p_min · BV tests per query; other points: their BV tests per query): "
       "the Pareto curve."},
      {"fig4_calibration.png",
       "Calibration, one panel per inexact series (in its figure 2 colour): the probability its answers "
       "report (decile means) against the observed collision frequency. Filled markers: deciles holding "
       "at least " +
           std::to_string(kCalibrationMinAnswers) + " answers, judged against the grey band of ±" +
           fmt("%g", kCalibrationTolerance) +
           "; hollow: fewer answers, not judged; numbers: answers per decile; the line breaks at an empty "
           "decile."},
      {"fig5_time_vs_size.png",
       "Mean time per query against model size (bytes per triangle, without polygons); numbers: BV tests per "
       "query."},
  };
  return figures;
}

std::vector<FrontPoint> error_time_front(const std::vector<SeriesSummary>& series, double max_error) {
  std::vector<FrontPoint> out;
  auto faster = [](const std::optional<SeriesSummary>& best, const SeriesSummary& s) {
    return !best || s.mean_time_us < best->mean_time_us;
  };
  for (const SeriesSummary& s : series) {
    auto it = std::find_if(out.begin(), out.end(), [&](const FrontPoint& f) { return f.mesh == s.mesh; });
    if (it == out.end()) it = out.insert(out.end(), FrontPoint{s.mesh, {}, {}, 0, {}, false});
    if (!(s.mean_time_us >= 0)) continue;
    if (s.exact_strategy) {
      if (faster(it->fastest_exact, s)) it->fastest_exact = s;
    } else if (s.fp_rate + s.fn_rate <= max_error + 1e-12 && faster(it->fastest_inexact, s)) {
      it->fastest_inexact = s;
    }
  }
  for (FrontPoint& f : out)
    if (f.fastest_exact && f.fastest_inexact && f.fastest_inexact->mean_time_us > 0) {
      f.interval = time_ratio(*f.fastest_exact, *f.fastest_inexact);
      f.speedup = f.interval.value;
      f.same_work = same_work(*f.fastest_exact, *f.fastest_inexact);
    }
  return out;
}

std::vector<OperatingPoint> operating_points(const RunOutput& run) {
  const ReportSpec& spec = run.scene.report;
  const auto series = summarize_band(run.rows);
  std::vector<OperatingPoint> out;
  std::vector<std::string> meshes;
  for (const auto& s : series)
    if (std::find(meshes.begin(), meshes.end(), s.mesh) == meshes.end()) meshes.push_back(s.mesh);
  for (const std::string& mesh : meshes) {
    const SeriesSummary *adb = nullptr, *base = nullptr;
    for (const auto& s : series) {
      if (s.mesh != mesh) continue;
      if (s.hierarchy == spec.operating_hierarchy && s.strategy == spec.operating_strategy &&
          s.p_min == spec.operating_p_min && s.budget.empty() && !adb)
        adb = &s;  // the first such series: the plain sweep, not a variant of it listed later
      if (s.hierarchy == spec.baseline_hierarchy && s.strategy == spec.baseline_strategy && !base) base = &s;
    }
    if (!adb || !base) continue;
    const Interval ratio = time_ratio(*base, *adb);
    out.push_back({mesh, *adb, *base, ratio.value, ratio, same_work(*base, *adb)});
  }
  return out;
}

namespace {

bool same_series(const CalibrationBin& b, const CalibrationSummary& s) {
  return b.mesh == s.mesh && b.hierarchy == s.hierarchy && b.strategy == s.strategy && b.p_min == s.p_min &&
         b.budget == s.budget && b.calibrated == s.calibrated;
}

/// The label results.csv gives the series, or one made of its parts when the rows do not have it; a
/// calibrated series is its raw series' label followed by " calibrated".
std::string calibration_label(const CalibrationBin& b, const std::vector<ResultRow>& rows) {
  const std::string suffix = b.calibrated ? " calibrated" : "";
  for (const ResultRow& r : rows)
    if (r.mesh == b.mesh && r.hierarchy == b.hierarchy && r.strategy == b.strategy && r.p_min == b.p_min &&
        r.budget == b.budget)
      return r.label + suffix;
  std::string label = b.strategy;
  if (b.p_min >= 0) label += " p_min=" + fmt("%g", b.p_min);
  if (!b.budget.empty()) label += " " + b.budget;
  return label + suffix;
}

/// Folds one bin into its series' summary.
void add_bin(CalibrationSummary& s, const CalibrationBin& b, std::size_t min_answers) {
  s.answers += b.count;
  if (b.count < min_answers || b.count == 0) return;
  if (!std::isfinite(b.mean_probability) || !std::isfinite(b.collision_frequency))
    throw std::invalid_argument("calibration bin " + fmt("%g", b.bin_low) + "-" + fmt("%g", b.bin_high) +
                                " of " + b.mesh + " " + b.hierarchy + " " + s.label + " holds " +
                                std::to_string(b.count) + " answers but no finite probability or frequency");
  const double gap = std::abs(b.mean_probability - b.collision_frequency);
  if (b.bin_low >= 0.1 - 1e-12) ++s.qualifying_above_tenth;
  if (s.qualifying_bins++ == 0 || gap > s.max_gap) {
    s.max_gap = gap;
    s.worst_reported = b.mean_probability;
    s.worst_observed = b.collision_frequency;
    s.worst_low = b.bin_low;
    s.worst_high = b.bin_high;
  }
}

}  // namespace

std::vector<CalibrationSummary> calibration_summary(const std::vector<CalibrationBin>& bins,
                                                    const std::vector<ResultRow>& rows,
                                                    std::size_t min_answers, double tolerance) {
  std::vector<CalibrationSummary> out;
  for (const CalibrationBin& b : bins) {
    auto it =
        std::find_if(out.begin(), out.end(), [&](const CalibrationSummary& s) { return same_series(b, s); });
    if (it == out.end()) {
      CalibrationSummary s;
      s.mesh = b.mesh;
      s.hierarchy = b.hierarchy;
      s.strategy = b.strategy;
      s.budget = b.budget;
      s.p_min = b.p_min;
      s.calibrated = b.calibrated;
      s.label = calibration_label(b, rows);
      s.max_gap = std::numeric_limits<double>::quiet_NaN();
      it = out.insert(out.end(), s);
    }
    add_bin(*it, b, min_answers);
  }
  for (CalibrationSummary& s : out) {
    s.judgeable = s.qualifying_bins >= kCalibrationMinDeciles && s.qualifying_above_tenth > 0;
    s.meets = s.judgeable && s.max_gap <= tolerance;
  }
  return out;
}

std::string distance_label(const Scene& scene) {
  if (scene.workload.axis == WorkloadSpec::Axis::Group) return "pose group (the pose file's \"group\")";
  if (scene.workload.axis == WorkloadSpec::Axis::Separation)
    return "separation: centre distance / (r_A + r_B), bins of " + fmt("%g", kSeparationBin) + " (" +
           fmt("%g", kSeparationOpenFrom + kSeparationBin / 2) + ": " + fmt("%g", kSeparationOpenFrom) +
           " and beyond)";
  return normalised_units(scene) ? "distance d of B's centre (each model normalised: longest side 2)"
                                 : "distance d of B's centre (scene units)";
}

std::string run_plot_script(const ReportOptions& options, const std::string& script_name,
                            const std::filesystem::path& dir, const std::string& arguments) {
  std::filesystem::path script = options.plot_script;
#ifdef BVHLAB_SOURCE_DIR
  if (script.empty()) script = std::filesystem::path(BVHLAB_SOURCE_DIR) / "bench" / script_name;
#endif
  const std::string python = options.python.empty() ? find_python() : options.python.string();
  if (python.empty())
    return "no Python with matplotlib found (install python3-matplotlib, or set BVHLAB_PYTHON)";
  if (!std::filesystem::is_regular_file(script)) return "plot script " + script.string() + " not found";
  const std::string command =
      shell_quote(python) + " " + shell_quote(script.string()) + " " + shell_quote(dir.string()) + arguments;
  const std::filesystem::path log = dir / "plot.log";
  const int status = std::system((command + " > " + shell_quote(log.string()) + " 2>&1").c_str());
  if (status == 0) {
    std::filesystem::remove(log);
    return {};
  }
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  return script.filename().string() + " failed (exit status " + std::to_string(status) + "): " + text.str();
}

namespace {

/// plot_report.py's arguments beyond the folder: the distance axis, each pair's band, the operating point.
std::string report_plot_arguments(const RunOutput& run) {
  const ReportSpec& r = run.scene.report;
  // results.csv marks each row inside its pair's band; the bands' words title figure 3.
  std::string arguments = " --quality-text " + shell_quote("each pair's summary band") +
                          " --distance-label " + shell_quote(distance_label(run.scene));
  for (const SummaryBand& band : summary_bands(run))
    arguments += " --band " + shell_quote(band.mesh + "=" + band.text);
  if (!r.operating_hierarchy.empty())
    arguments += " --operating-strategy " + shell_quote(r.operating_strategy) + " --operating-hierarchy " +
                 shell_quote(r.operating_hierarchy) + " --operating-p-min " + fmt("%.17g", r.operating_p_min);
  return arguments;
}

}  // namespace

ReportFolder report_folder(const RunOutput& run) {
  ReportFolder folder;
  for (const auto& f : report_figures()) folder.figures.push_back(f.file);
  folder.plot_script = "plot_report.py";
  folder.plot_arguments = report_plot_arguments(run);
  folder.write_data = [&](const std::filesystem::path& d) {
    write_results_csv(run, d / "results.csv");
    write_results_json(run, d / "results.json");
    write_calibration_csv(run, d / "calibration.csv");
    if (run.per_pose != PerPose::none) write_poses_csv(run, d / "poses.csv");
  };
  folder.readme = [&](const std::vector<std::string>&, const std::string& plot_error) {
    return report_readme(run, plot_error.empty(), plot_error);
  };
  return folder;
}

ReportFiles write_report(const RunOutput& run, const std::filesystem::path& dir,
                         const ReportOptions& options) {
  const ReportFolderFiles written = write_report_folder(dir, report_folder(run), options);
  ReportFiles files;
  files.dir = written.dir;
  files.results_csv = files.dir / "results.csv";
  files.results_json = files.dir / "results.json";
  files.calibration_csv = files.dir / "calibration.csv";
  files.readme = written.readme;
  files.figures = written.figures;
  files.plot_error = written.plot_error;
  return files;
}

}  // namespace bvhlab
