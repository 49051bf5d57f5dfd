// ADB annotation cost (adb/annotate.hpp) and the saved tree's size, per mesh.
//
//   BM_Annotate/<mesh>          annotate<2> of an AABB tree (one triangle per leaf), the tree built outside
//   the
//                               timed region. Counters: triangles, triangle-node pairs, clip calls, exact
//                               cells. Target: the 871k-triangle dragon in <= 60 s wall on 2 cores.
//   BM_SavedBytes/<mesh>/<L>    leaves of up to L triangles: annotation time and saved-tree bytes per
//   triangle,
//                               with and without the triangle ids (goal: <= 16 B/triangle for the AABB).
//
// Meshes missing from the cache are skipped with an error (fetch with meshes/fetch.sh); `generated_torus`
// needs no file. Annotation runs on 2 threads unless --threads=N is given before the benchmark flags.
#include "adb/adb_density.hpp"
#include "adb/saved_tree.hpp"
#include "bench/core/bench_flags.hpp"
#include "bench/core/generators.hpp"
#include "engine/mesh_catalog.hpp"
#include "volumes/aabb.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

unsigned g_threads = 2;

/// CPU seconds of the whole process (all threads): on a busy machine the wall time says little, while
/// cpu / threads is what the run takes on otherwise idle cores.
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

const std::vector<std::string> kMeshes = {"pinion.off",     "jeep1.ms3d",         "teapot.obj",
                                          "dragon_11k.ply", "injector_pipes.stl", "occt_tr12j_housing.stl",
                                          "bunny.obj",      "motorBike.obj",      "dragon_871k.ply",
                                          "generated_torus"};

/// A closed torus of 2 * 400 * 250 = 200,000 triangles, in the protocol's normalisation.
Mesh generated_torus() {
  Mesh m = generators::make_torus(0.7, 0.3, 400, 250);
  m.name = "generated_torus";
  return m;
}

/// Loads each mesh once; nullptr (with the reason) when it is missing.
const Mesh* mesh_named(const std::string& name, std::string& why) {
  static std::map<std::string, std::unique_ptr<Mesh>> cache;
  static std::map<std::string, std::string> failures;
  if (auto it = cache.find(name); it != cache.end()) return it->second.get();
  if (auto it = failures.find(name); it != failures.end()) {
    why = it->second;
    return nullptr;
  }
  try {
    auto mesh =
        std::make_unique<Mesh>(name == "generated_torus" ? generated_torus() : load_protocol_mesh(name));
    return cache.emplace(name, std::move(mesh)).first->second.get();
  } catch (const std::exception& e) {
    why = e.what();
    failures.emplace(name, why);
    return nullptr;
  }
}

void set_stats_counters(benchmark::State& state, const Mesh& mesh, const AnnotateStats& s) {
  state.counters["triangles"] = static_cast<double>(mesh.triangle_count());
  state.counters["nodes"] = static_cast<double>(s.nodes);
  state.counters["pairs"] = static_cast<double>(s.triangle_node_pairs);
  state.counters["clipped_pairs"] = static_cast<double>(s.clipped_triangles);
  state.counters["clip_calls"] = static_cast<double>(s.clip_calls);
  state.counters["skipped_clips"] = static_cast<double>(s.skipped_clips);
  state.counters["exact_cells"] = static_cast<double>(s.exact_cells);
  state.counters["annotate_s"] = s.seconds;
  state.counters["derived_areas"] = static_cast<double>(s.derived_areas);
}

void BM_Annotate(benchmark::State& state, const std::string& name) {
  std::string why;
  const Mesh* mesh = mesh_named(name, why);
  if (mesh == nullptr) {
    state.SkipWithError(("mesh missing: " + why).c_str());
    return;
  }
  const Bvh<Aabb> bvh = Bvh<Aabb>::build(*mesh);
  AnnotateOptions options;
  options.threads = g_threads;
  AnnotateStats stats;
  double cpu = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Bvh<Aabb> copy = bvh;
    state.ResumeTiming();
    const double cpu_start = process_cpu_seconds();
    auto tree = annotate_adb(std::move(copy), 2, options, &stats);
    cpu = process_cpu_seconds() - cpu_start;
    benchmark::DoNotOptimize(tree.density.possible_collision_cells.data());
  }
  set_stats_counters(state, *mesh, stats);
  state.counters["annotate_cpu_s"] = cpu;
  std::fprintf(
      stderr,
      "bench_annotate: %-24s %9zu triangles  annotate %7.2f s wall, %7.2f s CPU (%u threads)  %zu clip "
      "calls\n",
      name.c_str(), mesh->triangle_count(), stats.seconds, cpu, stats.threads, stats.clip_calls);
}

void BM_SavedBytes(benchmark::State& state, const std::string& name, std::uint32_t leaf_triangles) {
  std::string why;
  const Mesh* mesh = mesh_named(name, why);
  if (mesh == nullptr) {
    state.SkipWithError(("mesh missing: " + why).c_str());
    return;
  }
  BuildOptions build;
  build.max_leaf_triangles = leaf_triangles;
  const Bvh<Aabb> bvh = Bvh<Aabb>::build(*mesh, build);
  AnnotateOptions options;
  options.threads = g_threads;
  AnnotateStats stats;
  std::size_t with_ids = 0, without_ids = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Bvh<Aabb> copy = bvh;
    state.ResumeTiming();
    const auto tree = annotate_adb(std::move(copy), 2, options, &stats);
    state.PauseTiming();
    with_ids = save_tree_to_buffer(tree).size();
    without_ids = save_tree_to_buffer(tree, SaveOptions{.triangle_ids = false}).size();
    state.ResumeTiming();
  }
  const double n = static_cast<double>(mesh->triangle_count());
  set_stats_counters(state, *mesh, stats);
  state.counters["bytes_per_tri"] = static_cast<double>(with_ids) / n;
  state.counters["bytes_per_tri_no_ids"] = static_cast<double>(without_ids) / n;
  std::fprintf(stderr,
               "bench_annotate: %-24s leaves <= %u: %8zu nodes, saved %6.2f B/tri (%6.2f without ids), "
               "annotate %6.2f s\n",
               name.c_str(), leaf_triangles, stats.nodes, static_cast<double>(with_ids) / n,
               static_cast<double>(without_ids) / n, stats.seconds);
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  if (auto exit = bvhlab::initialize_benchmark(
          "bench_annotate", {{"threads", &bvhlab::g_threads, "annotation threads"}}, argc, argv))
    return *exit;
  for (const auto& name : bvhlab::kMeshes)
    benchmark::RegisterBenchmark(("BM_Annotate/" + name).c_str(), bvhlab::BM_Annotate, name)
        ->Iterations(1)
        ->Unit(benchmark::kSecond)
        ->UseRealTime();
  for (const auto& name : bvhlab::kMeshes)
    for (const std::uint32_t leaf : {1u, 2u, 4u, 8u})
      benchmark::RegisterBenchmark(("BM_SavedBytes/" + name + "/" + std::to_string(leaf)).c_str(),
                                   bvhlab::BM_SavedBytes, name, leaf)
          ->Iterations(1)
          ->Unit(benchmark::kSecond)
          ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
