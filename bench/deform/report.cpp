// The files of a deform run: one CSV row per frame, hierarchy, update and strategy variant, and a README
// that sums them up per (hierarchy, update, variant).
#include "bench/deform/deform.hpp"

#include "bench/pairs/report.hpp"
#include "bench/report_folder.hpp"
#include "bench/report_tables.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <map>
#include <sstream>

namespace bvhlab {

namespace {

using report_tables::percent;
using report_tables::quantile;

/// The CSV columns, in order; the JSON rows use the same keys.
const std::vector<std::string> kColumns{
    "frame",     "hierarchy",   "update",         "series",       "exact_strategy",     "degradation",
    "rebuilt",   "tree_micros", "density_micros", "query_micros", "query_total_micros", "queries",
    "colliding", "answered",    "missed",         "false_pairs",  "count_error",        "under_counted",
    "bv_tests"};

nlohmann::json row_json(const DeformRow& r) {
  return {{"frame", r.frame},
          {"hierarchy", r.hierarchy},
          {"update", r.update},
          {"series", r.series},
          {"exact_strategy", r.exact_strategy},
          {"degradation", r.degradation},
          {"rebuilt", r.rebuilt},
          {"tree_micros", r.tree_micros},
          {"density_micros", r.density_micros},
          {"query_micros", r.query_micros},
          {"query_total_micros", r.query_total_micros},
          {"queries", r.queries},
          {"colliding", r.colliding},
          {"answered", r.answered},
          {"missed", r.missed},
          {"false_pairs", r.false_pairs},
          {"count_error", r.count_error},
          {"under_counted", r.under_counted},
          {"bv_tests", r.bv_tests}};
}

std::string csv_cell(const nlohmann::json& v) {
  if (v.is_string()) return "\"" + v.get<std::string>() + "\"";
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number_float()) return fmt::format("{:.6g}", v.get<double>());
  return v.dump();
}

/// Per (hierarchy, update, series), in first-seen order.
struct Summary {
  std::string hierarchy, update, series;
  std::size_t frames = 0, rebuilt = 0, queries = 0, colliding = 0, missed = 0, false_pairs = 0;
  std::vector<double> update_micros, query_micros, frame_micros, count_error, under_counted, bv_tests;
};

std::vector<Summary> summarise(const std::vector<DeformRow>& rows) {
  std::vector<Summary> out;
  std::map<std::tuple<std::string, std::string, std::string>, std::size_t> index;
  for (const DeformRow& r : rows) {
    auto [it, fresh] = index.try_emplace({r.hierarchy, r.update, r.series}, out.size());
    if (fresh) {
      out.emplace_back();
      std::tie(out.back().hierarchy, out.back().update, out.back().series) = it->first;
    }
    Summary& s = out[it->second];
    ++s.frames;
    s.rebuilt += r.rebuilt;
    s.queries += r.queries;
    s.colliding += r.colliding;
    s.missed += r.missed;
    s.false_pairs += r.false_pairs;
    s.update_micros.push_back(r.tree_micros + r.density_micros);
    s.query_micros.push_back(r.query_micros);
    const bool fcl = r.update.starts_with("fcl");  // FCL's queries count no tests
    if (r.queries && !fcl)
      s.bv_tests.push_back(static_cast<double>(r.bv_tests) / static_cast<double>(r.queries));
    s.frame_micros.push_back(r.tree_micros + r.density_micros + r.query_total_micros);
    if (r.count_error >= 0) {
      s.count_error.push_back(r.count_error);
      s.under_counted.push_back(r.under_counted);
    }
  }
  return out;
}

/// The frame time of the same hierarchy and series when rebuilt ("rebuild", or "rebuild + annotate" for a
/// density): the goal's yardstick.
double rebuild_frame_micros(const std::vector<Summary>& all, const Summary& s) {
  for (const Summary& r : all)
    if (r.hierarchy == s.hierarchy && r.series == s.series &&
        (r.update == "rebuild" || r.update == "rebuild + annotate" || r.update == "fcl rebuild"))
      return quantile(r.frame_micros, 0.5);
  return 0;
}

std::string optional_number(const std::vector<double>& values, double scale, const char* format) {
  return values.empty() ? "-" : fmt::format(fmt::runtime(format), scale * quantile(values, 0.5));
}

}  // namespace

