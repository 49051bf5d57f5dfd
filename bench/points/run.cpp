// The points runner (bench/points/points.hpp): clouds from each pair's meshes, the mesh truth with its
// ambiguous band, and every series timed over the same poses. Every query runs through the run-time layer
// (engine/any_tree.hpp), which compiles each strategy once for the CLI, Python and every runner.
#include "bench/points/points.hpp"

#include "bench/core/ground_truth.hpp"
#include "bench/pairs/measure.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/report_tables.hpp"
#include "bvh/point_cloud.hpp"
#include "engine/any_tree.hpp"
#include "engine/protocol.hpp"
#include "engine/specs.hpp"

#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_octree.hpp"
#endif

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <span>

namespace bvhlab {

namespace {

/// One protocol pose with the meshes' answer and whether the band makes it ambiguous.
struct TruthPose {
  std::size_t group = 0;  ///< index into PointsSpec::distances
  bool truth = false, ambiguous = false;
};

bool collides(const PreparedQuery& query, const RigidTransform& pose) {
  bool answer = false;
  query.run(std::span(&pose, 1), [&](std::size_t, const Result& r) { answer = r.collides; });
  return answer;
}

/// The poses of every distance in order, and each one's truth from the meshes' exact query; ambiguous where
/// B moved by `shift` along an axis, either way, changes the answer.
std::vector<TruthPose> mesh_truth(const PreparedQuery& exact, const std::vector<RigidTransform>& poses,
                                  const std::vector<std::size_t>& groups, double shift) {
  std::vector<TruthPose> out;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    TruthPose t{groups[k], collides(exact, poses[k]), false};
    for (int axis = 0; axis < 3 && !t.ambiguous; ++axis)
      for (double sign : {-1.0, 1.0}) {
        RigidTransform moved = poses[k];
        moved.translation[axis] += sign * shift;
        t.ambiguous = t.ambiguous || collides(exact, moved) != t.truth;
      }
    out.push_back(t);
  }
  return out;
}

/// A cloud sampled from a mesh, in the mesh's units, and its AABB tree with ADB counts from the points'
/// areas: one side of a point query. The tree holds the cloud's surface and sphere coverings.
struct Cloud {
  UnitCloud points;  ///< FCL's octrees and the plain tree are built from them
  AnyTree tree;
  double spacing = 0;
};

/// The cloud's tree with `density` ("none" or "adb" at the scene's grid).
AnyTree cloud_tree(const UnitCloud& cloud, const std::string& density, const PointsSpec& spec) {
  BuildOptions options;
  options.max_leaf_points = spec.leaf;
  const ParamValues grid{{"grid", spec.grid}};
  return AnyTree::build_points(cloud, "aabb", density_spec(density, density == "adb" ? grid : ParamValues{}),
                               options);
}

Cloud make_cloud(const Mesh& mesh, const MeshUnits& units, std::size_t n, const PointsSpec& spec) {
  UnitCloud points;
  if (spec.varying) {
    static_cast<PointCloud&>(points) = sample_varying(mesh, n, spec.seed, spec.ratio);
    assign_knn_areas(points, 10);
  } else {
    static_cast<PointCloud&>(points) = sample_uniform(mesh, n, spec.seed);
  }
  points.units = units;
  AnyTree tree = cloud_tree(points, "adb", spec);
  const double spacing = std::sqrt(surface_area(mesh) / static_cast<double>(n));
  return Cloud{std::move(points), std::move(tree), spacing};
}

/// The rows of one series: per distance, then the total; errors on the clear poses only.
class RowMaker {
 public:
  RowMaker(const PointsRow& head, const PointsSpec& spec, const std::vector<TruthPose>& truth,
           double overhead)
      : head_(head), spec_(spec), truth_(truth), overhead_(overhead) {}

  void add(const std::string& series, const std::vector<QueryRecord>& records, PointsOutput& out) const {
    for (std::size_t g = 0; g < spec_.distances.size(); ++g)
      out.rows.push_back(row(series, records, static_cast<long>(g)));
    out.totals.push_back(row(series, records, -1));
  }

 private:
  PointsRow row(const std::string& series, const std::vector<QueryRecord>& records, long group) const {
    PointsRow r = head_;
    r.series = series;
    r.distance = group < 0 ? -1 : spec_.distances[static_cast<std::size_t>(group)];
    std::vector<double> micros;
    for (std::size_t k = 0; k < records.size(); ++k) {
      const TruthPose& t = truth_[k];
      if (group >= 0 && t.group != static_cast<std::size_t>(group)) continue;
      micros.push_back(net_micros(records[k].micros, overhead_));
      ++r.poses;
      if (t.ambiguous) {
        ++r.ambiguous;
        continue;
      }
      ++r.clear;
      r.colliding += t.truth;
      r.fp += records[k].collides && !t.truth;
      r.fn += !records[k].collides && t.truth;
    }
    for (double m : micros) r.mean_us += m;
    r.mean_us /= static_cast<double>(std::max<std::size_t>(micros.size(), 1));
    r.median_us = report_tables::median(std::move(micros));
    return r;
  }

