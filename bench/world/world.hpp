// The world runner: a scene of many instances moving over frames (scene "world"). Per frame and hierarchy:
// the world box of every instance from its tree's root, each broad phase's candidate pairs (timed; all must
// agree), the exact answer on every candidate pair (the ground truth: a pair the broad phase leaves out is
// apart), then every per-pair strategy on every candidate pair and every frame budget shared across them,
// each counted against the truth in pairs: missed (false negatives) and false (false positives). Where FCL
// is built (BVHLAB_HAVE_FCL), FCL's broad-phase managers and narrow phase run on the same instances and
// poses each frame, as rows of the hierarchy kFclWorldHierarchy, and must find the same colliding pairs.
#pragma once

#include "bench/core/scene.hpp"
#include "bench/report_folder.hpp"
#include "bench/run.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// The hierarchy of FCL's rows in a world run: one OBBRSS model per object, in FCL's dynamic AABB tree and
/// SaP managers (broad phases "fcl_dynamic_aabb_tree", "fcl_sap") and FCL's narrow phase (series "exact").
inline constexpr std::string_view kFclWorldHierarchy = "fcl_obbrss";

/// One frame of one series on one hierarchy.
struct WorldSeriesRow {
  int frame = 0;
  std::string hierarchy;
  std::string series;                 ///< "exact", "adb p_min=0.9", "frame adb_probability bv_tests=2000"
  std::string schedule;               ///< the frame-budget policy; empty for a per-pair strategy
  std::string budget;                 ///< the frame's budget ("bv_tests=2000"); empty for a per-pair strategy
  std::uint64_t budget_bv_tests = 0;  ///< the frame's cap of BV tests (0: none)
  double budget_deadline_us = 0;      ///< the frame's deadline (0: none)
  bool exact_strategy = false;
  std::size_t candidates = 0;   ///< candidate pairs of the frame (the broad phase's answer)
  std::size_t colliding = 0;    ///< of those, colliding in truth
  std::size_t answered = 0;     ///< of those, answered colliding
  std::size_t missed = 0;       ///< colliding, answered apart
  std::size_t false_pairs = 0;  ///< apart, answered colliding
  std::size_t flagged = 0;      ///< answered as a best effort (budget ran out)
  std::size_t untested = 0;     ///< under a frame budget: pairs the budget left without their root test
  std::size_t untested_colliding = 0;  ///< of those, colliding in truth
  double micros = 0;                   ///< narrow phase of the frame: every candidate pair
  std::uint64_t bv_tests = 0;
};

/// One candidate pair's answer in one frame, kept when RunOptions::per_pose asks for it (a row of
/// world_pairs.csv): every answer ("all") or the wrong ones ("wrong"), of the per-pair strategies and the
/// frame budgets on the scene's hierarchies (not FCL's).
struct WorldPairRow {
  int frame = 0;
  std::string hierarchy;
  std::string series;      ///< as in WorldSeriesRow
  std::string a, b;        ///< the instances' names
  bool truth = false;      ///< the exact answer
  bool collides = false;   ///< the series' answer
  bool flagged = false;    ///< a best effort (budget ran out)
  double probability = 0;  ///< the estimate it decided on (1 or 0 when exact)
  double micros = -1;      ///< the pair's query alone; -1 under a frame budget (timed as a whole frame)
  std::uint64_t bv_tests = 0;
};

/// One frame of one broad phase on one hierarchy's world boxes.
struct BroadPhaseRow {
  int frame = 0;
  std::string hierarchy, broad_phase;
  std::size_t objects = 0, candidates = 0;
  double boxes_micros = 0;   ///< the world boxes of every instance (shared by the broad phases); for FCL's
                             ///< managers, setTransform and computeAABB of every object
  double update_micros = 0;  ///< update plus pair finding (FCL: the manager's update or, in frame 0, its
                             ///< registration, then its all-pairs collide collecting the pairs)
};

/// A broad phase alone at one object count (WorldSpec::scaling): medians over the frames.
struct ScalingRow {
  std::string hierarchy, broad_phase;
  std::size_t objects = 0, candidates = 0;
  double boxes_micros = 0, update_micros = 0;
};

struct WorldOutput {
  std::string scene;
  std::size_t instances = 0;
  int frames = 0;
  std::vector<WorldSeriesRow> series;
  std::vector<WorldPairRow> pairs;  ///< per RunOptions::per_pose (none: empty)
  PerPose per_pose = PerPose::none;
  std::vector<BroadPhaseRow> broad;
  std::vector<ScalingRow> scaling;
  std::vector<ModelInfo> models;
  RunStats stats;
  /// "The right tool" (bench/pairs/advice.hpp): frame budgets too small to give every candidate pair its root
  /// test.
  std::vector<std::string> advice;
};

/// Runs a world scene (scene.world set). Throws std::invalid_argument for a scene without one.
WorldOutput run_world(const Scene& scene, const RunOptions& options);

/// world_frames.csv, world_broad_phase.csv and world_scaling.csv in `dir` (columns: the rows' fields), and
/// world_pairs.csv when the run kept pair rows (per_pose all or wrong).
void write_world_csv(const WorldOutput& output, const std::filesystem::path& dir);

/// The rows as JSON (Python's run_scene on a world scene): {"scene", "instances", "frames", "series": [...],
/// "broad_phase": [...], "scaling": [...]}, and "pairs": [...] when the run kept pair rows; each row keyed
/// like its CSV columns.
nlohmann::json world_document(const WorldOutput& output);

/// What its report folder holds (write_report_folder, bench/report_folder.hpp): the CSV files, its figures,
/// the README. `output` must outlive it.
ReportFolder world_report_folder(const WorldOutput& output);

/// The README of a world report: per series the pairs missed and false (percent of colliding and of apart
/// candidate pairs), median and 90th-percentile frame times; per broad phase the median frame time.
std::string world_readme(const WorldOutput& output, const std::vector<std::string>& figures = {});

}  // namespace bvhlab
