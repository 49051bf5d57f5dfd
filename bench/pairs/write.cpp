// The write stage of the bench pipeline: results.csv, calibration.csv and results.json from a run. The CSV
// columns and the JSON rows come from one field table, so the two cannot drift apart.
#include "bench/pairs/write.hpp"

#include "engine/policies.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace bvhlab {

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}
std::string csv_number(double v) {
  if (!std::isfinite(v)) return "";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
std::string csv_p_min(double p) {
  return p < 0 ? "" : csv_number(p);
}

std::ofstream open_output(const std::filesystem::path& file) {
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::trunc);
  if (!out) throw std::runtime_error(file.string() + ": cannot write");
  return out;
}

}  // namespace

namespace {

using json = nlohmann::json;

json optional_number(double v) {
  return std::isfinite(v) ? json(v) : json(nullptr);
}
json optional_p_min(double p) {
  return p < 0 ? json(nullptr) : json(p);
}

/// One column of results.csv and one key of the rows in results.json: both writers read this table.
struct RowField {
  const char* name;
  json (*value)(const ResultRow&);
};

const std::vector<RowField>& row_fields() {
  static const std::vector<RowField> fields{
      {"mesh", [](const ResultRow& r) { return json(r.mesh); }},
      {"hierarchy", [](const ResultRow& r) { return json(r.hierarchy); }},
      {"bv", [](const ResultRow& r) { return json(r.bv); }},
      {"annotation", [](const ResultRow& r) { return json(r.annotation); }},
      {"strategy", [](const ResultRow& r) { return json(r.strategy); }},
      {"label", [](const ResultRow& r) { return json(r.label); }},
      {"exact", [](const ResultRow& r) { return json(r.exact_strategy); }},
      {"p_min", [](const ResultRow& r) { return optional_p_min(r.p_min); }},
      {"budget", [](const ResultRow& r) { return json(r.budget); }},
      {"distance", [](const ResultRow& r) { return json(r.distance); }},
      {"queries", [](const ResultRow& r) { return json(r.queries); }},
      {"truth_colliding_rate", [](const ResultRow& r) { return json(r.truth_colliding_rate); }},
      {"answer_colliding_rate", [](const ResultRow& r) { return json(r.answer_colliding_rate); }},
      {"mean_time_us", [](const ResultRow& r) { return json(r.mean_time_us); }},
      {"median_time_us", [](const ResultRow& r) { return json(r.median_time_us); }},
      {"p99_time_us", [](const ResultRow& r) { return json(r.p99_time_us); }},
      {"max_time_us", [](const ResultRow& r) { return json(r.max_time_us); }},
      {"fp_rate", [](const ResultRow& r) { return json(r.fp_rate); }},
      {"fn_rate", [](const ResultRow& r) { return json(r.fn_rate); }},
      {"inexact_rate", [](const ResultRow& r) { return json(r.inexact_rate); }},
      {"budget_exhausted_rate", [](const ResultRow& r) { return json(r.budget_exhausted_rate); }},
      {"bv_tests_per_query", [](const ResultRow& r) { return optional_number(r.bv_tests_per_query); }},
      {"triangle_tests_per_query",
       [](const ResultRow& r) { return optional_number(r.triangle_tests_per_query); }},
      {"nodes_visited_per_query",
       [](const ResultRow& r) { return optional_number(r.nodes_visited_per_query); }},
      {"estimates_per_query", [](const ResultRow& r) { return optional_number(r.estimates_per_query); }},
      {"in_summary", [](const ResultRow& r) { return json(r.in_summary); }},
      {"model_bytes", [](const ResultRow& r) { return json(r.model_bytes); }},
      {"bytes_per_triangle", [](const ResultRow& r) { return json(r.bytes_per_triangle); }},
      {"distance_error", [](const ResultRow& r) { return optional_number(r.distance_error); }},
      {"width_median", [](const ResultRow& r) { return optional_number(r.width_median); }},
      {"width_tenth_rate", [](const ResultRow& r) { return optional_number(r.width_tenth_rate); }},
      {"interval_misses", [](const ResultRow& r) { return json(r.interval_misses); }},
  };
  return fields;
}

/// The record's pose, from the scene the run kept.
const RigidTransform& pose_of(const RunOutput& run, const PoseRecord& p) {
  return run.scene.workload.groups[p.group].poses[p.index];
}
json counter(const PoseRecord& p, std::uint64_t value) {
  return p.has_counters ? json(value) : json(nullptr);
}

/// One column of poses.csv and one key of poses_document's objects. The series' fields come from its row.
struct PoseField {
  const char* name;
  json (*value)(const RunOutput&, const PoseRecord&);
};

const std::vector<PoseField>& pose_fields() {
  using R = const RunOutput&;
  using P = const PoseRecord&;
  static const std::vector<PoseField> fields{
      {"mesh", [](R run, P p) { return json(run.rows[p.row].mesh); }},
      {"hierarchy", [](R run, P p) { return json(run.rows[p.row].hierarchy); }},
      {"bv", [](R run, P p) { return json(run.rows[p.row].bv); }},
      {"strategy", [](R run, P p) { return json(run.rows[p.row].strategy); }},
      {"label", [](R run, P p) { return json(run.rows[p.row].label); }},
      {"p_min", [](R run, P p) { return optional_p_min(run.rows[p.row].p_min); }},
      {"budget", [](R run, P p) { return json(run.rows[p.row].budget); }},
      {"distance", [](R run, P p) { return json(run.rows[p.row].distance); }},
      {"pose_index", [](R, P p) { return json(p.index); }},
      {"pose", [](R run, P p) { return json(pose_text(pose_of(run, p))); }},
      {"truth", [](R, P p) { return json(p.truth); }},
      {"answer", [](R, P p) { return json(p.answer); }},
      {"false_positive", [](R, P p) { return json(p.answer && !p.truth); }},
      {"false_negative", [](R, P p) { return json(!p.answer && p.truth); }},
      {"probability", [](R, P p) { return json(p.probability); }},
      {"exact", [](R, P p) { return json(p.exact); }},
      {"budget_exhausted", [](R, P p) { return json(p.budget_exhausted); }},
      {"time_us", [](R, P p) { return json(p.time_us); }},
      {"bv_tests", [](R, P p) { return counter(p, p.counters.bv_tests); }},
      {"triangle_tests", [](R, P p) { return counter(p, p.counters.triangle_tests); }},
      {"probability_evaluations", [](R, P p) { return counter(p, p.counters.probability_evaluations); }},
      {"nodes_visited", [](R, P p) { return counter(p, p.counters.nodes_visited); }},
  };
  return fields;
}

std::string csv_value(const json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) return csv_field(v.get<std::string>());
  if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
  if (v.is_number_integer() || v.is_number_unsigned()) return v.dump();
  return csv_number(v.get<double>());
}

}  // namespace

