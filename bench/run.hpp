// The scene runner: builds (or loads from the cache) exactly the trees a scene asks for, computes or loads
// the exact ground truth, times every strategy on the same poses in this process, and aggregates one row per
// (mesh pair, hierarchy, strategy variant, distance).
#pragma once

#include "adb/saved_tree.hpp"
#include "bench/core/scene.hpp"
#include "traversal/result.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Which per-pose records a run keeps (`bvhlab run/report --per-pose`): none (the default: nothing beyond
/// the aggregates), every timed query, or only those whose answer differs from the ground truth.
enum class PerPose { none, all, wrong };
/// "none", "all" or "wrong"; throws std::invalid_argument naming the value and the choices otherwise.
PerPose parse_per_pose(std::string_view text);
const char* per_pose_name(PerPose mode);

struct RunOptions {
  /// Root of the on-disk cache (trees/ and truth/ below it). Empty: nothing is read from or written to disk.
  std::filesystem::path cache_dir;
  bool progress = false;  ///< a progress bar on stderr
  /// Receives messages (skipped objects, rejected cache entries, what is being built). Default: stderr.
  std::function<void(const std::string&)> log;
  unsigned threads = 0;    ///< preprocessing threads; 0: hardware concurrency
  int warmup_queries = 2;  ///< untimed queries before each timed block of poses (caches, branch predictors)
  PerPose per_pose = PerPose::none;  ///< which queries RunOutput::poses keeps
};

/// Evidence of what the run did, for the "only what is needed" rule and the cache.
struct RunStats {
  std::size_t meshes_loaded = 0;
  std::size_t trees_built = 0;            ///< bvhlab hierarchies built from a mesh
  std::size_t trees_annotated = 0;        ///< ADB annotations computed (CGAL clipping)
  std::size_t annotation_clip_calls = 0;  ///< CGAL clipping calls made by those annotations
  std::size_t tree_cache_hits = 0;        ///< trees (plain or annotated) loaded from the disk cache
  std::size_t tree_cache_rejected = 0;    ///< cache entries found stale or corrupt, then rebuilt
  std::size_t tree_cache_stored = 0;
  std::size_t fcl_models_built = 0;
  std::size_t truth_computed = 0;  ///< pose sets whose ground truth was computed
  std::size_t truth_cache_hits = 0;
  std::size_t truth_cache_rejected = 0;
  std::size_t calibration_fitted = 0;      ///< calibration maps fitted on training poses
  std::size_t calibration_cache_hits = 0;  ///< calibration maps loaded from the disk cache
  std::size_t cgal_checked = 0;            ///< poses cross-checked against CGAL
  std::size_t cgal_mismatches = 0;         ///< of those, where CGAL disagreed with the ground truth
  std::size_t queries = 0;                 ///< timed queries (one per series and pose, as reported)
  /// How they were timed (the scene's "timing"): passes over the poses, and the per-pose statistic.
  int timing_repeats = 1;
  std::string timing_statistic = "min";
  /// Every timed sample of every pass, and those that were stalls (bench/pairs/timing_stats.hpp), with the
  /// time they lost beyond their pose's median; context switches forced on the timing thread meanwhile.
  std::size_t timed_samples = 0, stalled_samples = 0;
  double sampled_seconds = 0, stall_lost_seconds = 0;
  long involuntary_switches = 0;
  double preprocess_seconds = 0;
  double truth_seconds = 0;
  double query_seconds = 0;  ///< sum of the timed queries only
  double wall_seconds = 0;
  double clock_overhead_us = 0;      ///< cost of an empty timed region, subtracted from every query time
  std::vector<std::string> skipped;  ///< objects or pairs left out, with the reason
};

