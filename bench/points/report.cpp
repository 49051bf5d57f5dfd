// The files and tables of a points run (bench/points/points.hpp): the rows as CSV, the totals as text
// (bench_points) or Markdown (the report's README), and the goal's verdicts read off the totals.
#include "bench/points/points.hpp"

#include "bench/pairs/report.hpp"
#include "bench/report_folder.hpp"
#include "bench/report_tables.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace bvhlab {

namespace {

using Group = std::vector<const PointsRow*>;
using report_tables::percent;

/// The totals cut into (pair, density) groups, in run order.
std::vector<Group> groups_of(const std::vector<PointsRow>& totals) {
  std::vector<Group> out;
  for (const PointsRow& r : totals) {
    if (out.empty() || out.back().front()->pair != r.pair || out.back().front()->points != r.points)
      out.emplace_back();
    out.back().push_back(&r);
  }
  return out;
}

const PointsRow* find_series(const Group& g, const std::string& series) {
  for (const PointsRow* r : g)
    if (r->series == series) return r;
  return nullptr;
}

/// The fastest inexact row by mean time with at most `max_error` percent wrong.
const PointsRow* fastest_inexact(const Group& g, double max_error) {
  const PointsRow* best = nullptr;
  for (const PointsRow* r : g)
    if (is_inexact_series(r->series) && r->clear && r->error_percent() <= max_error &&
        (!best || r->mean_us < best->mean_us))
      best = r;
  return best;
}

double ratio(double reference, double value) {
  return value > 0 ? reference / value : 0;
}

std::string group_title(const PointsRow& r) {
  return fmt::format("{} at {} points (spacing {:.4f})", r.pair, r.points, r.spacing);
}

std::vector<std::string> group_verdicts(const Group& g, double max_error) {
  std::vector<std::string> out;
  const PointsRow* exact = find_series(g, "exact_points");
  if (!exact) return out;
  out.push_back(
      fmt::format("{}: exact_points misses {} of {} clear poses ({}%; {}% of the {} clear colliding)",
                  group_title(*exact), exact->fn, exact->clear, percent(exact->fn, exact->clear),
                  percent(exact->fn, exact->colliding), exact->colliding));
  if (const PointsRow* best = fastest_inexact(g, max_error))
    out.push_back(
        fmt::format("{}: best inexact at <= {:g}% wrong: {} ({:.2f}% wrong), {:.2f}x faster than "
                    "exact_points by mean time, {:.2f}x by median",
                    group_title(*exact), max_error, best->series, best->error_percent(),
                    ratio(exact->mean_us, best->mean_us), ratio(exact->median_us, best->median_us)));
  else
    out.push_back(fmt::format("{}: no inexact series at <= {:g}% wrong", group_title(*exact), max_error));
  for (const PointsRow* f : g) {
    if (f->series.rfind("fcl_octree", 0) != 0) continue;
    if (const PointsRow* best = fastest_inexact(g, f->error_percent()))
      out.push_back(
          fmt::format("{}: {} ({:.2f}% wrong): {} at {:.2f}% wrong is {:.2f}x faster by mean time, "
                      "{:.2f}x by median",
                      group_title(*f), f->series, f->error_percent(), best->series, best->error_percent(),
                      ratio(f->mean_us, best->mean_us), ratio(f->median_us, best->median_us)));
    else
      out.push_back(fmt::format("{}: {} ({:.2f}% wrong): no inexact series at equal or fewer errors",
                                group_title(*f), f->series, f->error_percent()));
  }
  return out;
}

/// The CSV columns; `with_distance` for the per-distance rows.
void write_rows(const std::vector<PointsRow>& rows, const std::filesystem::path& file, bool with_distance) {
  std::ofstream csv = report_tables::open_csv(file);
  csv << "pair,points,spacing," << (with_distance ? "distance," : "")
      << "series,poses,clear,ambiguous,colliding,fp,fn,median_us,mean_us\n";
  for (const PointsRow& r : rows) {
    csv << fmt::format("\"{}\",{},{:.6g},", r.pair, r.points, r.spacing);
    if (with_distance) csv << fmt::format("{:g},", r.distance);
    csv << fmt::format("\"{}\",{},{},{},{},{},{},{:.6g},{:.6g}\n", r.series, r.poses, r.clear, r.ambiguous,
                       r.colliding, r.fp, r.fn, r.median_us, r.mean_us);
  }
  if (!csv) throw std::runtime_error(file.string() + ": writing failed");
}

}  // namespace

nlohmann::json points_document(const PointsOutput& output) {
  const auto rows = [](const std::vector<PointsRow>& in, bool with_distance) {
    nlohmann::json out = nlohmann::json::array();
    for (const PointsRow& r : in) {
      nlohmann::json row = {
          {"pair", r.pair},   {"points", r.points}, {"spacing", r.spacing},     {"series", r.series},
          {"poses", r.poses}, {"clear", r.clear},   {"ambiguous", r.ambiguous}, {"colliding", r.colliding},
          {"fp", r.fp},       {"fn", r.fn},         {"median_us", r.median_us}, {"mean_us", r.mean_us}};
      if (with_distance) row["distance"] = r.distance;
      out.push_back(std::move(row));
    }
    return out;
  };
  return {{"scene", output.scene},
          {"rows", rows(output.rows, true)},
          {"summary", rows(output.totals, false)},
          {"cgal_checked", output.cgal_checked},
          {"cgal_mismatches", output.cgal_mismatches},
          {"notes", output.notes}};
}

