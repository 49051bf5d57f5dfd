// ADB error and speed on the protocol (adb/README.md, section 4): ADB on AABB (g = 2) for a list of p_min,
// side by side with bvhlab's exact trees, in one binary. Per (mesh, strategy, distance): time per query,
// false-positive and false-negative rates against exact ground truth, BV tests per query. At the end, a
// summary per mesh: for every p_min the mean time, the total error, and the speed-up over each exact tree;
// and the operating point: the fastest p_min whose total error is at most 4%. With --wide (the default), the
// ADB and exact series run on the trees' wide layout too (`..._wide`; traversal/wide_adb.hpp): ADB's wide
// walk estimates other pairs, so its error rates are its own.
// The trees and queries are the run-time layer's (engine/any_tree.hpp), compiled once in the engine: a pass
// over a distance's poses is one PreparedQuery::run, each answer handed back through one indirect call.
//
//   bench_adb [--meshes=a,b] [--steps=200] [--p-min=0.5,0.7,...] [--exact=aabb,dop24] [--grid=2]
//             [--tau=0.5] [--distances=1.2,1.4,...] [--wide=true] [benchmark flags]
#include "bench/core/bench_flags.hpp"
#include "engine/any_tree.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/policies.hpp"
#include "engine/protocol.hpp"
#include "engine/specs.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct Workload {
  std::vector<double> distances;
  std::vector<std::vector<RigidTransform>> poses;  // per distance
  std::vector<std::vector<char>> truth;            // per distance, per pose
};

struct Measured {
  double seconds_per_query = 0;
  std::size_t queries = 0, false_positives = 0, false_negatives = 0;
  double bv_tests = 0, estimates = 0;
};
// (mesh, strategy label) -> per distance. Filled by the benchmark bodies; read by the summary.
std::map<std::pair<std::string, std::string>, std::map<double, Measured>> g_measured;

