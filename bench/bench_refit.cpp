// Deforming meshes: per frame, refit (or rebuild) the deforming object's tree and run one exact query
// against a rigid second object, bvhlab and FCL 0.7 side by side on the same frames and poses.
//
//   bench_refit [--mesh=bunny.obj] [--deformation=twist] [--frames=24] [--distance=1.6]
//   [--volumes=aabb,obb,dop24]
//               [--crossover] [benchmark flags, e.g. --benchmark_repetitions=5]
//
// The deforming object A is the mesh (protocol-normalised: longest side 2) or, when it is not found, a cloth
// grid of 69,938 triangles; the deformation (bvh/deform.hpp) runs one period over the frames. B is the rest
// mesh, rigid, at protocol_pose(distance, frame, frames): the same pose for every library in a frame. Series
// per volume, each timing one pass over all frames (time_per_frame):
//   bvhlab/refit_merge  Bvh::refit(frame, Merge) + query_exact      fcl/refit    beginUpdateModel,
//   bvhlab/refit_fit    Bvh::refit(frame, Fit) + query_exact                     updateSubModel,
//   endUpdateModel bvhlab/rebuild      Bvh::build(frame, 1 thread) + query_exact                (refit,
//   bottom-up) + collide
//                                                                   fcl/rebuild  a new BVHModel + collide
// plus bvhlab/refit_only and fcl/refit_only: the merge refit and FCL's update alone, without a query.
// FCL pairs: aabb with AABB, obb with OBB, dop24 with KDOP<24> (other directions, the same count). Before
// timing, every frame's answer is checked for every series against CGAL: a bvhlab answer that differs ends
// the run with status 1, an FCL one is reported. After the run, the ratio bvhlab/FCL per volume (medians
// over repetitions when --benchmark_repetitions is given).
//
// --crossover measures, instead, what a refitted tree costs against a rebuilt one as the deformation
// grows (amplitude x 0.25 .. 8 at a quarter period): degradation(), refit and rebuild times, and the mean
// exact query time over protocol poses on both trees; that is how kRebuildDegradation was chosen.
#include "bench/core/bench_flags.hpp"
#include "bench/core/ground_truth.hpp"
#include "bvh/deform.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "traversal/exact.hpp"

#include <benchmark/benchmark.h>
#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_model.hpp"
#endif

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct Scene {
  Mesh rest;
  std::vector<Mesh> frames;
  std::vector<RigidTransform> poses;  ///< B in A's frame, one per frame
  std::vector<char> truth;            ///< CGAL's answer per frame
#ifdef BVHLAB_HAVE_FCL
  std::vector<std::vector<fcl::Vector3d>> fcl_frames;
  std::vector<fcl::Triangle> fcl_triangles;
#endif
};

BuildOptions one_thread() {
  BuildOptions o;
  o.threads = 1;  // FCL builds on one thread
  return o;
}

void set_frame_counters(benchmark::State& state, const Scene& scene, std::size_t colliding) {
  const double n = static_cast<double>(scene.frames.size());
  state.counters["time_per_frame"] =
      benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["colliding"] = static_cast<double>(colliding) / n;
}

// Per-frame answers of each series, checked against CGAL before anything is timed.
int mismatches(const Scene& scene, const std::vector<char>& answers, const std::string& series) {
  int wrong = 0;
  for (std::size_t f = 0; f < answers.size(); ++f)
    if (answers[f] != scene.truth[f]) {
      std::fprintf(stderr, "%s: frame %zu answers %d, CGAL %d\n", series.c_str(), f, answers[f],
                   scene.truth[f]);
      ++wrong;
    }
  return wrong;
}

template <class BV>
std::vector<char> bvhlab_answers(const Scene& scene, RefitMethod method, bool rebuild) {
  const auto tree_b = Bvh<BV>::build(scene.rest);
  auto tree = Bvh<BV>::build(scene.rest);
  std::vector<char> out;
  for (std::size_t f = 0; f < scene.frames.size(); ++f) {
    if (rebuild)
      tree = Bvh<BV>::build(scene.frames[f], one_thread());
    else
      tree.refit(scene.frames[f], method);
    out.push_back(query_exact(tree, tree_b, scene.poses[f]).collides);
  }
  return out;
}