std::vector<std::string> points_verdicts(const std::vector<PointsRow>& totals, double max_error) {
  std::vector<std::string> out;
  for (const Group& g : groups_of(totals))
    for (std::string& line : group_verdicts(g, max_error)) out.push_back(std::move(line));
  return out;
}

std::string points_text(const PointsOutput& output) {
  std::ostringstream text;
  for (const Group& g : groups_of(output.totals)) {
    const PointsRow& first = *g.front();
    text << fmt::format("\n{}: {} poses, {} ambiguous, {} clear ({} colliding)\n", group_title(first),
                        first.poses, first.ambiguous, first.clear, first.colliding);
    text << fmt::format("{:<36} {:>10} {:>10} {:>7} {:>7} {:>7} {:>9}\n", "series", "median_us", "mean_us",
                        "FP%", "FN%", "err%", "x_mean");
    const PointsRow* exact = find_series(g, "exact_points");
    for (const PointsRow* r : g)
      text << fmt::format("{:<36} {:>10.2f} {:>10.2f} {:>7} {:>7} {:>7.2f} {:>9.2f}\n", r->series,
                          r->median_us, r->mean_us, percent(r->fp, r->clear), percent(r->fn, r->clear),
                          r->error_percent(), exact ? ratio(exact->mean_us, r->mean_us) : 0.0);
  }
  text << "\n";
  for (const std::string& line : points_verdicts(output.totals)) text << line << "\n";
  for (const std::string& line : output.notes) text << "note: " << line << "\n";
  return text.str();
}

void write_points_csv(const PointsOutput& output, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  write_rows(output.rows, dir / "points_rows.csv", true);
  write_rows(output.totals, dir / "points_summary.csv", false);
}

std::string points_readme(const PointsOutput& output, const std::vector<std::string>& figures) {
  std::ostringstream md;
  md << "# " << output.scene << ": point clouds on the tumbling protocol, " << output.steps
     << " steps per distance\n\n"
     << "Clouds sampled from each pair's meshes; truth: the exact answer on the meshes. A pose is ambiguous "
        "when B moved by the band (about a point spacing) along an axis changes that answer; FP and FN are "
        "percent of the clear poses (the others). Times per query in µs, warm, net of the clock's overhead; "
        "x mean: exact_points' mean time over the series'. Per distance: points_rows.csv; these totals: "
        "points_summary.csv.\n";
  for (const PointsCloudInfo& c : output.clouds) {
    md << fmt::format(
        "\n## {} at {} points\n\n{} and {} triangles, spacing {:.4f} (sqrt(area / N)), band {:.4f}", c.pair,
        c.points, c.triangles_a, c.triangles_b, c.spacing, c.band);
    for (const std::string& o : c.octrees) md << "; FCL octree " << o;
    md << ".\n\n| series | poses | ambiguous | clear (colliding) | FP % | FN % | median µs | mean µs | x "
          "mean |\n"
       << "|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    Group g;
    for (const PointsRow& r : output.totals)
      if (r.pair == c.pair && r.points == c.points) g.push_back(&r);
    const PointsRow* exact = find_series(g, "exact_points");
    for (const PointsRow* r : g)
      md << fmt::format("| {} | {} | {} | {} ({}) | {} | {} | {:.2f} | {:.2f} | {:.2f} |\n", r->series,
                        r->poses, r->ambiguous, r->clear, r->colliding, percent(r->fp, r->clear),
                        percent(r->fn, r->clear), r->median_us, r->mean_us,
                        exact ? ratio(exact->mean_us, r->mean_us) : 0.0);
  }
  md << "\n## Against the goal\n\n";
  for (const std::string& line : points_verdicts(output.totals)) md << "- " << line << "\n";
  md << fmt::format("\nThe mesh truth agrees with CGAL on {} of {} poses checked.\n",
                    output.cgal_checked - output.cgal_mismatches, output.cgal_checked);
  for (const std::string& note : output.notes) md << "\nNote: " << note << "\n";
  for (const std::string& figure : figures) md << "\n![" << figure << "](" << figure << ")\n";
  return md.str();
}

ReportFolder points_report_folder(const PointsOutput& output) {
  ReportFolder folder;
  folder.every_figure = false;  // a figure is drawn only where the run has its data
  folder.figures = {"points_error_vs_time.png", "points_fp_fn.png"};
  folder.plot_script = "plot_points.py";
  folder.write_data = [&](const std::filesystem::path& d) { write_points_csv(output, d); };
  folder.readme = [&](const std::vector<std::string>& drawn, const std::string&) {
    return points_readme(output, drawn);
  };
  return folder;
}

}  // namespace bvhlab