/// One row of results.csv.
struct ResultRow {
  std::string mesh;                       ///< the pair's label: "jeep1", or "a|b" for two different objects
  std::string hierarchy, bv, annotation;  ///< annotation: the density's label, "none" or "adb grid=2 tau=0.5"
  std::string strategy;                   ///< a registered strategy's name
  std::string label;           ///< the series: "adb p_min=0.9", "time_critical p_min=0.9 bv_tests=50"
  bool exact_strategy = true;  ///< the strategy is exact (from the strategy table)
  double p_min = -1;           ///< the variant's p_min; < 0: it has none (an empty field)
  std::string budget;          ///< "" or "bv_tests=200" / "deadline_us=20"
  double distance = 0;
  std::size_t queries = 0;
  double truth_colliding_rate = 0, answer_colliding_rate = 0;
  /// Over the per-pose times (each the representative of its warm passes, net of the clock's own cost).
  double mean_time_us = 0, median_time_us = 0, p99_time_us = 0, max_time_us = 0;
  double fp_rate = 0, fn_rate = 0;
  double inexact_rate = 0, budget_exhausted_rate = 0;
  double bv_tests_per_query = 0, triangle_tests_per_query = 0, nodes_visited_per_query = 0;
  double estimates_per_query = 0;  ///< probability evaluations (ADB-type strategies)
  bool in_summary = false;         ///< inside its pair's summary band (bench/pairs/summary_band.hpp)
  /// The per-pose times in pose order, the same poses for every series of the pair and distance: the
  /// report's bootstrap intervals resample them (not written to results.csv).
  std::vector<double> pose_times_us;
  double model_bytes = 0, bytes_per_triangle = 0;  ///< of one object's tree (A's)
  /// Distance series (results with an interval [lower_bound, distance]) against each pose's reference
  /// distance: the first exact distance series of the plan, bvhlab's before FCL's. NaN for other series,
  /// or when the scene runs no exact distance series.
  double distance_error = kNoValue;  ///< max over poses of |distance - reference| / reference (absolute at 0)
  double width_median = kNoValue;    ///< median over poses apart of (distance - lower_bound) / reference
  double width_tenth_rate = kNoValue;  ///< poses apart whose interval is at most a tenth of the reference
  std::size_t interval_misses = 0;     ///< poses whose reference lies outside the interval beyond rounding
  static constexpr double kNoValue = std::numeric_limits<double>::quiet_NaN();
};

/// One probability bin of one ADB-type series, over all its distances.
struct CalibrationBin {
  std::string mesh, hierarchy, strategy, budget;
  double p_min = -1;
  /// The series' probabilities through its calibration map (the scene's "calibration"), not as reported.
  bool calibrated = false;
  double bin_low = 0, bin_high = 0;
  std::size_t count = 0;
  double mean_probability = 0;
  double collision_frequency = 0;  ///< fraction of the bin's queries that truly collide
};

/// One timed query of one series, kept when RunOptions::per_pose asks for it (a row of poses.csv).
struct PoseRecord {
  std::size_t row = 0;               ///< its series and distance: an index into RunOutput::rows
  std::size_t group = 0, index = 0;  ///< its pose: scene.workload.groups[group].poses[index]
  bool truth = false, answer = false;
  bool exact = true, budget_exhausted = false;
  bool has_counters = true;  ///< false for FCL models, which count nothing
  double probability = 0;
  double time_us = 0;  ///< net of the clock's own overhead, as results.csv's mean_time_us averages it
  Counters counters;
};

/// A tree (or FCL model) the run used, with its preprocessing cost.
struct ModelInfo {
  std::string object, hierarchy, bv, annotation;
  TreeUnits units;  ///< the normalisation of the mesh's coordinates, if any
  std::size_t triangles = 0, nodes = 0, depth = 0;
  double model_bytes = 0, bytes_per_triangle = 0;
  double density_bytes = 0;  ///< what the density adds to model_bytes (a strategy without one reads less)
  double wide_bytes = 0;     ///< the wide layout's, when a series walks it (not in model_bytes)
  double build_seconds = 0,
         annotate_seconds = 0;  ///< as measured when it was built (cached trees keep theirs)
  bool from_cache = false;
};

/// Ground truth colliding fraction per (pair, distance), for the cross-check with meshes/README.md.
struct TruthSummary {
  std::string mesh;
  double distance = 0;
  std::size_t poses = 0, colliding = 0;
};

struct Environment {
  std::string machine, compiler, build_type, git_commit, timestamp;
};
Environment detect_environment();

