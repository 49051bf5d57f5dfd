// The report folder's README.md, section by section, and the short results section for the project
// README (report_snippet). The numbers come from report.cpp's summaries.
#include "bench/pairs/report.hpp"

#include "bench/pairs/report_internal.hpp"
#include "bench/pairs/summary_band.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using namespace report_detail;

/// Text for a Markdown table cell: a pair label such as "a|b" must not split the cell.
std::string table_cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string percent(double rate) {
  return fmt("%.2f", 100 * rate);
}
std::string micros(double us) {
  return us >= 100 ? fmt("%.0f", us) : us >= 10 ? fmt("%.1f", us) : fmt("%.2f", us);
}
std::string count(double v) {
  return std::isfinite(v) ? fmt(v >= 100 ? "%.0f" : "%.1f", v) : "n/a";
}
std::string p_min_text(double p) {
  return p < 0 ? "" : fmt("%g", p);
}

std::string series_name(const SeriesSummary& s) {
  return s.label;
}

/// Every distance a row has, in order.
std::vector<double> row_distances(const RunOutput& run) {
  std::vector<double> distances;
  for (const auto& r : run.rows)
    if (std::find(distances.begin(), distances.end(), r.distance) == distances.end())
      distances.push_back(r.distance);
  std::sort(distances.begin(), distances.end());
  return distances;
}

/// How an object enters the run: its file, its units, its scale and placement.
std::string object_text(const SceneObject& o) {
  std::string text = "`" + o.name + "` (" + std::filesystem::path(o.mesh).filename().string() + ", " +
                     (o.normalize ? "normalised: centred, longest side 2" : "in its file's units");
  if (o.scale != 1) text += ", scaled by " + fmt("%g", o.scale);
  const RigidTransform& p = o.placement;
  if (!p.translation.isZero() || !p.rotation.isIdentity()) text += ", placed by the scene";
  return text + ")";
}

/// "`jeep` (jeep1.ms3d, normalised: ...) against a copy of itself; `env` (...) against `rob` (...)".
std::string pairs_text(const Scene& scene) {
  std::string text;
  for (const ScenePair& p : scene.pairs) {
    const SceneObject* a = scene.object(p.a);
    const SceneObject* b = scene.object(p.b);
    if (!a || !b) continue;
    text += (text.empty() ? "" : "; ") + object_text(*a) + " against " +
            (p.a == p.b ? std::string("a copy of itself") : object_text(*b));
  }
  return text;
}

/// The workload paragraph: the pairs as the scene gives them, the poses, and the units of the distances.
std::string workload_text(const Scene& scene) {
  const WorkloadSpec& w = scene.workload;
  std::ostringstream md;
  if (w.kind == WorkloadSpec::Kind::Protocol) {
    md << "Workload: the tumbling protocol (adb/README.md, section 4) on " << pairs_text(scene)
       << ". A stays put; B at (d, 0, 0) turns a full R_z(θ)R_x(θ) in " << w.steps
       << " steps per distance d ∈ {";
    for (std::size_t i = 0; i < w.distances.size(); ++i) md << (i ? ", " : "") << fmt("%g", w.distances[i]);
    md << "}. "
       << (normalised_units(scene) ? "Distances are in the normalised model's units (its longest side is 2)."
                                   : "Distances are in the scene's units (each object as listed above).")
       << "\n\n";
  } else if (w.kind == WorkloadSpec::Kind::Random) {
    md << "Workload: " << w.count << " random poses (seed " << w.seed << ") on " << pairs_text(scene)
       << ": B's translation uniform in the box [" << fmt("%g", w.box_min.x()) << ", "
       << fmt("%g", w.box_max.x()) << "] x [" << fmt("%g", w.box_min.y()) << ", " << fmt("%g", w.box_max.y())
       << "] x [" << fmt("%g", w.box_min.z()) << ", " << fmt("%g", w.box_max.z())
       << "] of A's frame, its rotation uniform. They form one group, filed under distance 0.\n\n";
  } else {
    md << "Workload: " << w.groups.size() << " pose groups from `" << w.pose_file.filename().string()
       << "` on " << pairs_text(scene)
       << ". The distance column is the pose file's group (by default the length of the translation).\n\n";
  }
  return md.str();
}

