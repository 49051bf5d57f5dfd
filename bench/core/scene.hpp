// A scene file says what one experiment needs: objects, hierarchies, annotation, strategies, workload and
// what the report should single out. Only what it names is built, annotated, loaded and run.
//
// Format (JSON; every field except "objects", "hierarchies" and "strategies" is optional):
//   {
//     "name": "demo",
//     "objects": [ {"mesh": "jeep1.ms3d", "name": "jeep", "optional": false, "normalize": false,
//                   "scale": 1.0, "placement": {"translation": [0,0,0], "axis_angle_deg": [0,0,1, 0]}} ],
//     "pairs": [["jeep", "jeep"]],                  // default: every object against a copy of itself
//     "hierarchies": [ {"bv": "aabb", "name": "aabb", "split": "sah", "max_leaf_triangles": 1},
//                      {"bv": "fcl_obbrss", "optional": true} ],   // optional: skipped if this build lacks
//                      it
//     "annotation": {"type": "adb", "grid": 2, "tau": 0.25},     // or {"type": "none"} (the default)
//     "strategies": [ {"type": "exact"}, {"type": "exact", "coherent": true}, {"type": "guided_exact"},
//                     {"type": "adb", "p_min": [0.5, 0.9]},
//                     {"type": "time_critical", "p_min": 0.9, "budgets": [{"bv_tests": 200}, {"deadline_us":
//                     20}]} ],
//     "workload": {"type": "protocol", "distances": [0.4, 0.6], "steps": 500, "stride": 1}
//              or {"type": "poses", "file": "poses.json"},
//     "calibration": {"training_seed": 2, "training_steps": 500},   // optional: calibrated series too
//     "report": {"quality_distances": [1.2, 2.0], "cgal_sample": 64,
//                "operating_point": {"hierarchy": "aabb", "p_min": 0.9},
//                "baseline": {"hierarchy": "dop24", "strategy": "exact"}}
//   }
// Mesh paths are taken relative to the scene file first, then looked up by file name in the mesh catalog
// (bundled meshes/ and the fetched-mesh cache). Strategies run on every hierarchy they apply to, or on the
// ones listed in their "hierarchies" field. A pose file holds {"poses": [{"translation": [x,y,z],
// "rotation": [[...],[...],[...]] or "axis_angle_deg": [ax,ay,az,deg], "group": d}, ...]}; "group" (default:
// the length of the translation) is the value the report files the pose under in its "distance" column.
// Objects keep their mesh file's units unless "normalize" is true (the protocol normalisation, which the
// protocol's distances assume).
//
// A pose list (`bvhlab query --poses FILE`) is plain text: one pose per line as pose_from_numbers takes it,
// numbers separated by blanks or commas; blank lines and lines starting with '#' are skipped.
#pragma once

#include "adb/parameters.hpp"
#include "bench/run_scene.hpp"  // SceneError
#include "bvh/topology.hpp"
#include "engine/specs.hpp"
#include "traversal/budget.hpp"
#include "volumes/geometry.hpp"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

struct SceneObject {
  std::string name;            ///< label in reports; default: the mesh file's stem
  std::string mesh;            ///< as written in the scene
  std::filesystem::path path;  ///< resolved file; empty when not found (then `optional` must be true)
  bool optional = false;       ///< a missing mesh skips the object (with a message) instead of failing
  bool normalize = false;      ///< the protocol normalisation: centre to origin, longest side 2
  double scale = 1;            ///< uniform scale applied after normalisation
  RigidTransform placement;    ///< applied to the vertices after scaling
};

/// Two objects queried against each other: A stays put, B moves by the workload's poses.
struct ScenePair {
  std::string a, b;  ///< object names
  [[nodiscard]] std::string label() const { return a == b ? a : a + "|" + b; }
};

/// Poses filed under one value of the report's "distance" column.
struct PoseGroup {
  double distance = 0;
  std::vector<RigidTransform> poses;
};

