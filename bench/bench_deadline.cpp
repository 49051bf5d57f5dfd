// Deadlines of the time-critical strategy: how far past its deadline a warm query returns. ADB trees (g = 2)
// of a protocol mesh against themselves, on the protocol poses whose unbudgeted ADB query is long (at least
// --min-pops node pairs at p_min 0.9), each query run once untimed and then timed alone with steady_clock.
// Per (mesh, BV, deadline): median, p99 and max of those per-query times, and the share flagged
// budget_exhausted. Two more series on the same poses give the cost of the deadline checks: no budget, and a
// deadline never reached (1e9 us), whose time per query differs only by the clock reads.
// After each series, `stall_share` is the share of 0.1 s of wall-clock time this thread lost in stalls of at
// least 1 us (gaps between back-to-back clock reads) without a context switch: time the machine takes
// (timer interrupts, the hypervisor). A stall that begins before a deadline and ends after it delays the
// answer past it, whatever the query does, so it shows in p99_us once stalls take about 1% of the time.
// The trees and queries are the run-time layer's (engine/any_tree.hpp): a timed query is one
// PreparedQuery::run of one pose: its call and the answer handed back add about 30 ns to the times.
//
//   bench_deadline [--meshes=injector_pipes.stl,occt_tr12j_housing.stl] [--bv=aabb,obb]
//                  [--deadlines=2,5,10,20] [--distances=1.2,1.4,1.6,1.8] [--steps=500] [--min-pops=40]
//                  [benchmark flags]
#include "bench/core/bench_flags.hpp"
#include "engine/any_tree.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/protocol.hpp"
#include "engine/specs.hpp"

#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using Clock = std::chrono::steady_clock;

/// The value at quantile q of sorted `v` (nearest rank).
double quantile(const std::vector<double>& v, double q) {
  const auto rank = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(rank, v.size() - 1)];
}

/// Context switches of this thread so far, voluntary or not.
long context_switches() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_nvcsw + usage.ru_nivcsw;
}

/// The share of `span` of wall-clock time lost in gaps of at least 1 us between back-to-back clock reads,
/// leaving out the gaps during which the thread was switched out (those count in `switched`).
double stall_share(std::chrono::milliseconds span) {
  const auto start = Clock::now();
  auto last = start;
  long switches = context_switches();
  Clock::duration lost{};
  for (auto now = start; now - start < span; last = now) {
    now = Clock::now();
    if (now - last < std::chrono::microseconds(1)) continue;
    if (const long seen = context_switches(); seen == switches)
      lost += now - last;
    else
      switches = seen;
    now = Clock::now();  // the next gap starts after the reading of the switches
  }
  return std::chrono::duration<double>(lost) / std::chrono::duration<double>(last - start);
}

/// Times every pose warm (one untimed query, then one timed), once per benchmark iteration.
void run_deadline(benchmark::State& state, const PreparedQuery& query,
                  const std::vector<RigidTransform>& poses, double deadline_us) {
  std::vector<double> micros, undisturbed;
  std::size_t flagged = 0;
  bool collides = false, exhausted = false, sink = false;
  const ResultSink keep = [&](std::size_t, const Result& r) {
    collides = r.collides;
    exhausted = r.budget_exhausted;
  };
  for (auto _ : state) {
    for (const RigidTransform& pose : poses) {
      query.run({&pose, 1}, keep);  // warms the caches for this pose
      sink ^= collides;
      const long switches = context_switches();
      const auto start = Clock::now();
      query.run({&pose, 1}, keep);
      const auto stop = Clock::now();
      const double us = std::chrono::duration<double, std::micro>(stop - start).count();
      micros.push_back(us);
      if (context_switches() == switches) undisturbed.push_back(us);
      flagged += exhausted;
      sink ^= collides;
    }
  }
  benchmark::DoNotOptimize(sink);
  std::sort(micros.begin(), micros.end());
  std::sort(undisturbed.begin(), undisturbed.end());
  // Queries during which the thread was switched out (another process took the core) count in p99_us but
  // not in p99_undisturbed_us: the difference is the machine's load, not the deadline check.
  state.counters["switched"] =
      1 - static_cast<double>(undisturbed.size()) / static_cast<double>(micros.size());
  if (!undisturbed.empty()) state.counters["p99_undisturbed_us"] = quantile(undisturbed, 0.99);
  double mean = 0;
  for (double t : micros) mean += t;
  state.counters["mean_us"] = mean / static_cast<double>(micros.size());
  state.counters["median_us"] = quantile(micros, 0.5);
  state.counters["p99_us"] = quantile(micros, 0.99);
  state.counters["max_us"] = micros.back();
  state.counters["flagged"] = static_cast<double>(flagged) / static_cast<double>(micros.size());
  state.counters["poses"] = static_cast<double>(poses.size());
  state.counters["stall_share"] = stall_share(std::chrono::milliseconds(100));
  if (deadline_us > 0 && deadline_us < 1e9)
    state.counters["p99_over_us"] = quantile(micros, 0.99) - deadline_us;
}