const std::vector<std::string>& results_csv_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> out;
    for (const RowField& f : row_fields()) out.emplace_back(f.name);
    for (const char* env : {"machine", "compiler", "build_type", "git_commit"}) out.emplace_back(env);
    return out;
  }();
  return columns;
}

void write_results_csv(const RunOutput& run, const std::filesystem::path& file) {
  std::ofstream out = open_output(file);
  const auto& columns = results_csv_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n';
  const Environment& env = run.environment;
  for (const ResultRow& r : run.rows) {
    for (const RowField& f : row_fields()) out << csv_value(f.value(r)) << ',';
    out << csv_field(env.machine) << ',' << csv_field(env.compiler) << ',' << csv_field(env.build_type) << ','
        << csv_field(env.git_commit) << '\n';
  }
  if (!out) throw std::runtime_error(file.string() + ": write error");
}

const std::vector<std::string>& poses_csv_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> out;
    for (const PoseField& f : pose_fields()) out.emplace_back(f.name);
    return out;
  }();
  return columns;
}

std::string pose_text(const RigidTransform& pose) {
  std::string out;
  char buf[32];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) {
      std::snprintf(buf, sizeof buf, "%.17g",
                    j < 3 ? double(pose.rotation(i, j)) : double(pose.translation[i]));
      if (!out.empty()) out += ',';
      out += buf;
    }
  return out;
}

void write_poses_csv(const RunOutput& run, const std::filesystem::path& file) {
  std::ofstream out = open_output(file);
  const auto& columns = poses_csv_columns();
  for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
  out << '\n';
  for (const PoseRecord& p : run.poses) {
    const auto& fields = pose_fields();
    for (std::size_t i = 0; i < fields.size(); ++i)
      out << (i ? "," : "") << csv_value(fields[i].value(run, p));
    out << '\n';
  }
  if (!out) throw std::runtime_error(file.string() + ": write error");
}

json poses_document(const RunOutput& run) {
  json out = json::array();
  for (const PoseRecord& p : run.poses) {
    json record = json::object();
    for (const PoseField& f : pose_fields()) record[f.name] = f.value(run, p);
    out.push_back(std::move(record));
  }
  return out;
}

void write_calibration_csv(const RunOutput& run, const std::filesystem::path& file) {
  std::ofstream out = open_output(file);
  out << "mesh,hierarchy,strategy,p_min,budget,calibrated,bin_low,bin_high,count,mean_probability,"
         "collision_frequency\n";
  for (const CalibrationBin& c : run.calibration)
    out << csv_field(c.mesh) << ',' << csv_field(c.hierarchy) << ',' << c.strategy << ','
        << csv_p_min(c.p_min) << ',' << csv_field(c.budget) << ',' << (c.calibrated ? 1 : 0) << ','
        << csv_number(c.bin_low) << ',' << csv_number(c.bin_high) << ',' << c.count << ','
        << csv_number(c.mean_probability) << ',' << csv_number(c.collision_frequency) << '\n';
  if (!out) throw std::runtime_error(file.string() + ": write error");
}

