// Wide against binary trees: the exact first-contact query on a binary tree (query_exact) and on its wide
// form (query_exact_wide: four children a node, tested at once), side by side, for every volume that has a
// wide layout (AABB and the k-DOPs).
//
//   bench_wide [--meshes=jeep1.ms3d,bunny.obj] [--volumes=aabb,dop18,dop24] [--distances=0.4,0.8,1.2,1.6,2.0]
//              [--steps=200] [benchmark flags]
//
// Per mesh and volume (a mesh against itself, protocol poses of every distance), one iteration makes one pass
// over all poses with each query, in alternating order, each pass timed as a whole. Counters, medians over
// the iterations (q1, q3: quartiles): µs per query for each, the speed-up binary over wide (per iteration,
// then its median), and per query the BV tests (the wide count includes empty lanes), node pairs taken and
// triangle tests of each. A pose where the two answer otherwise ends the run with an error.
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "bench/report_tables.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "traversal/wide_exact.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using Clock = std::chrono::steady_clock;

template <class BV>
struct Trees {
  Bvh<BV> binary;
  WideTreeOf<BV> wide;
};

template <class BV>
void run_series(benchmark::State& state, const Trees<BV>& t, const std::vector<RigidTransform>& poses) {
  std::vector<double> binary_us, wide_us, speedup;
  Counters binary_work, wide_work;
  std::vector<char> binary_answers(poses.size()), wide_answers(poses.size());
  std::uint64_t disagreements = 0;
  bool binary_first = true;
  for (auto _ : state) {
    double binary_seconds = 0, wide_seconds = 0;
    const auto binary_pass = [&] {
      const auto start = Clock::now();
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const Result r = query_exact(t.binary, t.binary, poses[k]);
        binary_answers[k] = r.collides;
        binary_work += r.counters;
      }
      binary_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    };
    const auto wide_pass = [&] {
      const auto start = Clock::now();
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const Result r = query_exact_wide(t.binary, t.wide, t.binary, t.wide, poses[k]);
        wide_answers[k] = r.collides;
        wide_work += r.counters;
      }
      wide_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    };
    if (binary_first)
      binary_pass(), wide_pass();
    else
      wide_pass(), binary_pass();
    binary_first = !binary_first;
    for (std::size_t k = 0; k < poses.size(); ++k) disagreements += binary_answers[k] != wide_answers[k];
    const double n = static_cast<double>(poses.size());
    binary_us.push_back(1e6 * binary_seconds / n);
    wide_us.push_back(1e6 * wide_seconds / n);
    speedup.push_back(binary_seconds / wide_seconds);
  }
  using report_tables::quantile;
  const double queries = static_cast<double>(poses.size() * speedup.size());
  state.counters["binary_us"] = quantile(binary_us, 0.5);
  state.counters["wide_us"] = quantile(wide_us, 0.5);
  state.counters["speedup"] = quantile(speedup, 0.5);
  state.counters["speedup_q1"] = quantile(speedup, 0.25);
  state.counters["speedup_q3"] = quantile(speedup, 0.75);
  state.counters["binary_bv_tests"] = static_cast<double>(binary_work.bv_tests) / queries;
  state.counters["wide_bv_tests"] = static_cast<double>(wide_work.bv_tests) / queries;
  state.counters["binary_pairs"] = static_cast<double>(binary_work.nodes_visited) / queries;
  state.counters["wide_pairs"] = static_cast<double>(wide_work.nodes_visited) / queries;
  state.counters["binary_triangle_tests"] = static_cast<double>(binary_work.triangle_tests) / queries;
  state.counters["wide_triangle_tests"] = static_cast<double>(wide_work.triangle_tests) / queries;
  state.counters["binary_ns_per_bv_test"] =
      1e3 * quantile(binary_us, 0.5) * queries / double(binary_work.bv_tests);
  state.counters["wide_ns_per_bv_test"] = 1e3 * quantile(wide_us, 0.5) * queries / double(wide_work.bv_tests);
  state.counters["disagreements"] = static_cast<double>(disagreements);
  if (disagreements) state.SkipWithError("the wide and the binary query answered otherwise");
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"jeep1.ms3d", "bunny.obj"};
  std::vector<std::string> volumes{"aabb", "dop18", "dop24"};
  std::vector<double> distances{0.4, 0.8, 1.2, 1.6, 2.0};
  int steps = 200;
  if (auto exit = initialize_benchmark("bench_wide",
                                       {{"meshes", &meshes, "meshes to run"},
                                        {"volumes", &volumes, "bounding volumes with a wide layout"},
                                        {"distances", &distances, "protocol distances"},
                                        {"steps", &steps, "poses per full turn"}},
                                       argc, argv))
    return *exit;
  if (steps < 1) {
    std::fprintf(stderr, "bench_wide: --steps must be at least 1\n");
    return 2;
  }
  static std::vector<RigidTransform> poses;
  for (double d : distances)
    for (const RigidTransform& pose : protocol_poses(d, steps)) poses.push_back(pose);
  for (const auto& v : volumes) {
    bool wide = false;
    try {
      with_volume(v, [&]<class BV>(std::type_identity<BV>) { wide = HasWideLayout<BV>; });
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "bench_wide: --volumes: %s\n", e.what());
      return 2;
    }
    if (!wide) {
      std::fprintf(stderr, "bench_wide: --volumes: %s has no wide layout (aabb and the k-DOPs have)\n",
                   v.c_str());
      return 2;
    }
  }
  for_each_protocol_mesh("bench_wide", meshes, [&](const std::string& label, const auto& mesh) {
    for (const auto& v : volumes)
      with_volume(v, [&]<class BV>(std::type_identity<BV>) {
        if constexpr (HasWideLayout<BV>) {
          auto binary = Bvh<BV>::build(*mesh);
          auto wide = WideTreeOf<BV>::build(binary);
          const auto trees = std::make_shared<const Trees<BV>>(Trees<BV>{std::move(binary), std::move(wide)});
          const std::string name = label + "/" + std::string(BV::name());
          benchmark::RegisterBenchmark(name.c_str(), [trees](benchmark::State& state) {
            run_series(state, *trees, poses);
          })->Unit(benchmark::kMillisecond);
        }
      });
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
