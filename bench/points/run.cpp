// The points runner (bench/points/points.hpp): clouds from each pair's meshes, the mesh truth with its
// ambiguous band, and every series timed over the same poses.
#include "bench/points/points.hpp"

#include "adb/point_density.hpp"
#include "bench/core/ground_truth.hpp"
#include "bench/pairs/measure.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/report_tables.hpp"
#include "bvh/point_surface.hpp"
#include "engine/protocol.hpp"
#include "traversal/point_leaves.hpp"
#include "volumes/aabb.hpp"

#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_octree.hpp"
#endif

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace bvhlab {

namespace {

/// One protocol pose with the meshes' answer and whether the band makes it ambiguous.
struct TruthPose {
  std::size_t group = 0;  ///< index into PointsSpec::distances
  bool truth = false, ambiguous = false;
};

/// The poses of every distance in order, and each one's truth; ambiguous where B moved by `shift` along an
/// axis, either way, changes the answer.
std::vector<TruthPose> mesh_truth(const Bvh<Aabb>& a, const Bvh<Aabb>& b,
                                  const std::vector<RigidTransform>& poses,
                                  const std::vector<std::size_t>& groups, double shift) {
  std::vector<TruthPose> out;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    TruthPose t{groups[k], query_exact(a, b, poses[k]).collides, false};
    for (int axis = 0; axis < 3 && !t.ambiguous; ++axis)
      for (double sign : {-1.0, 1.0}) {
        RigidTransform moved = poses[k];
        moved.translation[axis] += sign * shift;
        t.ambiguous = t.ambiguous || query_exact(a, b, moved).collides != t.truth;
      }
    out.push_back(t);
  }
  return out;
}

/// A cloud sampled from a mesh, its surface, and its ADB tree with the coverings: one side of a point query.
/// Held by pointer: the side refers to the surface and the coverings.
struct Cloud {
  PointCloud points;
  std::unique_ptr<PointSurface> surface;
  Tree<Aabb, AdbDensity> tree;
  std::vector<SphereCovering> coverings;
  double spacing = 0;

  [[nodiscard]] SurfaceSide side() const { return cloud_side(*surface, coverings); }
};

std::unique_ptr<Cloud> make_cloud(const Mesh& mesh, std::size_t n, const PointsSpec& spec) {
  auto cloud = std::make_unique<Cloud>();
  if (spec.varying) {
    cloud->points = sample_varying(mesh, n, spec.seed, spec.ratio);
    assign_knn_areas(cloud->points, 10);
  } else {
    cloud->points = sample_uniform(mesh, n, spec.seed);
  }
  cloud->surface = std::make_unique<PointSurface>(cloud->points);
  BuildOptions options;
  options.max_leaf_points = spec.leaf;
  cloud->tree = annotate_adb_points(Bvh<Aabb>::build(cloud->points, options), cloud->points, spec.grid);
  cloud->coverings = sphere_coverings(cloud->tree.bvh, *cloud->surface);
  cloud->spacing = std::sqrt(surface_area(mesh) / static_cast<double>(n));
  return cloud;
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

/// Times one series over every pose after a warm pass over all of them.
template <class Query>
std::vector<QueryRecord> timed(const std::vector<RigidTransform>& poses, Query&& query) {
  std::vector<QueryRecord> records;
  timed_series(poses, static_cast<int>(poses.size()), records, query);
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

/// Every series of one pair at one density.
void run_density(const Mesh& mesh_a, const Mesh& mesh_b, const Bvh<Aabb>& tree_a, const Bvh<Aabb>& tree_b,
                 bool same, std::size_t n, const PointsSpec& spec, PointsCloudInfo info, PointsOutput& out,
                 bool quiet) {
  const std::unique_ptr<Cloud> a = make_cloud(mesh_a, n, spec);
  const std::unique_ptr<Cloud> b = same ? nullptr : make_cloud(mesh_b, n, spec);
  const Cloud& cb = same ? *a : *b;
  info.points = n;
  info.spacing = std::max(a->spacing, cb.spacing);
  info.band = spec.band * info.spacing;
  std::vector<RigidTransform> poses;
  std::vector<std::size_t> groups;
  for (std::size_t g = 0; g < spec.distances.size(); ++g)
    for (const RigidTransform& pose : protocol_poses(spec.distances[g], spec.steps)) {
      poses.push_back(pose);
      groups.push_back(g);
    }
  const std::vector<TruthPose> truth = mesh_truth(tree_a, tree_b, poses, groups, info.band);
  cross_check(mesh_a, mesh_b, poses, truth, spec.cgal_sample, out);
  PointsRow head;
  head.pair = info.pair;
  head.points = n;
  head.spacing = info.spacing;
  const RowMaker rows(head, spec, truth, clock_overhead_us());
  rows.add("exact_mesh",
           timed(poses, [&](const RigidTransform& p) { return query_exact(tree_a, tree_b, p); }), out);
  rows.add("exact_points",
           timed(poses,
                 [&](const RigidTransform& p) {
                   return query_exact_points(a->tree.bvh, a->side(), cb.tree.bvh, cb.side(), p);
                 }),
           out);
  rows.add("exact_points_vs_mesh",
           timed(poses,
                 [&](const RigidTransform& p) {
                   return query_exact_points(a->tree.bvh, a->side(), tree_b, mesh_side(), p);
                 }),
           out);
  for (double p_min : spec.p_mins) {
    AdbOptions adb;
    adb.p_min = p_min;
    rows.add(fmt::format("adb p_min={:g}", p_min),
             timed(poses,
                   [&](const RigidTransform& p) {
                     return query_adb_points(a->tree, a->side(), cb.tree, cb.side(), p, adb);
                   }),
             out);
  }
  for (double levels : spec.confirm_levels)
    for (double p_min : spec.confirm_p_mins) {
      AdbOptions confirmed;
      confirmed.p_min = p_min;
      confirmed.confirm_levels = static_cast<std::uint8_t>(levels);
      rows.add(fmt::format("adb p_min={:g} confirm_levels={:g}", p_min, levels),
               timed(poses,
                     [&](const RigidTransform& p) {
                       return query_adb_points(a->tree, a->side(), cb.tree, cb.side(), p, confirmed);
                     }),
               out);
    }
  for (double bv_tests : spec.bv_tests) {
    AdbOptions capped;  // p_min 0.9; on exhaustion, "collision" iff the best queued estimate >= 0.5
    capped.budget.max_bv_tests = static_cast<std::uint64_t>(bv_tests);
    rows.add(fmt::format("time_critical p_min={:g} bv_tests={:g}", capped.p_min, bv_tests),
             timed(poses,
                   [&](const RigidTransform& p) {
                     return query_adb_points(a->tree, a->side(), cb.tree, cb.side(), p, capped);
                   }),
             out);
  }
  add_octree_series(*a, cb, info.spacing, spec, poses, rows, info, out);
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
    const Mesh mesh_a = load_object(oa).mesh;
    const Mesh mesh_b = pair.a == pair.b ? mesh_a : load_object(ob).mesh;
    const auto tree_a = Bvh<Aabb>::build(mesh_a);
    const auto tree_b = pair.a == pair.b ? tree_a : Bvh<Aabb>::build(mesh_b);
    PointsCloudInfo info;
    info.pair = pair.label();
    info.triangles_a = mesh_a.triangles.size();
    info.triangles_b = mesh_b.triangles.size();
    for (double n : spec.densities)
      run_density(mesh_a, mesh_b, tree_a, tree_b, pair.a == pair.b, static_cast<std::size_t>(n), spec, info,
                  out, quiet);
  }
  return out;
}

}  // namespace bvhlab