  PointsRow head_;
  const PointsSpec& spec_;
  const std::vector<TruthPose>& truth_;
  double overhead_;
};

/// Times one series over every pose after a warm pass over all of them (FCL's octrees).
template <class Query>
std::vector<QueryRecord> timed(const std::vector<RigidTransform>& poses, Query&& query) {
  std::vector<QueryRecord> records;
  timed_series(poses, static_cast<int>(poses.size()), records, query);
  return records;
}

/// Times `variant` with `a` fixed and `b` moved over every pose, after a warm pass over all of them.
std::vector<QueryRecord> timed(const std::vector<RigidTransform>& poses, const AnyTree& a, const AnyTree& b,
                               const StrategyVariant& variant) {
  std::vector<QueryRecord> records;
  a.prepare(b, variant)->time(poses, static_cast<int>(poses.size()), records);
  return records;
}

/// FCL's octree series, one per resolution (none without FCL).
void add_octree_series([[maybe_unused]] const Cloud& a, [[maybe_unused]] const Cloud& b,
                       [[maybe_unused]] double spacing, [[maybe_unused]] const PointsSpec& spec,
                       [[maybe_unused]] const std::vector<RigidTransform>& poses,
                       [[maybe_unused]] const RowMaker& rows, [[maybe_unused]] PointsCloudInfo& info,
                       [[maybe_unused]] PointsOutput& out) {
#ifdef BVHLAB_HAVE_FCL
  for (double factor : spec.octree_res) {
    const double res = factor * spacing;
    const auto start = Clock::now();
    const auto octree_a = make_fcl_octree(a.points, res);
    const auto octree_b = &a == &b ? octree_a : make_fcl_octree(b.points, res);
    info.octrees.push_back(
        fmt::format("res {:.4f} ({:g} spacings): {} occupied voxels in A, built in {:.1f} ms", res, factor,
                    octree_a->toBoxes().size(), micros_since(start) / 1000));
    FclOctreePair pair(octree_a, octree_b);
    rows.add(fmt::format("fcl_octree res={:g}", factor),
             timed(poses,
                   [&](const RigidTransform& pose) {
                     Result r;
                     r.collides = pair.collides(pose);
                     return r;
                   }),
             out);
  }
#endif
}

/// CGAL's answer against the mesh truth on up to `sample` poses spread over the list.
void cross_check(const Mesh& a, const Mesh& b, const std::vector<RigidTransform>& poses,
                 const std::vector<TruthPose>& truth, int sample, PointsOutput& out) {
  if (sample <= 0 || poses.empty()) return;
  const CgalGroundTruth cgal(a, b);
  const std::size_t n = std::min<std::size_t>(static_cast<std::size_t>(sample), poses.size());
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = i * poses.size() / n;
    ++out.cgal_checked;
    out.cgal_mismatches += cgal.collides(poses[k]) != truth[k].truth;
  }
}

/// The poses of every distance in order, and the index of each one's distance.
std::vector<RigidTransform> points_poses(const PointsSpec& spec, std::vector<std::size_t>& groups) {
  std::vector<RigidTransform> poses;
  for (std::size_t g = 0; g < spec.distances.size(); ++g)
    for (const RigidTransform& pose : protocol_poses(spec.distances[g], spec.steps)) {
      poses.push_back(pose);
      groups.push_back(g);
    }
  return poses;
}

/// One object of a pair: its mesh, the mesh's plain AABB tree and its units.
struct MeshSide {
  const Mesh& mesh;
  const AnyTree& tree;
  MeshUnits units;
};

/// The ADB and time-critical series on the clouds.
void add_adb_series(const Cloud& a, const Cloud& b, const PointsSpec& spec,
                    const std::vector<RigidTransform>& poses, const RowMaker& rows, PointsOutput& out) {
  for (double p_min : spec.p_mins)
    rows.add(fmt::format("adb p_min={:g}", p_min),
             timed(poses, a.tree, b.tree, strategy_variant("adb", {{"p_min", p_min}}, {})), out);
  for (double levels : spec.confirm_levels)
    for (double p_min : spec.confirm_p_mins)
      rows.add(fmt::format("adb p_min={:g} confirm_levels={:g}", p_min, levels),
               timed(poses, a.tree, b.tree,
                     strategy_variant("adb", {{"p_min", p_min}, {"confirm_levels", levels}}, {})),
               out);
  for (double bv_tests : spec.bv_tests) {
    // p_min 0.9; on exhaustion, "collision" iff the best queued estimate >= 0.5
    const StrategyVariant capped =
        strategy_variant("time_critical", {}, Budget{static_cast<std::uint64_t>(bv_tests), 0});
    rows.add(fmt::format("time_critical p_min={:g} bv_tests={:g}", capped.value_or("p_min", 0), bv_tests),
             timed(poses, a.tree, b.tree, capped), out);
  }
}

