// Point clouds on the tumbling protocol (scene "points"; adb/README.md, section 4): per pair of objects and
// density, a cloud sampled from each mesh, B tumbling about A at each distance. The ground truth is the
// exact answer on the meshes (cross-checked against CGAL on a sample). A pose is ambiguous when that answer
// changes with B moved by the band (PointsSpec::band point spacings) along any axis, either way: the objects
// are then within about a spacing of touching. Ambiguous poses are counted apart; false positives and false
// negatives are counted on the others, the clear poses.
//
// Series, all on AABB trees, timed one query at a time after a warm pass over the poses, net of the clock's
// own overhead: exact_mesh (exact on the meshes), exact_points (cloud against cloud), exact_points_vs_mesh
// (A's cloud against B's mesh), adb p_min=P on the clouds, adb p_min=P confirm_levels=L (ADB deciding only
// after L generations of candidates: AdbOptions::confirm_levels), time_critical p_min=0.9 bv_tests=N (ADB
// under a BV-test cap), and with FCL fcl_octree res=R (FCL's octrees of the same points, voxel side R
// spacings; bench/core/fcl_octree.hpp). bench_points and `bvhlab report` both run this.
#pragma once

#include "bench/core/scene.hpp"
#include "bench/report_folder.hpp"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace bvhlab {

/// One series of one pair at one density, over one distance's poses or over all of them.
struct PointsRow {
  std::string pair;        ///< the pair's label ("pinion", or "a|b")
  std::size_t points = 0;  ///< per cloud
  double spacing = 0;      ///< sqrt(area / points), the larger of the two clouds'
  double distance = -1;    ///< the protocol distance; -1 in the totals over every distance
  std::string series;
  std::size_t poses = 0, ambiguous = 0, clear = 0;
  std::size_t colliding = 0;   ///< clear poses whose mesh answer is "collides"
  std::size_t fp = 0, fn = 0;  ///< on the clear poses
  double median_us = 0, mean_us = 0;

  [[nodiscard]] double error_percent() const;  ///< (fp + fn) / clear, in percent; 0 without clear poses
};

/// One pair at one density: its clouds, and what was built for it.
struct PointsCloudInfo {
  std::string pair;
  std::size_t triangles_a = 0, triangles_b = 0, points = 0;
  double spacing = 0, band = 0;      ///< in scene units
  std::vector<std::string> octrees;  ///< per FCL octree: its voxel side, occupied voxels, build time
};

struct PointsOutput {
  std::string scene;
  int steps = 0;
  std::vector<PointsCloudInfo> clouds;
  std::vector<PointsRow> rows;    ///< per pair, density, distance and series
  std::vector<PointsRow> totals;  ///< per pair, density and series, over every distance
  std::size_t cgal_checked = 0, cgal_mismatches = 0;
  std::vector<std::string> notes;
};

/// What points_rows.csv ("rows") and points_summary.csv ("summary") hold, keyed like their columns, with
/// the CGAL cross-check's counts and the run's notes: Python's run_scene on a points scene.
nlohmann::json points_document(const PointsOutput& output);

/// Runs a points scene (scene.points set): every pair whose meshes are available (others are skipped with a
/// note). Progress goes to stderr unless `quiet`. Throws std::invalid_argument for a scene without "points",
/// MeshError for a mesh that does not load.
PointsOutput run_points(const Scene& scene, bool quiet);

/// Whether a series may trade errors for time (ADB at a p_min, time-critical).
bool is_inexact_series(const std::string& series);

/// The goal read off the totals, one line per pair and density: exact_points' false negatives, the
/// fastest inexact series at most `max_error` percent wrong and its speed-up over exact_points, and per FCL
/// octree the fastest inexact series with no more errors.
std::vector<std::string> points_verdicts(const std::vector<PointsRow>& totals, double max_error = 4.0);

/// The totals as a fixed-width text table per pair and density (bench_points prints it).
std::string points_text(const PointsOutput& output);

/// points_rows.csv (per distance) and points_summary.csv (over every distance) in `dir`.
void write_points_csv(const PointsOutput& output, const std::filesystem::path& dir);

/// The README of a points report: the totals per pair and density, the verdicts, the notes, the figures.
std::string points_readme(const PointsOutput& output, const std::vector<std::string>& figures = {});

/// What its report folder holds (write_report_folder, bench/report_folder.hpp): the CSV files, its figures,
/// the README. `output` must outlive it.
ReportFolder points_report_folder(const PointsOutput& output);

}  // namespace bvhlab
