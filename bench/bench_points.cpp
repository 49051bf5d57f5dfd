// Point clouds on the tumbling protocol (adb/README.md, section 4): one mesh, clouds sampled from it at
// several densities, B tumbling about A at each distance. The ground truth is the exact answer on the
// meshes. A pose is ambiguous when that answer changes with B moved by --band point spacings along any
// axis, either way (the objects are then within about that of touching): it is counted apart, and the
// errors are counted outside it. Per density and series: the median and mean time per query, false
// positives and false negatives outside the band (of the clear poses), and the speed-up over exact_points.
// Series: exact on the meshes, exact_points (cloud against cloud), exact_points of the cloud against the
// mesh, ADB on the clouds at each p_min and time-critical (ADB at p_min 0.9 under each --bv-tests budget;
// traversal/point_leaves.hpp). All on AABB trees, one run, queries
// timed one by one (warm: each series runs once over the poses before the timed pass). Built with FCL, also
// FCL's octree collision on octrees of the same points (bench/core/fcl_octree.hpp) at each --octree-res (in
// point spacings), and per octree the fastest inexact series (ADB or time-critical) with no more errors.
//
//   bench_points [--meshes=pinion.off] [--points=5000,20000] [--steps=200] [--band=1]
//                [--p-min=0.5,0.7,0.9,0.95,0.99] [--distances=0.4,...,2.0] [--leaf=16] [--octree-res=1,2]
#include "adb/point_density.hpp"
#include "bench/core/bench_flags.hpp"
#include "bench/core/mesh_catalog.hpp"
#include "bench/core/protocol.hpp"
#include "traversal/point_leaves.hpp"
#include "volumes/aabb.hpp"

#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_octree.hpp"
#endif

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct Pose {
  RigidTransform pose;
  bool truth = false;      ///< the meshes' exact answer
  bool ambiguous = false;  ///< the answer changes within the band
};

struct Row {
  std::string series;
  double median_us = 0, mean_us = 0;
  std::size_t fp = 0, fn = 0, clear = 0;
};

/// The protocol poses with the mesh answer; ambiguous where B moved by `shift` along an axis changes it.
std::vector<Pose> protocol_workload(const Bvh<Aabb>& mesh_tree, const std::vector<double>& distances,
                                    int steps, double shift) {
  std::vector<Pose> out;
  for (double d : distances)
    for (const RigidTransform& pose : protocol_poses(d, steps)) {
      Pose p{pose, query_exact(mesh_tree, mesh_tree, pose).collides, false};
      for (int axis = 0; axis < 3 && !p.ambiguous; ++axis)
        for (double sign : {-1.0, 1.0}) {
          RigidTransform moved = pose;
          moved.translation[axis] += sign * shift;
          p.ambiguous = p.ambiguous || query_exact(mesh_tree, mesh_tree, moved).collides != p.truth;
        }
      out.push_back(p);
    }
  return out;
}