/// Every series of one pair at one density.
void run_density(const MeshSide& mesh_a, const MeshSide& mesh_b, bool same, std::size_t n,
                 const PointsSpec& spec, PointsCloudInfo info, PointsOutput& out, bool quiet) {
  const Cloud a = make_cloud(mesh_a.mesh, mesh_a.units, n, spec);
  const std::optional<Cloud> b =
      same ? std::nullopt : std::optional<Cloud>(make_cloud(mesh_b.mesh, mesh_b.units, n, spec));
  const Cloud& cb = same ? a : *b;
  info.points = n;
  info.spacing = std::max(a.spacing, cb.spacing);
  info.band = spec.band * info.spacing;
  std::vector<std::size_t> groups;
  const std::vector<RigidTransform> poses = points_poses(spec, groups);
  const StrategyVariant exact = strategy_variant("exact", {}, {});
  const std::vector<TruthPose> truth =
      mesh_truth(*mesh_a.tree.prepare(mesh_b.tree, exact), poses, groups, info.band);
  cross_check(mesh_a.mesh, mesh_b.mesh, poses, truth, spec.cgal_sample, out);
  PointsRow head;
  head.pair = info.pair;
  head.points = n;
  head.spacing = info.spacing;
  const RowMaker rows(head, spec, truth, clock_overhead_us());
  rows.add("exact_mesh", timed(poses, mesh_a.tree, mesh_b.tree, exact), out);
  rows.add("exact_points", timed(poses, a.tree, cb.tree, exact), out);
  // The mesh's tree carries no density, so A's cloud is queried through a plain tree of the same shape.
  const AnyTree plain_a = cloud_tree(a.points, "none", spec);
  rows.add("exact_points_vs_mesh", timed(poses, plain_a, mesh_b.tree, exact), out);
  add_adb_series(a, cb, spec, poses, rows, out);
  add_octree_series(a, cb, info.spacing, spec, poses, rows, info, out);
  if (!quiet)
    std::fprintf(stderr, "bvhlab: %s at %zu points: %zu poses measured\n", info.pair.c_str(), n,
                 poses.size());
  out.clouds.push_back(std::move(info));
}

}  // namespace

double PointsRow::error_percent() const {
  return clear ? 100.0 * static_cast<double>(fp + fn) / static_cast<double>(clear) : 0.0;
}

bool is_inexact_series(const std::string& series) {
  return series.rfind("adb", 0) == 0 || series.rfind("time_critical", 0) == 0;
}

PointsOutput run_points(const Scene& scene, bool quiet) {
  if (!scene.points) throw std::invalid_argument("run_points: scene " + scene.name + " has no \"points\"");
  const PointsSpec& spec = *scene.points;
  PointsOutput out;
  out.scene = scene.name;
  out.steps = spec.steps;
  out.notes = scene.notes;
  for (const ScenePair& pair : scene.pairs) {
    const SceneObject &oa = *scene.object(pair.a), &ob = *scene.object(pair.b);
    if (oa.path.empty() || ob.path.empty()) {
      out.notes.push_back("pair " + pair.label() + " skipped: its mesh is not available (meshes/fetch.sh)");
      continue;
    }
    const ObjectData object_a = load_object(oa);
    const ObjectData object_b = pair.a == pair.b ? object_a : load_object(ob);
    const MeshUnits units_a{object_a.units, 1}, units_b{object_b.units, 1};
    const AnyTree tree_a = AnyTree::build(object_a.mesh, units_a, "aabb", {}, {});
    const AnyTree tree_b = pair.a == pair.b ? tree_a : AnyTree::build(object_b.mesh, units_b, "aabb", {}, {});
    PointsCloudInfo info;
    info.pair = pair.label();
    info.triangles_a = object_a.mesh.triangles.size();
    info.triangles_b = object_b.mesh.triangles.size();
    for (double n : spec.densities)
      run_density({object_a.mesh, tree_a, units_a}, {object_b.mesh, tree_b, units_b}, pair.a == pair.b,
                  static_cast<std::size_t>(n), spec, info, out, quiet);
  }
  return out;
}

}  // namespace bvhlab