struct WorkloadSpec {
  enum class Kind { Protocol, PoseFile, Random } kind = Kind::Protocol;
  /// What the report's "distance" column holds: the protocol's distance, the separation of the two objects
  /// (their centre distance over the sum of their bounding radii, binned: random and pose-file workloads by
  /// default), or a pose file's own groups.
  enum class Axis { Distance, Separation, Group } axis = Axis::Distance;
  std::vector<double> distances{0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0};
  int steps = 5000;
  /// Protocol only: every stride-th step of the steps' full turn (how far B turns between two queries of a
  /// coherent strategy).
  int stride = 1;
  std::filesystem::path pose_file;  ///< PoseFile only (resolved)
  /// Random only: how many poses, the seed, and the box B's translation is drawn from.
  int count = 0;
  std::uint64_t seed = 0;
  Vec3 box_min = Vec3::Zero(), box_max = Vec3::Zero();
  std::vector<PoseGroup> groups;  ///< the poses, generated or read while parsing
  /// Identifies the pose set for the ground-truth cache (protocol parameters or the file's content hash).
  std::string identity;
};

struct ReportSpec {
  double quality_min = 0, quality_max = 0;  ///< distances the time-versus-quality summary uses, if given
  /// Given in the scene. When not, each mesh pair is summarised over the band of distances where its ground
  /// truth has between 5% and 95% colliding poses, found from the run (bench/pairs/summary_band.hpp).
  bool quality_given = false;
  int cgal_sample = 64;                     ///< poses per object pair cross-checked against CGAL
  std::string operating_hierarchy;          ///< default: the first hierarchy the operating strategy runs on
  double operating_p_min = -1;              ///< default: the largest p_min <= 0.9, else the largest
  std::string operating_strategy;           ///< default: the first inexact strategy with a p_min
  std::string baseline_hierarchy;           ///< default: dop24 if present, else the first hierarchy
  std::string baseline_strategy = "exact";  ///< an exact strategy
};

/// "calibration": every inexact series is first run on a training pose set drawn from `training_seed`,
/// disjoint from the workload's poses, and a monotone map (adb/calibration.hpp) fitted from its answers
/// against the exact truth; the report then shows each series' test probabilities raw and through its map.
struct CalibrationSpec {
  std::uint64_t training_seed = 0;
  int training_steps = 0;  ///< per protocol distance, or in all for a random workload
  /// The training poses, drawn while parsing: a protocol workload's distances with the turn angle drawn
  /// uniformly (R_z(t) R_x(t) as the protocol's steps), or a random workload's box from the training seed.
  WorkloadSpec training;
};

/// One placed copy of a scene object in a world scene. Copies of one object share its trees.
struct WorldInstance {
  std::string name;    ///< "jeep#3" (the object's name and its copy number), or as given
  std::string object;  ///< a scene object's name
};

/// One entry of "frame_budgets": schedules that share one budget across a frame's candidate pairs.
struct FrameBudgetSpec {
  std::vector<std::string> schedules;    ///< schedule policies, by name
  std::vector<Budget> budgets;           ///< one run per budget (BV tests and/or microseconds per frame)
  double p_min = 0.9;                    ///< a pair whose estimate reaches it is decided colliding
  int confirm_levels = 0;                ///< AdbOptions::confirm_levels of every pair (0: the paper's rule)
  std::string order = "best_first";      ///< each pair's traversal order (frame_order: FrameOptions::order)
  bool memory = false;                   ///< frame-to-frame fronts (FrameMemory) across the frames
  std::vector<std::string> hierarchies;  ///< where it runs: as given, else each with a probability density
  [[nodiscard]] bool applies_to(const HierarchySpec& h) const {
    return hierarchies.empty() ||
           std::find(hierarchies.begin(), hierarchies.end(), h.name) != hierarchies.end();
  }
};