/// Runs `query` over the poses once warm-up, once timed per query; errors outside the band.
template <class Query>
Row measure(const std::string& series, const std::vector<Pose>& poses, Query&& query) {
  bool sink = false;
  for (const Pose& p : poses) sink ^= query(p.pose).collides;
  std::vector<double> micros;
  micros.reserve(poses.size());
  Row row{series};
  for (const Pose& p : poses) {
    const auto start = std::chrono::steady_clock::now();
    const Result r = query(p.pose);
    micros.push_back(
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    sink ^= r.collides;
    if (p.ambiguous) continue;
    ++row.clear;
    row.fp += r.collides && !p.truth;
    row.fn += !r.collides && p.truth;
  }
  benchmark::DoNotOptimize(sink);
  for (double t : micros) row.mean_us += t;
  row.mean_us /= static_cast<double>(micros.size());
  std::nth_element(micros.begin(), micros.begin() + std::ptrdiff_t(micros.size() / 2), micros.end());
  row.median_us = micros[micros.size() / 2];
  return row;
}

/// The series that may trade errors for time: ADB at a p_min, and time-critical.
bool is_inexact(const std::string& series) {
  return series.rfind("adb", 0) == 0 || series.rfind("time_critical", 0) == 0;
}

double error_percent(const Row& r) {
  return 100.0 * static_cast<double>(r.fp + r.fn) / static_cast<double>(r.clear);
}

void print_rows(const std::vector<Row>& rows, const Row& reference, double max_error) {
  std::printf("%-22s %10s %10s %7s %7s %7s %9s %9s\n", "series", "median_us", "mean_us", "FP%", "FN%", "err%",
              "x_median", "x_mean");
  const Row* best = nullptr;
  for (const Row& r : rows) {
    const double n = static_cast<double>(r.clear);
    const double fp = 100.0 * static_cast<double>(r.fp) / n, fn = 100.0 * static_cast<double>(r.fn) / n;
    std::printf("%-22s %10.2f %10.2f %7.2f %7.2f %7.2f %9.2f %9.2f\n", r.series.c_str(), r.median_us,
                r.mean_us, fp, fn, fp + fn, reference.median_us / r.median_us, reference.mean_us / r.mean_us);
    if (is_inexact(r.series) && fp + fn <= max_error && (!best || r.mean_us < best->mean_us)) best = &r;
  }
  if (best)
    std::printf("best inexact at <= %.0f%% wrong: %s, %.2fx faster than %s by mean time, %.2fx by median\n",
                max_error, best->series.c_str(), reference.mean_us / best->mean_us, reference.series.c_str(),
                reference.median_us / best->median_us);
  else
    std::printf("no inexact series at <= %.0f%% wrong\n", max_error);
}

/// Per FCL octree row, the fastest inexact row (by mean time) with no more errors than it on the clear poses.
void print_adb_against_fcl(const std::vector<Row>& rows) {
  for (const Row& f : rows) {
    if (f.series.rfind("fcl_octree", 0) != 0) continue;
    const Row* best = nullptr;
    for (const Row& r : rows)
      if (is_inexact(r.series) && error_percent(r) <= error_percent(f) &&
          (!best || r.mean_us < best->mean_us))
        best = &r;
    if (best)
      std::printf("%s (%.2f%% wrong): %s at %.2f%% wrong is %.2fx faster by mean time, %.2fx by median\n",
                  f.series.c_str(), error_percent(f), best->series.c_str(), error_percent(*best),
                  f.mean_us / best->mean_us, f.median_us / best->median_us);
    else
      std::printf("%s (%.2f%% wrong): no inexact series at equal or fewer errors\n", f.series.c_str(),
                  error_percent(f));
  }
}

struct Setup {
  std::vector<double> points{5000, 20000};
  std::vector<double> p_mins{0.5, 0.7, 0.9, 0.95, 0.99};
  std::vector<double> distances = ProtocolOptions{}.distances;
  int steps = 200;
  double band = 1;
  unsigned leaf = 16;
  std::vector<double> octree_res{1, 2};   ///< FCL octree voxel sides, in point spacings
  std::vector<double> bv_tests{50, 200};  ///< time-critical budgets (ADB at p_min 0.9 with a BV-test cap)
};

/// FCL's octree series, one per resolution (none without FCL).
void add_fcl_octree_rows([[maybe_unused]] const PointCloud& cloud, [[maybe_unused]] double spacing,
                         [[maybe_unused]] const Setup& setup, [[maybe_unused]] const std::vector<Pose>& poses,
                         [[maybe_unused]] std::vector<Row>& rows) {
#ifdef BVHLAB_HAVE_FCL
  for (double factor : setup.octree_res) {
    const double res = factor * spacing;
    const auto start = std::chrono::steady_clock::now();
    const auto octree = make_fcl_octree(cloud, res);
    const double build_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::printf("octree res %.4f (%.3g spacings): %zu occupied leaves, built in %.1f ms\n", res, factor,
                octree->toBoxes().size(), build_ms);
    FclOctreePair pair(octree, octree);
    char name[32];
    std::snprintf(name, sizeof name, "fcl_octree res=%.4f", res);
    rows.push_back(measure(name, poses, [&](const RigidTransform& pose) {
      Result r;
      r.collides = pair.collides(pose);
      return r;
    }));
  }
#endif
}

void run_mesh(const std::string& file, const Setup& setup) {
  const Mesh mesh = load_protocol_mesh(file);
  const auto mesh_tree = Bvh<Aabb>::build(mesh);
  const double area = surface_area(mesh);
  std::printf("\n=== %s: %zu triangles, area %.3f (longest side 2), %d steps x %zu distances ===\n",
              file.c_str(), mesh.triangles.size(), area, setup.steps, setup.distances.size());
  for (double count : setup.points) {
    const auto n = static_cast<std::size_t>(count);
    const double spacing = std::sqrt(area / count);
    const std::vector<Pose> poses =
        protocol_workload(mesh_tree, setup.distances, setup.steps, setup.band * spacing);
    std::size_t ambiguous = 0, colliding = 0;
    for (const Pose& p : poses) ambiguous += p.ambiguous, colliding += p.truth && !p.ambiguous;
    const PointCloud cloud = sample_uniform(mesh, n, 1);
    const PointSurface surface(cloud);
    BuildOptions options;
    options.max_leaf_points = setup.leaf;
    const auto tree = annotate_adb_points(Bvh<Aabb>::build(cloud, options), cloud, 2);
    const auto coverings = sphere_coverings(tree.bvh, surface);
    const SurfaceSide side = cloud_side(surface, coverings);
    std::printf(
        "\n%zu points, spacing %.4f (sqrt(area / N)), band %.4f: %zu poses, %zu ambiguous, %zu clear "
        "(%zu colliding)\n",
        n, spacing, setup.band * spacing, poses.size(), ambiguous, poses.size() - ambiguous, colliding);
    std::vector<Row> rows;
    rows.push_back(measure("exact_mesh", poses, [&](const RigidTransform& pose) {
      return query_exact(mesh_tree, mesh_tree, pose);
    }));
    rows.push_back(measure("exact_points", poses, [&](const RigidTransform& pose) {
      return query_exact_points(tree.bvh, side, tree.bvh, side, pose);
    }));
    rows.push_back(measure("exact_points_vs_mesh", poses, [&](const RigidTransform& pose) {
      return query_exact_points(tree.bvh, side, mesh_tree, mesh_side(), pose);
    }));
    for (double p_min : setup.p_mins) {
      AdbOptions adb;
      adb.p_min = p_min;
      char name[32];
      std::snprintf(name, sizeof name, "adb p_min %.2f", p_min);
      rows.push_back(measure(name, poses, [&](const RigidTransform& pose) {
        return query_adb_points(tree, side, tree, side, pose, adb);
      }));
    }
    for (double bv_tests : setup.bv_tests) {
      AdbOptions time_critical;  // p_min 0.9; on exhaustion, "collision" iff the best queued estimate >= 0.5
      time_critical.budget.max_bv_tests = static_cast<std::uint64_t>(bv_tests);
      char name[48];
      std::snprintf(name, sizeof name, "time_critical bv_tests=%.0f", bv_tests);
      rows.push_back(measure(name, poses, [&](const RigidTransform& pose) {
        return query_adb_points(tree, side, tree, side, pose, time_critical);
      }));
    }
    add_fcl_octree_rows(cloud, spacing, setup, poses, rows);
    print_rows(rows, rows[1], 4.0);
    print_adb_against_fcl(rows);
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"pinion.off"};
  Setup setup;
  if (auto exit = initialize_benchmark(
          "bench_points",
          {{"meshes", &meshes, "meshes to sample"},
           {"points", &setup.points, "points per cloud, one cloud per value"},
           {"p-min", &setup.p_mins, "ADB's p_min values"},
           {"distances", &setup.distances, "protocol distances"},
           {"steps", &setup.steps, "poses per distance"},
           {"band", &setup.band, "ambiguous band, in point spacings"},
           {"leaf", &setup.leaf, "points per leaf"},
           {"bv-tests", &setup.bv_tests, "time-critical series: BV-test budgets at p_min 0.9"},
           {"octree-res", &setup.octree_res, "FCL octree voxel sides in point spacings (built with FCL)"}},
          argc, argv))
    return *exit;
  try {
    if (setup.steps < 1) throw std::invalid_argument("--steps must be at least 1");
    if (!(setup.band >= 0)) throw std::invalid_argument("--band must be at least 0 spacings");
    for (double n : setup.bv_tests)
      if (!(n >= 1 && n <= 1e9 && n == std::floor(n)))
        throw std::invalid_argument("--bv-tests must be whole numbers from 1 to 10^9");
    for (double r : setup.octree_res)
      if (!(r > 0 && r <= 1e3)) throw std::invalid_argument("--octree-res must be in (0, 1000] spacings");
    for (double n : setup.points)
      if (!(n >= 11 && n <= 1e7 && n == std::floor(n)))
        throw std::invalid_argument("--points must be whole numbers from 11 to 10^7");
    for (const auto& file : meshes) {
      if (!find_mesh(file)) {
        std::fprintf(stderr, "bench_points: skipping %s (not found; run meshes/fetch.sh)\n", file.c_str());
        continue;
      }
      run_mesh(file, setup);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_points: %s\n", e.what());
    return 2;
  }
  return 0;
}
