// The files of a world run: one CSV row per frame and series, one per frame and broad phase, and a README
// that sums them up.
#include "bench/world/world.hpp"

#include "bench/pairs/report.hpp"
#include "bench/report_folder.hpp"
#include "bench/report_tables.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

namespace bvhlab {

namespace {

using report_tables::open_csv;
using report_tables::percent;
using report_tables::quantile;

/// One summary line per (hierarchy, series), in first-seen order.
struct SeriesTotals {
  std::string hierarchy, series;
  std::size_t candidates = 0, colliding = 0, missed = 0, false_pairs = 0, flagged = 0;
  std::vector<double> micros;
};

std::vector<SeriesTotals> totals(const std::vector<WorldSeriesRow>& rows) {
  std::vector<SeriesTotals> out;
  std::map<std::pair<std::string, std::string>, std::size_t> index;
  for (const WorldSeriesRow& r : rows) {
    auto [it, fresh] = index.try_emplace({r.hierarchy, r.series}, out.size());
    if (fresh) out.push_back({r.hierarchy, r.series, 0, 0, 0, 0, 0, {}});
    SeriesTotals& t = out[it->second];
    t.candidates += r.candidates;
    t.colliding += r.colliding;
    t.missed += r.missed;
    t.false_pairs += r.false_pairs;
    t.flagged += r.flagged;
    t.micros.push_back(r.micros);
  }
  return out;
}

/// world_pairs.csv: one row per kept pair answer (WorldPairRow); micros empty under a frame budget.
void write_world_pairs_csv(const WorldOutput& output, const std::filesystem::path& file) {
  std::ofstream pairs = open_csv(file);
  pairs << "frame,hierarchy,series,a,b,truth,collides,flagged,probability,micros,bv_tests\n";
  for (const WorldPairRow& r : output.pairs)
    pairs << fmt::format("{},{},\"{}\",\"{}\",\"{}\",{},{},{},{:.6g},{},{}\n", r.frame, r.hierarchy, r.series,
                         r.a, r.b, r.truth ? 1 : 0, r.collides ? 1 : 0, r.flagged ? 1 : 0, r.probability,
                         r.micros < 0 ? std::string() : fmt::format("{:.3f}", r.micros), r.bv_tests);
  if (!pairs) throw std::runtime_error(file.string() + ": writing failed");
}

}  // namespace

void write_world_csv(const WorldOutput& output, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream frames = open_csv(dir / "world_frames.csv");
  frames << "frame,hierarchy,series,schedule,budget,exact_strategy,candidates,colliding,answered,missed,"
            "false_pairs,flagged,untested,untested_colliding,micros,bv_tests\n";
  for (const WorldSeriesRow& r : output.series)
    frames << fmt::format("{},{},\"{}\",{},{},{},{},{},{},{},{},{},{},{},{:.3f},{}\n", r.frame, r.hierarchy,
                          r.series, r.schedule, r.budget, r.exact_strategy ? 1 : 0, r.candidates, r.colliding,
                          r.answered, r.missed, r.false_pairs, r.flagged, r.untested, r.untested_colliding,
                          r.micros, r.bv_tests);
  std::ofstream broad = open_csv(dir / "world_broad_phase.csv");
  broad << "frame,hierarchy,broad_phase,objects,candidates,boxes_micros,update_micros\n";
  for (const BroadPhaseRow& r : output.broad)
    broad << fmt::format("{},{},{},{},{},{:.3f},{:.3f}\n", r.frame, r.hierarchy, r.broad_phase, r.objects,
                         r.candidates, r.boxes_micros, r.update_micros);
  std::ofstream scaling = open_csv(dir / "world_scaling.csv");
  scaling << "hierarchy,broad_phase,objects,candidates,boxes_micros,update_micros\n";
  for (const ScalingRow& r : output.scaling)
    scaling << fmt::format("{},{},{},{},{:.3f},{:.3f}\n", r.hierarchy, r.broad_phase, r.objects, r.candidates,
                           r.boxes_micros, r.update_micros);
  if (!frames || !broad || !scaling)
    throw std::runtime_error(dir.string() + ": writing the world CSV files failed");
  if (output.per_pose != PerPose::none) write_world_pairs_csv(output, dir / "world_pairs.csv");
}

namespace {

void series_table(std::ostream& md, const WorldOutput& output) {
  md << "Missed: colliding candidate pairs answered apart (percent of the colliding ones). False: pairs "
        "apart "
        "answered colliding (percent of the apart candidates). Correct: pairs answered right, in percent of "
        "the candidate pairs and of all pairs of instances (a pair the broad phase leaves out is answered "
        "right by it). Flagged: best-effort answers when the budget ran out. Times are per frame, for every "
        "candidate pair of the frame.\n\n"
     << "| hierarchy | series | candidate pairs | colliding | missed % | false % | correct % of candidates | "
        "correct % of all pairs | flagged | median µs | p90 µs |\n"
     << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const std::size_t all_pairs = output.instances * (output.instances ? output.instances - 1 : 0) / 2 *
                                static_cast<std::size_t>(output.frames);
  for (const SeriesTotals& t : totals(output.series)) {
    const std::size_t wrong = t.missed + t.false_pairs;
    md << fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1f} | {:.1f} |\n", t.hierarchy,
                      t.series, t.candidates, t.colliding, percent(t.missed, t.colliding),
                      percent(t.false_pairs, t.candidates - t.colliding),
                      percent(t.candidates - wrong, t.candidates), percent(all_pairs - wrong, all_pairs),
                      t.flagged, quantile(t.micros, 0.5), quantile(t.micros, 0.9));
  }
}