/// Many objects moving over frames ("world" in the file; format: bench/scenes/README.md).
struct WorldSpec {
  std::vector<WorldInstance> instances;
  Box region;              ///< where random placements start and random walks stay (reflected at its faces)
  int frames = 0;          ///< how many frames
  std::uint64_t seed = 0;  ///< random placement and walk
  double step = 0;         ///< random walk: largest move per axis and frame, in scene units
  double turn_deg = 0;     ///< random walk: largest turn per axis and frame, in degrees
  std::filesystem::path frame_file;  ///< a pose per instance and frame, in place of the random walk
  /// poses[f][i]: instance i's pose in frame f, generated or read while parsing.
  std::vector<std::vector<RigidTransform>> poses;
  std::vector<std::string> broad_phases;  ///< by name; default: every registered one
  std::vector<FrameBudgetSpec> frame_budgets;
  /// Object counts at which the broad phases are also timed alone (the scene's objects copied to that many
  /// instances at the scene's density); empty: none.
  std::vector<int> scaling;
  /// Identifies the instances and their motion for the ground-truth cache.
  std::string identity;
};

/// A deforming object against a rigid one over frames ("deform" in the file; format: bench/scenes/README.md).
struct DeformSpec {
  std::string object;       ///< the deforming scene object (A)
  std::string other;        ///< the rigid scene object B; default: a rigid copy of A at rest
  std::string deformation;  ///< a procedural deformation (bvh/deform.hpp parse_deformation); or frame files
  std::vector<std::filesystem::path> frame_files;  ///< one mesh per frame, all of one topology
  int frames = 0;                                  ///< procedural: frames over one period
  std::vector<PoseGroup> poses;                    ///< B's poses against A, the same in every frame
  bool refit_by_fit = false;                       ///< refit by fitting every node (else by merging)
  double rebuild_degradation = 2.0;                ///< refit trees past it are rebuilt (Bvh::degradation)
  std::vector<DensityUpdateSpec> density_updates;  ///< for the hierarchies with an ADB density
};

/// Point clouds sampled from each pair's meshes, B tumbling about A on the protocol ("points" in the file;
/// format: bench/scenes/README.md; the series and the measuring: bench/points/points.hpp).
struct PointsSpec {
  std::vector<double> densities{5000, 20000};  ///< points per cloud (whole numbers), one cloud per value
  std::uint64_t seed = 1;                      ///< sampling seed (B's cloud of another object: seed + 1)
  bool varying = false;                        ///< sample_varying with k-NN areas, else sample_uniform
  double ratio = 4;                            ///< varying: the density ratio along the longest axis
  std::vector<double> distances{0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0};
  int steps = 200;          ///< protocol poses per distance
  double band = 1;          ///< the ambiguous band, in point spacings
  std::uint32_t leaf = 16;  ///< points per leaf
  int grid = 2;             ///< the ADB grid of the clouds' trees
  std::vector<double> p_mins{0.5, 0.7, 0.9, 0.95, 0.99};
  std::vector<double> confirm_levels;             ///< ADB with AdbOptions::confirm_levels: one series per
  std::vector<double> confirm_p_mins{0.9, 0.99};  ///< level and p_min here (none without levels)
  std::vector<double> bv_tests{50, 200};          ///< time-critical series: BV-test caps at p_min 0.9
  std::vector<double> octree_res;                 ///< FCL octree voxel sides in spacings (FCL builds only)
  int cgal_sample = 16;                           ///< poses per pair whose mesh truth is checked against CGAL
};

/// How each (series, pose) is timed ("timing" in the file): `repeats` warm passes over the poses, each pose
/// timed once per pass, reduced to one time per pose by `statistic` (bench/pairs/timing_stats.hpp).
struct TimingSpec {
  enum class Statistic { Median, Min } statistic = Statistic::Min;
  int repeats = 3;
};
const char* statistic_name(TimingSpec::Statistic statistic);

/// Empty when `s` runs on the FCL hierarchy of volume `fcl_bv`: exact first contact on both, distance on
/// fcl_obbrss (FCL's OBB has no distance), never coherent; else the one message every caller gives.
std::string fcl_refusal(const StrategySpec& s, std::string_view fcl_bv);