/// How the times were taken, and how much the machine disturbed them.
void readme_timing(std::ostream& md, const RunStats& stats) {
  md << "Times: each (series, pose) is the " << stats.timing_statistic << " of " << stats.timing_repeats
     << " warm pass" << (stats.timing_repeats == 1 ? "" : "es")
     << " over the poses (every series runs each block of 50 poses in turn, so drift and stalls hit all "
        "alike), timed with a steady clock less its own cost ("
     << fmt("%.3f", stats.clock_overhead_us)
     << " µs); a series' mean, median and p99 are over those per-pose times, on the same poses for every "
        "series, in one process. Speed-ups carry a 95% interval (bootstrap over the poses).\n\n";
  if (stats.timing_repeats < 2) {
    md << "Disturbance: not measured (one pass gives no second sample of a pose).\n\n";
    return;
  }
  const double share = stats.sampled_seconds > 0 ? stats.stall_lost_seconds / stats.sampled_seconds : 0;
  md << "Disturbance: " << stats.stalled_samples << " of " << stats.timed_samples
     << " samples were stalls (over " << fmt("%g", kStallFactor) << "× their pose's median + "
     << fmt("%g", kStallMarginUs) << " µs), losing " << fmt("%.2f", 100 * share) << "% of the timed time; "
     << stats.involuntary_switches << " forced context switches. "
     << (share >= kDisturbedShare
             ? "**This run was disturbed** (at least " + fmt("%g", 100 * kDisturbedShare) +
                   "% lost): the per-pose " + stats.timing_statistic +
                   " discards most stalls, but compare its ratios with care.\n\n"
             : "Undisturbed (under " + fmt("%g", 100 * kDisturbedShare) + "% lost).\n\n");
}

/// Title, where and how the run was made, the workload, and what was skipped.
void readme_header(std::ostream& md, const RunOutput& run) {
  const Scene& scene = run.scene;
  const Environment& env = run.environment;
  const RunStats& stats = run.stats;
  md << "# bvhlab report: " << scene.name << "\n\n";
  md << "Scene `" << (scene.file.empty() ? std::string("<memory>") : scene.file.filename().string())
     << "`, run " << env.timestamp << " on " << env.machine << "; " << env.compiler << ", " << env.build_type
     << " build, commit `" << env.git_commit << "`.\n\n";
  md << workload_text(scene);
  if (scene.density.name != NoDensity::name())
    md << "Density annotation of the trees that need one: `" << scene.density.label()
       << "` (parameters in `bvhlab policies`; the ADB method in adb/README.md).\n\n";
  for (const HierarchySpec& h : scene.hierarchies)
    if (h.density) md << "Hierarchy `" << h.name << "` carries its own: `" << h.density->label() << "`.\n\n";
  readme_timing(md, stats);
  for (const auto& why : stats.skipped) md << "> **Skipped:** " << why << "\n\n";
  for (const auto& advice : run.advice) md << "> **The right tool:** " << advice << "\n\n";
}

/// "`hierarchy` label: 1.23 µs mean (median 1.1, p99 2.4), 12.3 BV tests, 4.0 triangle tests, 3.1 estimates".
std::string series_text(const SeriesSummary& s) {
  std::string text = "`" + s.hierarchy + "` " + s.label + ": " + micros(s.mean_time_us) +
                     " µs mean (median " + micros(s.median_time_us) + ", p99 " + micros(s.p99_time_us) + ")";
  if (!std::isfinite(s.bv_tests_per_query)) return text + ", no work counters";
  return text + ", " + count(s.bv_tests_per_query) + " BV tests, " + count(s.triangle_tests_per_query) +
         " triangle tests, " + count(s.estimates_per_query) + " estimates per query";
}

/// Why a band cannot compare strategies, or "" when it can.
std::string uninformative(const SummaryBand* band) {
  if (!band) return "it has no ground truth";
  if (band->poses == 0) return "its band holds no pose";
  if (band->colliding == 0)
    return "no pose of its band collides, so every strategy answers the same trivial 'no'";
  if (band->colliding == band->poses)
    return "every pose of its band collides, so there is nothing to tell apart";
  return "";
}