template <class BV>
void register_bvhlab(const std::shared_ptr<const Scene>& scene, int& bvhlab_wrong) {
  const std::string bv(BV::name());
  struct Series {
    std::string name;
    RefitMethod method;
    bool rebuild;
  };
  for (const Series& s :
       {Series{"refit_merge", RefitMethod::Merge, false}, Series{"refit_fit", RefitMethod::Fit, false},
        Series{"rebuild", RefitMethod::Merge, true}}) {
    const std::string name = "bvhlab/" + s.name + "/" + bv;
    bvhlab_wrong += mismatches(*scene, bvhlab_answers<BV>(*scene, s.method, s.rebuild), name);
    benchmark::RegisterBenchmark(name.c_str(), [scene, s](benchmark::State& state) {
      const auto tree_b = Bvh<BV>::build(scene->rest);
      auto tree = Bvh<BV>::build(scene->rest);
      std::size_t colliding = 0;
      for (auto _ : state) {
        colliding = 0;
        for (std::size_t f = 0; f < scene->frames.size(); ++f) {
          if (s.rebuild)
            tree = Bvh<BV>::build(scene->frames[f], one_thread());
          else
            tree.refit(scene->frames[f], s.method);
          colliding += query_exact(tree, tree_b, scene->poses[f]).collides;
        }
        benchmark::DoNotOptimize(colliding);
      }
      set_frame_counters(state, *scene, colliding);
    })->Unit(benchmark::kMillisecond);
  }
  // The refit alone, without the query: what the per-frame update itself costs.
  benchmark::RegisterBenchmark(("bvhlab/refit_only/" + bv).c_str(), [scene](benchmark::State& state) {
    auto tree = Bvh<BV>::build(scene->rest);
    for (auto _ : state)
      for (const Mesh& frame : scene->frames) tree.refit(frame);
    set_frame_counters(state, *scene, 0);
  })->Unit(benchmark::kMillisecond);
}

#ifdef BVHLAB_HAVE_FCL
template <class FclBV>
std::vector<char> fcl_answers(const Scene& scene, bool rebuild) {
  const auto b = make_fcl_model<FclBV>(scene.rest);
  auto a = make_fcl_model<FclBV>(scene.rest);
  std::vector<char> out;
  for (std::size_t f = 0; f < scene.frames.size(); ++f) {
    if (rebuild) {
      a = make_fcl_model<FclBV>(scene.fcl_frames[f], scene.fcl_triangles);
    } else {
      a->beginUpdateModel();
      a->updateSubModel(scene.fcl_frames[f]);
      a->endUpdateModel(true, true);
    }
    out.push_back(fcl_collides(*a, *b, scene.poses[f]));
  }
  return out;
}

template <class FclBV>
void register_fcl(const std::shared_ptr<const Scene>& scene, const std::string& bv) {
  for (bool rebuild : {false, true}) {
    const std::string name = std::string("fcl/") + (rebuild ? "rebuild/" : "refit/") + bv;
    const int wrong = mismatches(*scene, fcl_answers<FclBV>(*scene, rebuild), name);
    if (wrong > 0)
      std::fprintf(stderr, "%s: %d of %zu frames differ from CGAL\n", name.c_str(), wrong,
                   scene->frames.size());
    benchmark::RegisterBenchmark(name.c_str(), [scene, rebuild](benchmark::State& state) {
      const auto b = make_fcl_model<FclBV>(scene->rest);
      auto a = make_fcl_model<FclBV>(scene->rest);
      std::size_t colliding = 0;
      for (auto _ : state) {
        colliding = 0;
        for (std::size_t f = 0; f < scene->frames.size(); ++f) {
          if (rebuild) {
            a = make_fcl_model<FclBV>(scene->fcl_frames[f], scene->fcl_triangles);
          } else {
            a->beginUpdateModel();
            a->updateSubModel(scene->fcl_frames[f]);
            a->endUpdateModel(true, true);
          }
          colliding += fcl_collides(*a, *b, scene->poses[f]);
        }
        benchmark::DoNotOptimize(colliding);
      }
      set_frame_counters(state, *scene, colliding);
    })->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark(("fcl/refit_only/" + bv).c_str(), [scene](benchmark::State& state) {
    auto a = make_fcl_model<FclBV>(scene->rest);
    for (auto _ : state)
      for (const auto& frame : scene->fcl_frames) {
        a->beginUpdateModel();
        a->updateSubModel(frame);
        a->endUpdateModel(true, true);
      }
    set_frame_counters(state, *scene, 0);
  })->Unit(benchmark::kMillisecond);
}
#endif

// Keeps each benchmark's median time per iteration (the median aggregate when there are repetitions), so
// main can print the ratios of one run.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs) {
      const std::string name = run.run_name.function_name;
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median")
        median_[name] = run.GetAdjustedCPUTime();
      else if (run.run_type == Run::RT_Iteration)
        times_[name].push_back(run.GetAdjustedCPUTime());
    }
    ConsoleReporter::ReportRuns(runs);
  }
  /// CPU milliseconds per iteration (every series runs on one thread; CPU time is less disturbed by other
  /// load than wall time), or a negative number for a benchmark that did not run.
  [[nodiscard]] double median(const std::string& name) const {
    if (auto it = median_.find(name); it != median_.end()) return it->second;
    auto it = times_.find(name);
    if (it == times_.end() || it->second.empty()) return -1;
    std::vector<double> v = it->second;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }

 private:
  std::map<std::string, double> median_;
  std::map<std::string, std::vector<double>> times_;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Refitted against rebuilt trees as the deformation grows (see the file comment).