struct Scene {
  std::string name;
  std::filesystem::path file;  ///< where it was read from (empty for a string)
  std::vector<SceneObject> objects;
  std::vector<ScenePair> pairs;
  std::vector<HierarchySpec> hierarchies;
  DensitySpec density;
  std::vector<StrategySpec> strategies;
  WorkloadSpec workload;
  ReportSpec report;
  TimingSpec timing;
  std::optional<CalibrationSpec> calibration;
  /// Set for a world scene: many instances over frames, in place of "pairs" and "workload".
  std::optional<WorldSpec> world;
  /// Set for a deform scene: one deforming object against a rigid one, in place of "pairs" and "workload".
  std::optional<DeformSpec> deform;
  /// Set for a points scene: clouds sampled from each pair's meshes, in place of the strategies and workload.
  std::optional<PointsSpec> points;
  /// What the parser left out on purpose (an optional hierarchy this build cannot provide), for the report.
  std::vector<std::string> notes;

  [[nodiscard]] const SceneObject* object(std::string_view name) const;
  [[nodiscard]] const HierarchySpec* hierarchy(std::string_view name) const;
  /// Whether strategy `s` runs on hierarchy `h` (an FCL hierarchy only takes exact).
  [[nodiscard]] bool applies(const StrategySpec& s, const HierarchySpec& h) const;
  /// The density `h`'s trees carry when a strategy on them needs one: its own, else the scene's.
  [[nodiscard]] const DensitySpec& density_of(const HierarchySpec& h) const;
  /// Whether any strategy on `h` needs a density: only then are `h`'s trees annotated.
  [[nodiscard]] bool needs_density(const HierarchySpec& h) const;
};

/// Ranges of the workload's and the budgets' values, checked against these by the scene parser and the CLI
/// alike (the policies' own parameters have theirs in the policy tables).
namespace limits {
inline constexpr ParamSpec kDistance{
    .name = "distance", .description = "protocol distance", .min = 0, .max = 1e6};
inline constexpr ParamSpec kSteps{
    .name = "steps", .description = "protocol poses per distance", .min = 1, .max = 1e7, .integer = true};
/// Poses a scene generates in all (a protocol's distances times its steps over the stride, a random count, a
/// training set): 20 times the largest shipped scene, and a bound on the parser's memory and time.
inline constexpr ParamSpec kPoses{
    .name = "poses", .description = "poses a scene generates", .min = 1, .max = 1e6, .integer = true};
inline constexpr ParamSpec kBvTests{.name = "bv_tests",
                                    .description = "budget of BV-pair tests",
                                    .min = 1,
                                    .max = 1099511627776.0,  // 2^40
                                    .integer = true};
inline constexpr ParamSpec kDeadlineUs{.name = "deadline_us",
                                       .description = "deadline in microseconds",
                                       .min = 0,
                                       .max = 1e9,
                                       .exclusive_min = true};
}  // namespace limits

/// A pose from numbers: TX TY TZ (a translation), TX TY TZ AX AY AZ DEGREES (and a rotation by DEGREES
/// about the axis), or the 3 x 4 matrix [R | t] row by row (12 numbers; R orthonormal within 1e-6, det +1).
/// Throws std::invalid_argument naming the problem.
RigidTransform pose_from_numbers(std::span<const double> numbers);

/// One pose of a pose list, and the line it was read from (1-based).
struct ListedPose {
  RigidTransform pose;
  std::size_t line = 0;
};
/// Parses a pose list (format above). Throws SceneError "SOURCE:LINE: problem" for a malformed line, and for
/// a list without poses.
std::vector<ListedPose> parse_pose_list(std::string_view text, const std::string& source);
/// Reads a pose list file. Throws SceneError naming the file (and the line).
std::vector<ListedPose> load_pose_list(const std::filesystem::path& file);

/// Names a scene may use for "bv": the registered volumes, then fcl_obb and fcl_obbrss.
std::vector<std::string> hierarchy_bv_names();

/// Parses and checks a scene. Relative paths resolve against `base_dir`. Throws SceneError.
Scene parse_scene(std::string_view json_text, const std::filesystem::path& base_dir,
                  std::string_view source_name = "<scene>");
/// Reads a scene file; paths resolve against its folder. Throws SceneError (also for an unreadable file).
Scene load_scene(const std::filesystem::path& file);

/// Reads an explicit pose file (format above). Throws SceneError naming the file and the JSON path.
std::vector<PoseGroup> load_pose_file(const std::filesystem::path& file);

}  // namespace bvhlab