/// Per (hierarchy, broad phase), in first-seen order: medians over the frames.
struct BroadTotals {
  std::string hierarchy, broad_phase;
  double candidates = 0, boxes = 0, update = 0, total = 0;  ///< total: boxes plus update, per frame
};

std::vector<BroadTotals> broad_totals(const std::vector<BroadPhaseRow>& rows) {
  std::map<std::pair<std::string, std::string>, std::vector<const BroadPhaseRow*>> groups;
  std::vector<std::pair<std::string, std::string>> order;
  for (const BroadPhaseRow& r : rows) {
    auto& g = groups[{r.hierarchy, r.broad_phase}];
    if (g.empty()) order.emplace_back(r.hierarchy, r.broad_phase);
    g.push_back(&r);
  }
  std::vector<BroadTotals> out;
  for (const auto& key : order) {
    std::vector<double> candidates, boxes, update, total;
    for (const BroadPhaseRow* r : groups[key]) {
      candidates.push_back(static_cast<double>(r->candidates));
      boxes.push_back(r->boxes_micros);
      update.push_back(r->update_micros);
      total.push_back(r->boxes_micros + r->update_micros);
    }
    out.push_back({key.first, key.second, quantile(candidates, 0.5), quantile(boxes, 0.5),
                   quantile(update, 0.5), quantile(total, 0.5)});
  }
  return out;
}

void broad_phase_table(std::ostream& md, const WorldOutput& output) {
  const std::vector<BroadTotals> rows = broad_totals(output.broad);
  const auto fcl_tree = std::find_if(rows.begin(), rows.end(), [](const BroadTotals& t) {
    return t.hierarchy == kFclWorldHierarchy && t.broad_phase == "fcl_dynamic_aabb_tree";
  });
  const bool ratio = fcl_tree != rows.end() && fcl_tree->total > 0;
  md << "\nBroad phase per frame (world boxes of every instance, then update and pair finding; medians over "
        "the frames, the total per frame too";
  if (ratio)
    md << ". FCL's rows (" << kFclWorldHierarchy
       << "): setTransform and computeAABB of every object, then the manager's update (its registration in "
          "frame 0) and its all-pairs collide collecting the pairs, on FCL's own boxes (around each model's "
          "bounding sphere when rotated); against FCL's tree: the total over FCL's dynamic AABB tree's";
  md << "):\n\n| hierarchy | broad phase | objects | candidate pairs | boxes µs | update µs | total µs |"
     << (ratio ? " against FCL's tree |" : "") << "\n|---|---|---:|---:|---:|---:|---:|"
     << (ratio ? "---:|" : "") << "\n";
  for (const BroadTotals& t : rows) {
    md << fmt::format("| {} | {} | {} | {:.0f} | {:.1f} | {:.1f} | {:.1f} |", t.hierarchy, t.broad_phase,
                      output.instances, t.candidates, t.boxes, t.update, t.total);
    if (ratio) md << fmt::format(" {:.2f} |", t.total / fcl_tree->total);
    md << "\n";
  }
}