struct Setup {
  std::vector<double> deadlines{2, 5, 10, 20};
  std::vector<double> distances{1.2, 1.4, 1.6, 1.8};
  int steps = 500;
  std::uint64_t min_pops = 40;
};

/// ADB at p_min 0.9 without a budget, or time-critical with a deadline of `deadline_us`.
StrategyVariant adb_variant(double deadline_us) {
  if (deadline_us == 0) return strategy_variant("adb", {{"p_min", 0.9}}, Budget{});
  return strategy_variant("time_critical", {{"p_min", 0.9}}, Budget{.deadline_us = deadline_us});
}

void register_mesh(const std::string& label, const std::string& bv, const Mesh& mesh, const Setup& setup) {
  const auto tree = std::make_shared<const AnyTree>(
      AnyTree::build(mesh, MeshUnits{}, bv, density_spec("adb", {{"grid", 2}}), BuildOptions{}));
  auto poses = std::make_shared<std::vector<RigidTransform>>();
  const auto unbudgeted = tree->prepare(*tree, adb_variant(0));
  for (double d : setup.distances) {
    const std::vector<RigidTransform> all = protocol_poses(d, setup.steps);
    unbudgeted->run(all, [&](std::size_t k, const Result& r) {
      if (r.counters.nodes_visited >= setup.min_pops) poses->push_back(all[k]);
    });
  }
  std::fprintf(stderr, "bench_deadline: %s on %s: %zu long poses (>= %ju node pairs)\n", label.c_str(),
               bv.c_str(), poses->size(), std::uintmax_t(setup.min_pops));
  if (poses->empty()) return;
  auto add = [&](const std::string& series, double deadline_us) {
    const std::shared_ptr<const PreparedQuery> query = tree->prepare(*tree, adb_variant(deadline_us));
    const std::string name = label + "/" + bv + "/" + series;
    benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
      run_deadline(state, *query, *poses, deadline_us);
    })->Unit(benchmark::kMillisecond);
  };
  add("no_budget", 0);
  add("deadline_never_reached", 1e9);
  for (double deadline : setup.deadlines) {
    char series[64];
    std::snprintf(series, sizeof series, "deadline_us:%g", deadline);
    add(series, deadline);
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  // The housing for OBB: no OBB query on the pipes takes --min-pops node pairs (ADB counts in node frames).
  std::vector<std::string> meshes{"injector_pipes.stl", "occt_tr12j_housing.stl"};
  std::vector<std::string> volumes{"aabb", "obb"};
  Setup setup;
  if (auto exit = initialize_benchmark("bench_deadline",
                                       {{"meshes", &meshes, "meshes to run"},
                                        {"bv", &volumes, "bounding volumes"},
                                        {"deadlines", &setup.deadlines, "deadlines in microseconds"},
                                        {"distances", &setup.distances, "protocol distances"},
                                        {"steps", &setup.steps, "poses per distance"},
                                        {"min-pops", &setup.min_pops, "pops between clock reads"}},
                                       argc, argv))
    return *exit;
  try {
    if (setup.steps < 1) throw std::invalid_argument("--steps must be at least 1");
    for (double d : setup.deadlines)
      if (!(d > 0 && d < 1e9)) throw std::invalid_argument("--deadlines must lie in (0, 1e9) microseconds");
    for (const auto& file : meshes) {
      if (!find_mesh(file)) {
        std::fprintf(stderr, "bench_deadline: skipping %s (not found; run meshes/fetch.sh)\n", file.c_str());
        continue;
      }
      const Mesh mesh = load_protocol_mesh(file);
      const std::string label = std::filesystem::path(file).stem().string();
      for (const auto& v : volumes) register_mesh(label, v, mesh, setup);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_deadline: %s\n", e.what());
    return 2;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