template <class BV>
void crossover(const Mesh& rest, Deformation d) {
  std::vector<RigidTransform> poses;
  for (double dist : {0.6, 1.0, 1.4}) {
    const auto p = protocol_poses(dist, 100);
    poses.insert(poses.end(), p.begin(), p.end());
  }
  const auto tree_b = Bvh<BV>::build(rest);
  auto mean_query_us = [&](const Bvh<BV>& tree) {
    double best = 1e300;
    for (int rep = 0; rep < 3; ++rep) {  // the fastest of three passes: least disturbed by other load
      const auto start = std::chrono::steady_clock::now();
      std::size_t hits = 0;
      for (const auto& pose : poses) hits += query_exact(tree, tree_b, pose).collides;
      benchmark::DoNotOptimize(hits);
      best = std::min(best, seconds_since(start));
    }
    return 1e6 * best / double(poses.size());
  };
  std::printf("%-6s %7s %11s %10s %11s %14s %14s %7s\n", BV::name().data(), "scale", "degradation",
              "refit_ms", "rebuild_ms", "query_refit_us", "query_built_us", "slowdown");
  const double amplitude = d.amplitude;
  for (double scale : {0.25, 0.5, 1.0, 2.0, 4.0, 8.0}) {
    d.amplitude = amplitude * scale;
    if (d.kind == DeformationKind::Pulsate) d.amplitude = std::min(d.amplitude, 0.9);
    const Mesh moved = deform(rest, d, 0.25 / d.cycles);
    auto refitted = Bvh<BV>::build(rest, one_thread());
    auto start = std::chrono::steady_clock::now();
    refitted.refit(moved);
    const double refit_s = seconds_since(start);
    start = std::chrono::steady_clock::now();
    const auto rebuilt = Bvh<BV>::build(moved, one_thread());
    const double rebuild_s = seconds_since(start);
    const double q_refit = mean_query_us(refitted), q_built = mean_query_us(rebuilt);
    std::printf("%-6s %7.2f %11.3f %10.2f %11.2f %14.2f %14.2f %7.2f\n", BV::name().data(), scale,
                refitted.degradation(), 1e3 * refit_s, 1e3 * rebuild_s, q_refit, q_built, q_refit / q_built);
    std::fflush(stdout);
  }
}

// The deforming object's frames, B's pose in each and CGAL's answer, for FCL also the frames' points.
void add_frames(Scene& scene, const Deformation& deformation, double distance, int frames) {
  for (int f = 0; f < frames; ++f) {
    scene.frames.push_back(deform(scene.rest, deformation, frame_time(f, frames)));
    scene.poses.push_back(protocol_pose(distance, f, frames));
    scene.truth.push_back(CgalGroundTruth(scene.frames.back(), scene.rest).collides(scene.poses.back()));
#ifdef BVHLAB_HAVE_FCL
    scene.fcl_frames.push_back(fcl_points(scene.frames.back()));
#endif
  }
#ifdef BVHLAB_HAVE_FCL
  scene.fcl_triangles = fcl_triangles(scene.rest);
#endif
  std::fprintf(stderr, "bench_refit: %ld of %d frames collide (CGAL)\n",
               std::count(scene.truth.begin(), scene.truth.end(), 1), frames);
}