namespace {

/// results.json's "stats": the run's counters and times.
json stats_json(const RunStats& s) {
  return {{"meshes_loaded", s.meshes_loaded},
          {"trees_built", s.trees_built},
          {"trees_annotated", s.trees_annotated},
          {"annotation_clip_calls", s.annotation_clip_calls},
          {"tree_cache_hits", s.tree_cache_hits},
          {"tree_cache_rejected", s.tree_cache_rejected},
          {"tree_cache_stored", s.tree_cache_stored},
          {"fcl_models_built", s.fcl_models_built},
          {"truth_computed", s.truth_computed},
          {"truth_cache_hits", s.truth_cache_hits},
          {"truth_cache_rejected", s.truth_cache_rejected},
          {"calibration_fitted", s.calibration_fitted},
          {"calibration_cache_hits", s.calibration_cache_hits},
          {"cgal_checked", s.cgal_checked},
          {"cgal_mismatches", s.cgal_mismatches},
          {"queries", s.queries},
          {"preprocess_seconds", s.preprocess_seconds},
          {"truth_seconds", s.truth_seconds},
          {"query_seconds", s.query_seconds},
          {"wall_seconds", s.wall_seconds},
          {"clock_overhead_us", s.clock_overhead_us},
          {"timing_repeats", s.timing_repeats},
          {"timing_statistic", s.timing_statistic},
          {"timed_samples", s.timed_samples},
          {"stalled_samples", s.stalled_samples},
          {"sampled_seconds", s.sampled_seconds},
          {"stall_lost_seconds", s.stall_lost_seconds},
          {"involuntary_switches", s.involuntary_switches},
          {"skipped", s.skipped}};
}

/// results.json's "models": one entry per tree the run built or loaded.
json models_json(const RunOutput& run) {
  json models = json::array();
  for (const ModelInfo& m : run.models)
    models.push_back({{"object", m.object},
                      {"hierarchy", m.hierarchy},
                      {"bv", m.bv},
                      {"annotation", m.annotation},
                      {"triangles", m.triangles},
                      {"nodes", m.nodes},
                      {"depth", m.depth},
                      {"model_bytes", m.model_bytes},
                      {"bytes_per_triangle", m.bytes_per_triangle},
                      {"build_seconds", m.build_seconds},
                      {"annotate_seconds", m.annotate_seconds},
                      {"from_cache", m.from_cache}});
  return models;
}

/// results.json's "calibration": calibration.csv's bins, with null for a missing p_min or number.
json calibration_json(const RunOutput& run) {
  json cal = json::array();
  for (const CalibrationBin& c : run.calibration)
    cal.push_back({{"mesh", c.mesh},
                   {"hierarchy", c.hierarchy},
                   {"strategy", c.strategy},
                   {"p_min", c.p_min < 0 ? json(nullptr) : json(c.p_min)},
                   {"budget", c.budget},
                   {"calibrated", c.calibrated},
                   {"bin_low", c.bin_low},
                   {"bin_high", c.bin_high},
                   {"count", c.count},
                   {"mean_probability", optional_number(c.mean_probability)},
                   {"collision_frequency", optional_number(c.collision_frequency)}});
  return cal;
}

}  // namespace

json results_document(const RunOutput& run) {
  const Environment& env = run.environment;
  json doc;
  doc["scene"] = {{"name", run.scene_name}, {"file", run.scene_file.string()}};
  doc["environment"] = {{"machine", env.machine},
                        {"compiler", env.compiler},
                        {"build_type", env.build_type},
                        {"git_commit", env.git_commit},
                        {"timestamp", env.timestamp}};
  doc["stats"] = stats_json(run.stats);
  doc["models"] = models_json(run);
  json truth = json::array();
  for (const TruthSummary& t : run.truth)
    truth.push_back(
        {{"mesh", t.mesh}, {"distance", t.distance}, {"poses", t.poses}, {"colliding", t.colliding}});
  doc["ground_truth"] = truth;
  json rows = json::array();
  for (const ResultRow& r : run.rows) {
    json row = json::object();
    for (const RowField& f : row_fields()) row[f.name] = f.value(r);
    rows.push_back(std::move(row));
  }
  doc["rows"] = rows;
  doc["calibration"] = calibration_json(run);
  doc["policies"] = policies_json();
  return doc;
}

void write_results_json(const RunOutput& run, const std::filesystem::path& file) {
  std::ofstream out = open_output(file);
  out << results_document(run).dump(1) << '\n';
  if (!out) throw std::runtime_error(file.string() + ": write error");
}

}  // namespace bvhlab
