// Wide against binary trees: the exact first-contact query on a binary tree and on its wide layout (four
// children a node, tested at once: traversal/wide_exact.hpp), side by side, for every volume that has a wide
// layout. Both are the run-time layer's prepared queries (engine/any_tree.hpp), compiled once in the engine.
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
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"
#include "engine/protocol.hpp"

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

/// The exact query of one tree against itself, on the binary tree and on its wide layout.
struct Queries {
  std::unique_ptr<PreparedQuery> binary, wide;
};

/// One pass of `query` over `poses`: its seconds; each answer and the work added to `answers` and `work`.
double timed_pass(const PreparedQuery& query, const std::vector<RigidTransform>& poses,
                  std::vector<char>& answers, Counters& work) {
  const ResultSink record = [&](std::size_t k, const Result& r) {
    answers[k] = r.collides;
    work += r.counters;
  };
  const auto start = Clock::now();
  query.run(poses, record);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void run_series(benchmark::State& state, const Queries& q, const std::vector<RigidTransform>& poses) {
  std::vector<double> binary_us, wide_us, speedup;
  Counters binary_work, wide_work;
  std::vector<char> binary_answers(poses.size()), wide_answers(poses.size());
  std::uint64_t disagreements = 0;
  bool binary_first = true;
  for (auto _ : state) {
    double binary_seconds = 0, wide_seconds = 0;
    const auto binary_pass = [&] {
      binary_seconds = timed_pass(*q.binary, poses, binary_answers, binary_work);
    };
    const auto wide_pass = [&] { wide_seconds = timed_pass(*q.wide, poses, wide_answers, wide_work); };
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
    std::string refusal;
    try {
      refusal = wide_layout_refusal(v);
    } catch (const std::invalid_argument& e) {
      refusal = e.what();
    }
    if (!refusal.empty()) {
      std::fprintf(stderr, "bench_wide: --volumes: %s\n", refusal.c_str());
      return 2;
    }
  }
  StrategyVariant exact = strategy_variant("exact", {}, Budget{}), wide = exact;
  wide.wide = true;
  for_each_protocol_mesh("bench_wide", meshes, [&](const std::string& label, const auto& mesh) {
    for (const auto& v : volumes) {
      const AnyTree tree = AnyTree::build(*mesh, MeshUnits{}, v, density_spec("none", {}), BuildOptions{});
      auto queries = std::make_shared<Queries>(Queries{tree.prepare(tree, exact), tree.prepare(tree, wide)});
      benchmark::RegisterBenchmark((label + "/" + v).c_str(), [queries](benchmark::State& state) {
        run_series(state, *queries, poses);
      })->Unit(benchmark::kMillisecond);
    }
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