void run_poses(benchmark::State& state, const Workload& w, std::size_t d, const PreparedQuery& query,
               Measured& out) {
  const auto& poses = w.poses[d];
  const auto& truth = w.truth[d];
  std::size_t fp = 0, fn = 0;
  double bv_tests = 0, estimates = 0;
  const ResultSink count = [&](std::size_t k, const Result& r) {
    fp += r.collides && !truth[k];
    fn += !r.collides && truth[k];
    bv_tests += static_cast<double>(r.counters.bv_tests);
    estimates += static_cast<double>(r.counters.probability_evaluations);
  };
  std::size_t passes = 0;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    fp = fn = 0;
    bv_tests = estimates = 0;
    query.run(poses, count);
    ++passes;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double n = static_cast<double>(poses.size());
  out = {seconds / (static_cast<double>(passes) * n), poses.size(), fp, fn, bv_tests / n, estimates / n};
  state.counters["time_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["fp_rate"] = static_cast<double>(fp) / n;
  state.counters["fn_rate"] = static_cast<double>(fn) / n;
  state.counters["bv_tests"] = bv_tests / n;
  state.counters["estimates"] = estimates / n;
}

/// One benchmark per distance of `variant` on `tree` against itself, named label/strategy/d:….
void register_series(const std::string& label, const std::string& strategy,
                     const std::shared_ptr<const AnyTree>& tree, const StrategyVariant& variant,
                     const std::shared_ptr<const Workload>& w) {
  const std::shared_ptr<const PreparedQuery> query = tree->prepare(*tree, variant);
  for (std::size_t d = 0; d < w->distances.size(); ++d) {
    char name[160];
    std::snprintf(name, sizeof name, "%s/%s/d:%.1f", label.c_str(), strategy.c_str(), w->distances[d]);
    benchmark::RegisterBenchmark(name, [=](benchmark::State& state) {
      run_poses(state, *w, d, *query, g_measured[{label, strategy}][w->distances[d]]);
    })->Unit(benchmark::kMillisecond);
  }
}

/// `mesh`'s tree of volume `bv` without a density.
std::shared_ptr<const AnyTree> plain_tree(const Mesh& mesh, const std::string& bv) {
  return std::make_shared<const AnyTree>(
      AnyTree::build(mesh, MeshUnits{}, bv, density_spec("none", {}), BuildOptions{}));
}

/// The ADB series: `plain` (the AABB tree) annotated, one series per p_min.
void register_adb(const std::string& label, const AnyTree& plain, const std::shared_ptr<const Workload>& w,
                  const std::vector<double>& p_mins, int grid, double tau, bool wide) {
  AnnotateStats stats;
  const DensitySpec adb = density_spec("adb", {{"grid", grid}, {"tau", tau}});
  const auto tree = std::make_shared<const AnyTree>(plain.annotated(adb, AnnotationContext{}, &stats));
  std::fprintf(stderr, "bench_adb: %s annotated (g = %d) in %.2f s\n", label.c_str(), grid, stats.seconds);
  for (double p_min : p_mins) {
    char strategy[64];
    std::snprintf(strategy, sizeof strategy, "adb_aabb_g%d/p:%.2f", grid, p_min);
    StrategyVariant variant = strategy_variant("adb", {{"p_min", p_min}}, Budget{});
    register_series(label, strategy, tree, variant, w);
    if (!wide) continue;
    std::snprintf(strategy, sizeof strategy, "adb_aabb_g%d_wide/p:%.2f", grid, p_min);
    variant.wide = true;
    register_series(label, strategy, tree, variant, w);
  }
}

void print_summary(const std::vector<std::string>& exact_names) {
  std::map<std::string, std::vector<std::pair<std::string, Measured>>> by_mesh;
  for (const auto& [key, per_distance] : g_measured) {
    Measured total;
    double seconds = 0;
    for (const auto& [d, m] : per_distance) {
      seconds += m.seconds_per_query * static_cast<double>(m.queries);
      total.queries += m.queries;
      total.false_positives += m.false_positives;
      total.false_negatives += m.false_negatives;
      total.bv_tests += m.bv_tests * static_cast<double>(m.queries);
      total.estimates += m.estimates * static_cast<double>(m.queries);
    }
    if (total.queries == 0) continue;
    total.seconds_per_query = seconds / static_cast<double>(total.queries);
    total.bv_tests /= static_cast<double>(total.queries);
    total.estimates /= static_cast<double>(total.queries);
    by_mesh[key.first].emplace_back(key.second, total);
  }
  std::printf("\n=== ADB summary (means over all measured poses and distances) ===\n");
  for (const auto& [mesh, rows] : by_mesh) {
    std::map<std::string, double> exact_time;
    for (const auto& [strategy, m] : rows)
      if (strategy.rfind("exact_", 0) == 0) exact_time[strategy] = m.seconds_per_query;
    std::printf("\n%s\n%-24s %12s %8s %8s %8s %10s %10s", mesh.c_str(), "strategy", "us/query", "FP%", "FN%",
                "err%", "BV tests", "estimates");
    for (const auto& e : exact_names) std::printf("  vs %-14s", ("exact_" + e).c_str());
    std::printf("\n");
    std::string best;
    double best_time = 0;
    for (const auto& [strategy, m] : rows) {
      const double n = static_cast<double>(m.queries);
      const double fp = 100.0 * m.false_positives / n, fn = 100.0 * m.false_negatives / n;
      std::printf("%-24s %12.2f %8.2f %8.2f %8.2f %10.1f %10.1f", strategy.c_str(), m.seconds_per_query * 1e6,
                  fp, fn, fp + fn, m.bv_tests, m.estimates);
      for (const auto& e : exact_names) {
        const auto it = exact_time.find("exact_" + e);
        if (it != exact_time.end()) std::printf("  %12.2fx", it->second / m.seconds_per_query);
      }
      std::printf("\n");
      if (strategy.rfind("adb_", 0) == 0 && fp + fn <= 4.0 &&
          (best.empty() || m.seconds_per_query < best_time))
        best = strategy, best_time = m.seconds_per_query;
    }
    if (best.empty())
      std::printf("operating point: no p_min reaches total error <= 4%%\n");
    else
      for (const auto& e : exact_names) {
        const auto it = exact_time.find("exact_" + e);
        if (it != exact_time.end())
          std::printf("operating point (error <= 4%%): %s, %.2fx faster than exact %s\n", best.c_str(),
                      it->second / best_time, e.c_str());
      }
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"injector_pipes.stl", "occt_tr12j_housing.stl"};
  std::vector<std::string> exact{"aabb", "dop24"};
  std::vector<double> p_mins{0.5, 0.7, 0.8, 0.9, 0.95, 0.99};
  std::vector<double> distances = ProtocolOptions{}.distances;
  int steps = 200, grid = 2;
  bool wide = true;
  double tau = density_spec("adb", {}).values.at("tau");  // the density's default
  if (auto exit = initialize_benchmark("bench_adb",
                                       {{"meshes", &meshes, "meshes to run"},
                                        {"exact", &exact, "exact hierarchies to compare with"},
                                        {"p-min", &p_mins, "ADB's p_min values"},
                                        {"distances", &distances, "protocol distances"},
                                        {"steps", &steps, "poses per distance"},
                                        {"grid", &grid, "ADB grid (2, 3 or 4)"},
                                        {"tau", &tau, "ADB's tau"},
                                        {"wide", &wide, "also ADB and the exact trees on the wide layout"}},
                                       argc, argv))
    return *exit;
  try {
    if (steps < 1) throw std::invalid_argument("--steps must be at least 1");
    if (grid < 2 || grid > 4) throw std::invalid_argument("--grid must be 2, 3 or 4");
    for (const auto& file : meshes) {
      if (!find_mesh(file)) {
        std::fprintf(stderr, "bench_adb: skipping %s (not found; run meshes/fetch.sh)\n", file.c_str());
        continue;
      }
      const Mesh mesh = load_protocol_mesh(file);
      const std::string label = std::filesystem::path(file).stem().string();
      auto workload = std::make_shared<Workload>();
      workload->distances = distances;
      // One AABB tree: the truth (its exact answers, equal to CGAL's: tests/traversal), the exact AABB
      // series and the tree ADB annotates.
      const auto aabb = plain_tree(mesh, "aabb");
      const StrategyVariant exact_variant = strategy_variant("exact", {}, Budget{});
      const auto truth_query = aabb->prepare(*aabb, exact_variant);
      for (double d : distances) {
        workload->poses.push_back(protocol_poses(d, steps));
        auto& truth = workload->truth.emplace_back(workload->poses.back().size());
        truth_query->run(workload->poses.back(),
                         [&](std::size_t k, const Result& r) { truth[k] = r.collides; });
      }
      for (const auto& e : exact) {
        const auto tree = e == "aabb" ? aabb : plain_tree(mesh, e);
        register_series(label, "exact_" + e, tree, exact_variant, workload);
        if (!wide || !wide_layout_refusal(e).empty()) continue;
        StrategyVariant walked = exact_variant;
        walked.wide = true;
        register_series(label, "exact_" + e + "_wide", tree, walked, workload);
      }
      register_adb(label, *aabb, workload, p_mins, grid, tau, wide);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_adb: %s\n", e.what());
    return 2;
  }
  benchmark::RunSpecifiedBenchmarks();
  std::vector<std::string> exact_series;  // the summary's columns: each exact tree, binary and wide
  for (const auto& e : exact) {
    exact_series.push_back(e);
    if (wide && wide_layout_refusal(e).empty()) exact_series.push_back(e + "_wide");
  }
  print_summary(exact_series);
  benchmark::Shutdown();
  return 0;
}