void write_deform_csv(const DeformOutput& output, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  std::ofstream csv = report_tables::open_csv(dir / "deform_frames.csv");
  for (std::size_t c = 0; c < kColumns.size(); ++c) csv << (c ? "," : "") << kColumns[c];
  csv << '\n';
  for (const DeformRow& r : output.rows) {
    const nlohmann::json row = row_json(r);
    for (std::size_t c = 0; c < kColumns.size(); ++c) csv << (c ? "," : "") << csv_cell(row.at(kColumns[c]));
    csv << '\n';
  }
  if (!csv) throw std::runtime_error((dir / "deform_frames.csv").string() + ": writing failed");
}

nlohmann::json deform_document(const DeformOutput& output) {
  nlohmann::json rows = nlohmann::json::array();
  for (const DeformRow& r : output.rows) rows.push_back(row_json(r));
  return {{"scene", output.scene},         {"object", output.object},
          {"other", output.other},         {"deformation", output.deformation},
          {"triangles", output.triangles}, {"frames", output.frames},
          {"poses", output.poses},         {"rows", rows}};
}

std::string deform_readme(const DeformOutput& output, const std::vector<std::string>& figures) {
  std::ostringstream md;
  md << "# " << output.scene << ": " << output.object << " (" << output.triangles << " triangles, "
     << output.deformation << ") against " << output.other << ", " << output.frames << " frames, "
     << output.poses << " poses per frame\n\n"
     << "Per frame the deforming object's tree is refitted (rebuilt when its degradation passes the scene's "
        "limit: column rebuilt) or rebuilt; FCL's model is updated and refitted, or rebuilt. Update: tree "
        "plus "
        "density, median µs per frame. Frame: update plus every query of the frame, median µs; vs rebuild: "
        "that over the same hierarchy and strategy when rebuilt (and re-annotated). Missed: colliding poses "
        "answered apart (percent of the colliding); false: poses apart answered colliding (percent of those "
        "apart), against the exact answer on the deformed mesh. BV tests: per query, median over frames (a "
        "coherent strategy continues each pose's state from the last frame while the tree is refitted, and "
        "starts afresh on a tree built anew). Count error: mean |count - exact recount| "
        "per "
        "node, median over frames; under: share of nodes counted below the exact recount.\n\n"
     << "| hierarchy | update | strategy | rebuilt | update µs | query µs | BV tests | frame µs | vs rebuild "
        "| missed % | false % | count error | under % |\n"
     << "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  const std::vector<Summary> all = summarise(output.rows);
  for (const Summary& s : all) {
    const double frame = quantile(s.frame_micros, 0.5), rebuild = rebuild_frame_micros(all, s);
    md << fmt::format("| {} | {} | {} | {} | {:.0f} | {:.2f} | {} | {:.0f} | {} | {} | {} | {} | {} |\n",
                      s.hierarchy, s.update, s.series, s.rebuilt, quantile(s.update_micros, 0.5),
                      quantile(s.query_micros, 0.5), optional_number(s.bv_tests, 1, "{:.1f}"), frame,
                      rebuild > 0 ? fmt::format("{:.2f}", frame / rebuild) : "-",
                      percent(s.missed, s.colliding), percent(s.false_pairs, s.queries - s.colliding),
                      optional_number(s.count_error, 1, "{:.3f}"),
                      optional_number(s.under_counted, 100, "{:.1f}"));
  }
  for (const std::string& note : output.notes) md << "\nNote: " << note << "\n";
  for (const std::string& figure : figures) md << "\n![" << figure << "](" << figure << ")\n";
  return md.str();
}

ReportFolder deform_report_folder(const DeformOutput& output) {
  ReportFolder folder;
  folder.every_figure = false;  // a figure is drawn only where the run has its data
  folder.figures = {"deform_time_per_frame.png", "deform_error_vs_time.png"};
  folder.plot_script = "plot_deform.py";
  folder.write_data = [&](const std::filesystem::path& d) { write_deform_csv(output, d); };
  folder.readme = [&](const std::vector<std::string>& drawn, const std::string&) {
    return deform_readme(output, drawn);
  };
  return folder;
}

}  // namespace bvhlab