void scaling_table(std::ostream& md, const WorldOutput& output) {
  if (output.scaling.empty()) return;
  md << "\nBroad phases alone against the object count (the scene's objects copied at its density; medians "
        "per "
        "frame):\n\n| hierarchy | broad phase | objects | candidate pairs | boxes µs | update µs |\n"
        "|---|---|---:|---:|---:|---:|\n";
  for (const ScalingRow& r : output.scaling)
    md << fmt::format("| {} | {} | {} | {} | {:.1f} | {:.1f} |\n", r.hierarchy, r.broad_phase, r.objects,
                      r.candidates, r.boxes_micros, r.update_micros);
}

}  // namespace

std::string world_readme(const WorldOutput& output, const std::vector<std::string>& figures) {
  std::ostringstream md;
  md << "# " << output.scene << ": " << output.instances << " instances, " << output.frames << " frames\n\n";
  for (const std::string& advice : output.advice) md << "> **The right tool:** " << advice << "\n\n";
  series_table(md, output);
  broad_phase_table(md, output);
  scaling_table(md, output);
  for (const std::string& figure : figures) md << "\n![" << figure << "](" << figure << ")\n";
  return md.str();
}

nlohmann::json world_document(const WorldOutput& output) {
  nlohmann::json series = nlohmann::json::array(), broad = nlohmann::json::array(),
                 scaling = nlohmann::json::array();
  for (const WorldSeriesRow& r : output.series)
    series.push_back({{"frame", r.frame},
                      {"hierarchy", r.hierarchy},
                      {"series", r.series},
                      {"schedule", r.schedule},
                      {"budget", r.budget},
                      {"exact_strategy", r.exact_strategy},
                      {"candidates", r.candidates},
                      {"colliding", r.colliding},
                      {"answered", r.answered},
                      {"missed", r.missed},
                      {"false_pairs", r.false_pairs},
                      {"flagged", r.flagged},
                      {"untested", r.untested},
                      {"untested_colliding", r.untested_colliding},
                      {"micros", r.micros},
                      {"bv_tests", r.bv_tests}});
  for (const BroadPhaseRow& r : output.broad)
    broad.push_back({{"frame", r.frame},
                     {"hierarchy", r.hierarchy},
                     {"broad_phase", r.broad_phase},
                     {"objects", r.objects},
                     {"candidates", r.candidates},
                     {"boxes_micros", r.boxes_micros},
                     {"update_micros", r.update_micros}});
  for (const ScalingRow& r : output.scaling)
    scaling.push_back({{"hierarchy", r.hierarchy},
                       {"broad_phase", r.broad_phase},
                       {"objects", r.objects},
                       {"candidates", r.candidates},
                       {"boxes_micros", r.boxes_micros},
                       {"update_micros", r.update_micros}});
  nlohmann::json document = {{"scene", output.scene},   {"instances", output.instances},
                             {"frames", output.frames}, {"series", series},
                             {"broad_phase", broad},    {"scaling", scaling},
                             {"advice", output.advice}};
  if (output.per_pose == PerPose::none) return document;
  nlohmann::json pairs = nlohmann::json::array();
  for (const WorldPairRow& r : output.pairs)
    pairs.push_back({{"frame", r.frame},
                     {"hierarchy", r.hierarchy},
                     {"series", r.series},
                     {"a", r.a},
                     {"b", r.b},
                     {"truth", r.truth},
                     {"collides", r.collides},
                     {"flagged", r.flagged},
                     {"probability", r.probability},
                     {"micros", r.micros < 0 ? nlohmann::json() : nlohmann::json(r.micros)},
                     {"bv_tests", r.bv_tests}});
  document["pairs"] = std::move(pairs);
  return document;
}

ReportFolder world_report_folder(const WorldOutput& output) {
  ReportFolder folder;
  folder.every_figure = false;  // a figure is drawn only where the run has its data
  folder.figures = {"world_errors_vs_budget.png", "world_broad_phase_vs_objects.png"};
  folder.plot_script = "plot_world.py";
  folder.write_data = [&](const std::filesystem::path& d) { write_world_csv(output, d); };
  folder.readme = [&](const std::vector<std::string>& drawn, const std::string&) {
    return world_readme(output, drawn);
  };
  return folder;
}

}  // namespace bvhlab