/// The operating point, stated plainly: both series with their work, and a verdict the interval carries.
void readme_operating_point(std::ostream& md, const RunOutput& run, const std::vector<SummaryBand>& bands) {
  const Scene& scene = run.scene;
  md << "## Result at the operating point\n\n";
  const auto points = operating_points(run);
  if (points.empty()) {
    md << "No operating point: the scene has no `"
       << (scene.report.operating_strategy.empty() ? std::string("adb") : scene.report.operating_strategy)
       << "` strategy at p_min = " << p_min_text(scene.report.operating_p_min) << " on `"
       << scene.report.operating_hierarchy << "`, or no baseline `" << scene.report.baseline_strategy
       << "` on `" << scene.report.baseline_hierarchy << "`.\n\n";
  }
  for (const auto& p : points) {
    const SummaryBand* band = band_of(bands, p.mesh);
    md << "- **" << p.mesh << "** (" << (band ? band->text : std::string("no band")) << ", " << p.adb.queries
       << " queries): ";
    if (const std::string why = uninformative(band); !why.empty()) {
      md << "no comparison: " << why << ".\n";
      continue;
    }
    md << series_text(p.adb) << ", against " << series_text(p.baseline) << ": "
       << speedup_text(p.interval, p.same_work) << ", with " << percent(p.adb.fp_rate)
       << "% false positives and " << percent(p.adb.fn_rate) << "% false negatives ("
       << percent(p.adb.fp_rate + p.adb.fn_rate) << "% wrong answers).\n";
  }
  if (!points.empty())
    md << "\nFor comparison, the paper reports a speed-up of about 3 to 6 over an exact DOP-tree at about 4% "
          "errors (ADB on AABBs, 8 cells per node, Pentium-IV). Compare ratios within one run.\n";
  md << "\n";
}

void readme_figures(std::ostream& md, bool figures_ok, const std::string& plot_error) {
  md << "## Figures\n\n";
  if (!figures_ok) md << "> The figures could not be drawn: " << plot_error << "\n\n";
  for (const auto& f : report_figures())
    md << "![" << f.caption << "](" << f.file << ")\n\n*" << f.caption << "*\n\n";
}

/// Whether figure 3's p_min curves follow their work, step by step, over each pair's band (`band_series`).
void readme_curves(std::ostream& md, const std::vector<SeriesSummary>& band_series) {
  const std::vector<CurveStep> steps = pmin_curve_steps(band_series);
  if (steps.empty()) return;
  std::set<std::string> curves;
  std::size_t same = 0;
  std::vector<const CurveStep*> against;
  for (const CurveStep& s : steps) {
    curves.insert(s.mesh + '\x1f' + s.hierarchy + '\x1f' + s.curve);
    same += s.same_work;
    if (s.against_work) against.push_back(&s);
  }
  md << "**Figure 3's p_min curves against their work** (over each pair's band): " << steps.size()
     << (steps.size() == 1 ? " step" : " steps") << " between neighbouring p_min on " << curves.size()
     << (curves.size() == 1 ? " curve; " : " curves; ") << same
     << " of them same work. A step goes against its work when the BV tests per query change by more than "
        "1% and the time's 95% interval lies wholly on the other side of 1: ";
  if (against.empty()) {
    md << "none does.\n\n";
    return;
  }
  md << against.size() << (against.size() == 1 ? " does:\n\n" : " do:\n\n");
  for (const CurveStep* s : against)
    md << "- " << table_cell(s->mesh) << ", " << s->hierarchy << " " << s->curve << ": p_min "
       << p_min_text(s->p_min) << " → " << p_min_text(s->next_p_min) << ", BV tests " << count(s->bv_tests)
       << " → " << count(s->next_bv_tests) << ", time ×" << fmt("%.3f", s->time_ratio.value)
       << " (95% interval " << fmt("%.3f", s->time_ratio.lo) << "–" << fmt("%.3f", s->time_ratio.hi) << ")\n";
  md << "\n";
}

/// Each pair's summary band, one line each.
void readme_bands(std::ostream& md, const std::vector<SummaryBand>& bands) {
  for (const SummaryBand& b : bands) {
    md << "- " << table_cell(b.mesh) << ": " << b.text << "; " << b.poses << " poses, " << b.colliding
       << " colliding";
    if (const std::string why = uninformative(&b); !why.empty()) md << ". No speed-up is given: " << why;
    md << ".\n";
  }
  md << "\n";
}

