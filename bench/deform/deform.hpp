// The deform runner: one object deforming over frames against a rigid one (scene "deform"). Per frame the
// deforming object's trees follow it: refitted (rebuilt when degraded) and, side by side, rebuilt; FCL's
// models are updated and refitted, and rebuilt. Every tree answers B's poses; the answers are counted
// against the exact answer on the deformed mesh (a fresh AABB tree's exact traversal, which the tests check
// against CGAL). Trees with the ADB density follow with each density-update policy, whose counts are
// compared with an exact recount.
#pragma once

#include "bench/core/scene.hpp"
#include "bench/report_folder.hpp"
#include "bench/run.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>

#include <filesystem>
#include <string>
#include <vector>

namespace bvhlab {

/// One frame of one way of keeping one hierarchy up to date, answering with one strategy variant.
struct DeformRow {
  int frame = 0;
  std::string hierarchy;
  /// "refit", "rebuild", "refit + <density update>", "rebuild + annotate", "fcl refit", "fcl rebuild"
  std::string update;
  std::string series;  ///< the strategy variant: "exact", "adb p_min=0.9"
  bool exact_strategy = false;
  double degradation = 1;     ///< the tree's after the update (Bvh::degradation; 1 for a rebuild)
  bool rebuilt = false;       ///< the refitted tree passed the scene's rebuild_degradation and was rebuilt
  double tree_micros = 0;     ///< refit or rebuild of A's tree (FCL: update-and-refit, or rebuild)
  double density_micros = 0;  ///< the density update, or the annotation of a rebuilt tree
  double query_micros = 0;    ///< median per query
  double query_total_micros = 0;  ///< every query of the frame
  std::size_t queries = 0, colliding = 0, answered = 0, missed = 0, false_pairs = 0;
  std::uint64_t bv_tests = 0;  ///< every query of the frame
  double count_error = -1;     ///< mean |count - exact recount| per node; -1 where no density is kept
  double under_counted = -1;   ///< share of nodes counted below the exact recount; -1 likewise
};

struct DeformOutput {
  std::string scene, object, other, deformation;
  std::size_t triangles = 0;  ///< of the deforming object
  int frames = 0;
  std::size_t poses = 0;
  std::vector<DeformRow> rows;
  std::vector<std::string> notes;
};

/// Runs a deform scene (scene.deform set). Throws std::invalid_argument for a scene without one, and
/// MeshError for a frame file that does not fit the first.
DeformOutput run_deform(const Scene& scene, const RunOptions& options);

/// deform_frames.csv in `dir` (columns: the rows' fields).
void write_deform_csv(const DeformOutput& output, const std::filesystem::path& dir);

/// The rows as JSON (Python's run_scene on a deform scene): {"scene", "object", ..., "rows": [...]}.
nlohmann::json deform_document(const DeformOutput& output);

/// The README of a deform report: per hierarchy and update, median update and query time per frame and the
/// answers missed and false; per density update its count error.
std::string deform_readme(const DeformOutput& output, const std::vector<std::string>& figures = {});

/// What its report folder holds (write_report_folder, bench/report_folder.hpp): the CSV files, its figures,
/// the README. `output` must outlive it.
ReportFolder deform_report_folder(const DeformOutput& output);

}  // namespace bvhlab