// Registers every series of every volume (checking each answer first); returns the wrong bvhlab answers.
int register_series(const std::shared_ptr<const Scene>& scene, const std::vector<std::string>& volumes) {
  int bvhlab_wrong = 0;
  for (const auto& v : volumes) {
    with_volume(v, [&]<class BV>(std::type_identity<BV>) { register_bvhlab<BV>(scene, bvhlab_wrong); });
#ifdef BVHLAB_HAVE_FCL
    if (v == "aabb") register_fcl<fcl::AABBd>(scene, v);
    if (v == "obb") register_fcl<fcl::OBBd>(scene, v);
    if (v == "dop24") register_fcl<fcl::KDOPd<24>>(scene, v);
#endif
  }
  return bvhlab_wrong;
}

// The table after the run: bvhlab against FCL per volume.
void print_ratios(const RatioReporter& reporter, const std::vector<std::string>& volumes, int frames) {
  std::printf("\nbvhlab / FCL (median CPU ms per pass of %d frames):\n", frames);
  std::printf("%-6s %12s %12s %12s %12s %12s %12s %12s %12s %12s\n", "bv", "refit_merge", "refit_fit",
              "fcl_refit", "merge/fcl", "fit/fcl", "rebuild", "fcl_rebuild", "refit_only", "fcl_ref_only");
  for (const auto& v : volumes) {
    const double merge = reporter.median("bvhlab/refit_merge/" + v),
                 fit = reporter.median("bvhlab/refit_fit/" + v);
    const double fcl = reporter.median("fcl/refit/" + v);
    const double rebuild = reporter.median("bvhlab/rebuild/" + v),
                 fcl_rebuild = reporter.median("fcl/rebuild/" + v);
    std::printf("%-6s %12.2f %12.2f %12.2f %12.3f %12.3f %12.2f %12.2f %12.2f %12.2f\n", v.c_str(), merge,
                fit, fcl, fcl > 0 ? merge / fcl : 0.0, fcl > 0 ? fit / fcl : 0.0, rebuild, fcl_rebuild,
                reporter.median("bvhlab/refit_only/" + v), reporter.median("fcl/refit_only/" + v));
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::string mesh_name = "bunny.obj", spec = "twist";
  std::vector<std::string> volumes{"aabb", "obb", "dop24"};
  int frames = 24;
  double distance = 1.6;
  bool run_crossover = false;
  if (auto exit = initialize_benchmark("bench_refit",
                                       {{"mesh", &mesh_name, "the deforming mesh"},
                                        {"deformation", &spec, "a deformation (\"twist:amplitude=1.5\")"},
                                        {"frames", &frames, "frames per pass"},
                                        {"volumes", &volumes, "bounding volumes"},
                                        {"distance", &distance, "distance of the second object"},
                                        {"crossover", &run_crossover, "measure refit against rebuild only"}},
                                       argc, argv))
    return *exit;
  try {
    if (frames < 1) throw std::invalid_argument("--frames must be at least 1");
    for (const auto& v : volumes) with_volume(v, [](auto) {});  // refuses unknown names
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_refit: %s\n", e.what());
    return 2;
  }
  const Deformation deformation = parse_deformation(spec);

  auto scene = std::make_shared<Scene>();
  if (find_mesh(mesh_name)) {
    scene->rest = load_protocol_mesh(mesh_name);
  } else {
    std::fprintf(stderr, "bench_refit: %s not found (run meshes/fetch.sh); using a cloth grid\n",
                 mesh_name.c_str());
    scene->rest = cloth_grid(187);
    normalize_to_unit_cube(scene->rest);
  }
  std::fprintf(stderr, "bench_refit: %s, %zu triangles, %s, %d frames\n", scene->rest.name.c_str(),
               scene->rest.triangle_count(), spec.c_str(), frames);
  if (run_crossover) {
    for (const auto& v : volumes)
      with_volume(v, [&]<class BV>(std::type_identity<BV>) { crossover<BV>(scene->rest, deformation); });
    return 0;
  }
  add_frames(*scene, deformation, distance, frames);
  if (const int bvhlab_wrong = register_series(scene, volumes); bvhlab_wrong > 0) {
    std::fprintf(stderr, "bench_refit: %d bvhlab answers differ from CGAL\n", bvhlab_wrong);
    return 1;
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  print_ratios(reporter, volumes, frames);
  benchmark::Shutdown();
  return 0;
}