/// The summary table over each pair's band (`band_series`): times beside the work.
void readme_summary(std::ostream& md, const RunOutput& run, const std::vector<SummaryBand>& bands,
                    const std::vector<SeriesSummary>& band_series) {
  md << "## Summary over each pair's band\n\n";
  readme_bands(md, bands);
  md << "| mesh | hierarchy | strategy | mean µs | median µs | p99 µs | max µs | FP % | FN % | BV "
        "tests/query | "
        "triangle tests/query | estimates/query | bytes/triangle |\n"
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const auto& s : band_series)
    md << "| " << table_cell(s.mesh) << " | " << s.hierarchy << " | " << series_name(s) << " | "
       << micros(s.mean_time_us) << " | " << micros(s.median_time_us) << " | " << micros(s.p99_time_us)
       << " | " << micros(s.max_time_us) << " | " << percent(s.fp_rate) << " | " << percent(s.fn_rate)
       << " | " << count(s.bv_tests_per_query) << " | " << count(s.triangle_tests_per_query) << " | "
       << count(s.estimates_per_query) << " | " << fmt("%.1f", s.bytes_per_triangle) << " |\n";
  md << "\nEach time is a per-pose " << run.stats.timing_statistic << " of " << run.stats.timing_repeats
     << " warm passes; the maximum is the slowest pose's. FCL exposes no work counters (n/a).\n\n";
}

/// The fastest inexact series within 4% wrong answers against the fastest exact one, per mesh pair.
void readme_front(std::ostream& md, const std::vector<SummaryBand>& bands,
                  const std::vector<SeriesSummary>& band_series) {
  const auto front = error_time_front(band_series, kFrontMaxError);
  if (std::none_of(front.begin(), front.end(),
                   [](const FrontPoint& f) { return f.fastest_exact.has_value(); }))
    return;
  const std::string bound = percent(kFrontMaxError) + "%";
  md << "## Against the fastest exact hierarchy\n\nOver each pair's band (above): the fastest exact series, "
        "and the fastest inexact one with at most "
     << bound
     << " wrong answers (FP + FN), each with its work per query (BV tests / triangle tests / "
        "estimates).\n\n"
     << "| mesh | fastest exact | µs | work | fastest inexact within " << bound
     << " | µs | work | FP % | FN % | speed-up |\n|---|---|---:|---|---|---:|---|---:|---:|---|\n";
  auto work = [](const SeriesSummary& s) {
    return count(s.bv_tests_per_query) + " / " + count(s.triangle_tests_per_query) + " / " +
           count(s.estimates_per_query);
  };
  for (const FrontPoint& f : front) {
    if (!f.fastest_exact) continue;
    md << "| " << table_cell(f.mesh) << " | " << f.fastest_exact->hierarchy << " " << f.fastest_exact->label
       << " | " << micros(f.fastest_exact->mean_time_us) << " | " << work(*f.fastest_exact) << " | ";
    if (!f.fastest_inexact) {
      md << "none | | | | | |\n";
      continue;
    }
    const std::string why = uninformative(band_of(bands, f.mesh));
    md << f.fastest_inexact->hierarchy << " " << f.fastest_inexact->label << " | "
       << micros(f.fastest_inexact->mean_time_us) << " | " << work(*f.fastest_inexact) << " | "
       << percent(f.fastest_inexact->fp_rate) << " | " << percent(f.fastest_inexact->fn_rate) << " | "
       << (why.empty() ? speedup_text(f.interval, f.same_work, false) : "none: " + why) << " |\n";
  }
  md << "\n";
}