struct RunOutput {
  std::string scene_name;
  std::filesystem::path scene_file;
  Scene scene;
  Environment environment;
  RunStats stats;
  std::vector<ResultRow> rows;
  std::vector<CalibrationBin> calibration;
  std::vector<ModelInfo> models;
  std::vector<TruthSummary> truth;
  /// Where the scene asks a strategy to work outside what it was made for: what to use instead, and why.
  std::vector<std::string> advice;
  PerPose per_pose = PerPose::none;  ///< what `poses` holds
  std::vector<PoseRecord> poses;     ///< in results order: per row, its poses in order
};

/// Runs a parsed scene. Throws for I/O and model errors; an optional object whose mesh is missing is
/// skipped (recorded in stats.skipped).
RunOutput run_scene(const Scene& scene, const RunOptions& options);
/// An object's mesh as a run loads it: normalised (if asked), scaled and placed. Throws MeshError.
Mesh load_scene_object(const SceneObject& object);

/// Queries between two objects, with the trees a scene with this one hierarchy would use (and the same
/// cache).
struct QueryRequest {
  HierarchySpec hierarchy;
  DensitySpec density;  ///< what the trees carry; a strategy that needs a density must accept it
  StrategyVariant strategy;
  int repeat = 0;  ///< warm queries timed after the first one at each pose (0: none)
};
/// One pose's answer: the first query's full result and time (cold: right after the trees were made or the
/// previous pose was answered), then the times of `repeat` more, timed as the runner times its series.
struct PoseAnswer {
  Result result;
  double micros = 0;
  std::vector<double> warm_micros;  ///< each less the clock's own overhead (clamped at 0), as in results.csv
};
struct QueryOutcome {
  std::vector<PoseAnswer> answers;  ///< one per pose, in order
  ModelInfo model_a, model_b;
  RunStats stats;
  /// Where the strategy is not the right tool for these objects: what to use instead, and why.
  std::vector<std::string> advice;
  /// The mesh loader's warnings, each after its object's name ("gear: coordinates are far ...").
  std::vector<std::string> warnings;
};
/// Throws std::invalid_argument for an empty list of poses or a strategy that cannot run on the trees.
QueryOutcome run_query(const SceneObject& a, const SceneObject& b, const QueryRequest& request,
                       std::span<const RigidTransform> poses, const RunOptions& options);
inline QueryOutcome run_query(const SceneObject& a, const SceneObject& b, const QueryRequest& request,
                              const RigidTransform& pose, const RunOptions& options) {
  return run_query(a, b, request, std::span<const RigidTransform>(&pose, 1), options);
}

/// What a saved-tree file's header says about its tree.
struct SavedTreeInfo {
  std::string bv;
  std::string density;     ///< the density's name
  std::string annotation;  ///< its description: "none", "adb grid=2 tau=0.25"
  std::uint64_t nodes = 0, triangles = 0;
  TreeUnits units;
};
/// Reads a saved tree (adb/saved_tree.hpp) and describes it. Throws SavedTreeError naming the file for
/// anything that is not one, or names a BV or density this build does not know.
SavedTreeInfo peek_saved_tree(const std::filesystem::path& file);
/// Whether `file` starts like a saved tree (so the CLI can take trees and meshes alike).
bool is_saved_tree(const std::filesystem::path& file);

/// Queries between two saved trees (no polygons), `repeat` as in QueryRequest. Both must have the same BV and
/// density, the same kind of units (both normalised or both in their files' units), and the strategy must
/// run on them without polygons. Throws std::invalid_argument otherwise.
QueryOutcome run_query_on_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                const StrategyVariant& strategy, std::span<const RigidTransform> poses,
                                int repeat = 0);
inline QueryOutcome run_query_on_trees(const std::filesystem::path& a, const std::filesystem::path& b,
                                       const StrategyVariant& strategy, const RigidTransform& pose) {
  return run_query_on_trees(a, b, strategy, std::span<const RigidTransform>(&pose, 1));
}

/// Builds (and annotates with the density, if any) one object's tree and saves it, without polygons, in the
/// saved-tree format.
struct BuildOutcome {
  ModelInfo model;
  std::uintmax_t file_bytes = 0;
};
BuildOutcome build_tree_file(
    const SceneObject& object, const HierarchySpec& hierarchy, const DensitySpec& density,
    const std::filesystem::path& output, unsigned threads = 0,
    std::function<void(const std::string&)> log = [](const std::string&) {});

}  // namespace bvhlab