/// Per series, how far the reported probability is from the observed collision frequency.
void readme_calibration(std::ostream& md, const RunOutput& run) {
  const auto summaries = calibration_summary(run.calibration, run.rows);
  if (summaries.empty()) return;
  const std::string tolerance = fmt("%g", kCalibrationTolerance);
  md << "## Calibration\n\nOver all distances, the answers of each inexact series binned by the "
        "probability "
        "they report (deciles, as in `calibration.csv` and figure 4). The target: in every decile holding "
        "at "
        "least "
     << kCalibrationMinAnswers << " answers, the mean reported probability within " << tolerance
     << " of the observed collision frequency. A verdict needs at least " << kCalibrationMinDeciles
     << " such deciles, one of them above 0.1; otherwise there is too little spread to judge.\n\n"
        "| mesh | hierarchy | strategy | answers | deciles with ≥ "
     << kCalibrationMinAnswers << " answers | largest gap | worst decile: reported → observed | within "
     << tolerance << " |\n|---|---|---|---:|---:|---:|---|---|\n";
  std::vector<std::string> meeting;
  for (const auto& s : summaries) {
    md << "| " << table_cell(s.mesh) << " | " << s.hierarchy << " | " << s.label << " | " << s.answers
       << " | " << s.qualifying_bins << " | ";
    if (s.qualifying_bins == 0) {
      md << "n/a | | too little spread to judge |\n";
      continue;
    }
    md << fmt("%.3f", s.max_gap) << " | " << fmt("%.1f", s.worst_low) << "–" << fmt("%.1f", s.worst_high)
       << ": " << fmt("%.3f", s.worst_reported) << " → " << fmt("%.3f", s.worst_observed) << " | "
       << (!s.judgeable ? "too little spread to judge"
           : s.meets    ? "yes"
                        : "no")
       << " |\n";
    if (s.meets) meeting.push_back(s.mesh + " " + s.hierarchy + " " + s.label);
  }
  md << "\n";
  if (const auto& c = run.scene.calibration) {
    md << "A series marked *calibrated* is its raw series' answers with each probability passed through a "
          "monotone map fitted on held-out training poses ("
       << c->training_steps
       << (run.scene.workload.kind == WorkloadSpec::Kind::Random ? " in all" : " per distance") << ", seed "
       << c->training_seed
       << ", scene field `calibration`): its decisions, times and errors are the raw series'.\n\n";
  }
  if (meeting.empty()) {
    md << "No series meets the target.\n\n";
    return;
  }
  md << "Meeting the target: ";
  for (std::size_t i = 0; i < meeting.size(); ++i) md << (i ? "; " : "") << meeting[i];
  md << ".\n\n";
}

/// Which series a per-distance table lists.
enum class Listed { all, inexact, distances, anytime_distances };

/// Whether a row measures a distance (ResultRow::distance_error is set).
bool measures_distance(const ResultRow& r) {
  return !std::isnan(r.distance_error);
}

/// One table of a value per series (rows) and distance (columns).
void per_distance_table(std::ostream& md, const RunOutput& run, const std::vector<double>& distances,
                        const std::string& title, Listed listed,
                        const std::function<std::string(const ResultRow&)>& cell) {
  md << "## " << title << "\n\n| mesh | hierarchy | strategy |";
  for (double d : distances) md << " d=" << fmt("%g", d) << " |";
  md << "\n|---|---|---|";
  for (std::size_t i = 0; i < distances.size(); ++i) md << "---:|";
  md << "\n";
  for (const auto& s : summarize(run.rows, -1e300, 1e300)) {
    if (listed == Listed::inexact && s.exact_strategy) continue;
    std::vector<const ResultRow*> rows(distances.size(), nullptr);
    for (const auto& r : run.rows)
      for (std::size_t i = 0; i < distances.size(); ++i)
        if (r.distance == distances[i] && r.mesh == s.mesh && r.hierarchy == s.hierarchy &&
            r.strategy == s.strategy && r.p_min == s.p_min && r.budget == s.budget && r.label == s.label)
          rows[i] = &r;
    const bool distance =
        std::any_of(rows.begin(), rows.end(), [](auto* r) { return r && measures_distance(*r); });
    if ((listed == Listed::distances || listed == Listed::anytime_distances) && !distance) continue;
    if (listed == Listed::anytime_distances && s.exact_strategy) continue;
    md << "| " << table_cell(s.mesh) << " | " << s.hierarchy << " | " << series_name(s) << " |";
    for (const ResultRow* row : rows) md << " " << (row ? cell(*row) : std::string("")) << " |";
    md << "\n";
  }
  md << "\n";
}

/// A relative error or width: "0", or two significant digits.
std::string relative(double v) {
  return std::isnan(v) ? "" : v == 0 ? "0" : fmt("%.2g", v);
}

/// The distance series against their reference (ResultRow::distance_error), when the scene runs any.
void readme_distances(std::ostream& md, const RunOutput& run, const std::vector<double>& distances) {
  if (std::none_of(run.rows.begin(), run.rows.end(), measures_distance)) return;
  std::size_t misses = 0;
  for (const ResultRow& r : run.rows) misses += r.interval_misses;
  per_distance_table(
      md, run, distances, "Distances: median time (µs) and largest relative error", Listed::distances,
      [](const ResultRow& r) { return micros(r.median_time_us) + " (" + relative(r.distance_error) + ")"; });
  md << "Each pose's reference is the first exact distance series (bvhlab's before FCL's); the error is "
        "|distance - reference| / reference, the largest over the poses (absolute where the objects touch). "
     << (misses == 0 ? std::string("Every interval [lower bound, distance] held its reference.")
                     : "**" + std::to_string(misses) + " intervals missed their reference.**")
     << "\n\n";
  if (std::any_of(run.rows.begin(), run.rows.end(),
                  [](const ResultRow& r) { return measures_distance(r) && !r.exact_strategy; }))
    per_distance_table(md, run, distances,
                       "Anytime distance: median interval width / distance, and poses within a tenth (%)",
                       Listed::anytime_distances, [](const ResultRow& r) {
                         if (std::isnan(r.width_median))
                           return std::string();  // every pose in contact: no width
                         return relative(r.width_median) + " (" + percent(r.width_tenth_rate) + ")";
                       });
}

void readme_per_distance(std::ostream& md, const RunOutput& run, const std::vector<double>& distances) {
  per_distance_table(
      md, run, distances, "Mean time per query (µs) and BV tests per query by distance", Listed::all,
      [](const ResultRow& r) { return micros(r.mean_time_us) + " (" + count(r.bv_tests_per_query) + ")"; });
  if (std::any_of(run.rows.begin(), run.rows.end(), [](const ResultRow& r) { return !r.exact_strategy; }))
    per_distance_table(md, run, distances, "False positives / false negatives (%) by distance",
                       Listed::inexact,
                       [](const ResultRow& r) { return percent(r.fp_rate) + " / " + percent(r.fn_rate); });
}

void readme_models(std::ostream& md, const RunOutput& run) {
  md << "## Models\n\n| object | hierarchy | BV | annotation | triangles | nodes | depth | bytes/triangle "
        "| "
        "build s | "
        "annotate s | from cache |\n|---|---|---|---|---:|---:|---:|---:|---:|---:|---|\n";
  for (const auto& m : run.models)
    md << "| " << table_cell(m.object) << " | " << m.hierarchy << " | " << m.bv << " | " << m.annotation
       << " | " << m.triangles << " | " << m.nodes << " | "
       << (m.depth ? std::to_string(m.depth) : std::string("")) << " | " << fmt("%.1f", m.bytes_per_triangle)
       << " | " << fmt("%.3f", m.build_seconds) << " | "
       << (m.annotate_seconds > 0 ? fmt("%.2f", m.annotate_seconds) : std::string("")) << " | "
       << (m.from_cache ? "yes" : "no") << " |\n";
  md << "\nBytes per triangle count nodes and volumes (and one byte of pc per node when annotated), not "
        "polygons. "
        "Build and annotation times are those measured when the tree was made (cached trees keep "
        "theirs).\n\n";
}

void readme_ground_truth(std::ostream& md, const RunOutput& run, const std::vector<double>& distances) {
  const RunStats& stats = run.stats;
  md << "## Ground truth\n\nExact first-contact traversal, computed once per (mesh, pose set) and cached; "
     << stats.cgal_checked
     << " poses cross-checked against CGAL (exact predicates): " << stats.cgal_mismatches << " disagreement"
     << (stats.cgal_mismatches == 1 ? "" : "s") << ".\n\n| mesh |";
  for (double d : distances) md << " d=" << fmt("%g", d) << " |";
  md << "\n|---|";
  for (std::size_t i = 0; i < distances.size(); ++i) md << "---:|";
  md << "\n";
  std::vector<std::string> meshes;
  for (const auto& t : run.truth)
    if (std::find(meshes.begin(), meshes.end(), t.mesh) == meshes.end()) meshes.push_back(t.mesh);
  for (const auto& mesh : meshes) {
    md << "| " << table_cell(mesh) << " (colliding %) |";
    for (double d : distances) {
      std::string cell;
      for (const auto& t : run.truth)
        if (t.mesh == mesh && t.distance == d && t.poses)
          cell = fmt("%.1f", 100.0 * double(t.colliding) / double(t.poses));
      md << " " << cell << " |";
    }
    md << "\n";
  }
}

void readme_run(std::ostream& md, const RunStats& stats) {
  md << "\n## Run\n\n"
     << stats.queries << " timed queries (" << fmt("%.1f", stats.query_seconds)
     << " s inside queries), preprocessing " << fmt("%.1f", stats.preprocess_seconds) << " s, ground truth "
     << fmt("%.1f", stats.truth_seconds) << " s, wall " << fmt("%.1f", stats.wall_seconds)
     << " s. Trees built: " << stats.trees_built << ", annotated: " << stats.trees_annotated
     << ", loaded from the cache: " << stats.tree_cache_hits
     << " (rejected as stale or corrupt: " << stats.tree_cache_rejected
     << "); FCL models built: " << stats.fcl_models_built
     << ".\n\nFiles: `results.csv` (one row per mesh, "
        "hierarchy, strategy, p_min, budget and distance), `results.json` (the same plus models, ground "
        "truth and "
        "run statistics), `calibration.csv`.\n";
}

}  // namespace

std::string report_readme(const RunOutput& run, bool figures_ok, const std::string& plot_error) {
  const std::vector<SummaryBand> bands = summary_bands(run);
  const std::vector<double> distances = row_distances(run);
  const std::vector<SeriesSummary> band_series = summarize_band(run.rows);  // read by three sections
  std::ostringstream md;
  readme_header(md, run);
  readme_operating_point(md, run, bands);
  readme_figures(md, figures_ok, plot_error);
  readme_curves(md, band_series);
  readme_summary(md, run, bands, band_series);
  readme_front(md, bands, band_series);

  readme_calibration(md, run);
  readme_per_distance(md, run, distances);
  readme_distances(md, run, distances);
  readme_models(md, run);
  readme_ground_truth(md, run, distances);
  readme_run(md, run.stats);
  return md.str();
}

std::string report_snippet(const RunOutput& run, const std::filesystem::path& report_dir) {
  std::ostringstream md;
  const std::vector<SummaryBand> bands = summary_bands(run);
  md << "## Results\n\nScene `" << run.scene.file.filename().string() << "` (" << run.stats.queries
     << " timed queries; `make demo` runs `bench/scenes/demo.json`) writes a report folder (`"
     << report_dir.filename().string() << "/README.md`, `results.csv`, five figures). On "
     << run.environment.machine << " (" << run.environment.build_type << ", commit `"
     << run.environment.git_commit << "`), over each pair's summary band:\n\n";
  for (const auto& p : operating_points(run)) {
    const SummaryBand* band = band_of(bands, p.mesh);
    md << "- **" << p.mesh << "** (" << (band ? band->text : std::string("no band")) << "): ADB on "
       << p.adb.hierarchy << " (p_min = " << fmt("%g", p.adb.p_min) << ") " << micros(p.adb.mean_time_us)
       << " µs per query vs " << micros(p.baseline.mean_time_us) << " µs for " << p.baseline.strategy << " "
       << p.baseline.hierarchy << ": ";
    if (const std::string why = uninformative(band); !why.empty())
      md << "no comparison (" << why << ").\n";
    else
      md << speedup_text(p.interval, p.same_work, false) << ", " << percent(p.adb.fp_rate)
         << "% false positives, " << percent(p.adb.fn_rate) << "% false negatives.\n";
  }
  md << "\nFigures: ";
  for (std::size_t i = 0; i < report_figures().size(); ++i)
    md << (i ? ", " : "") << "`" << report_figures()[i].file << "`";
  md << ". The report's README has the full tables (time per distance, FP/FN per distance, models, ground "
        "truth "
        "cross-checked against CGAL: "
     << run.stats.cgal_checked << " poses, " << run.stats.cgal_mismatches << " disagreements).\n";
  return md.str();
}

}  // namespace bvhlab
