// Coherent against cold exact queries on the protocol (traversal/coherent.hpp): B turns by one step of
// `--steps` per query at each distance, and every `--strides`-th pose is asked, in order.
//
//   bench_coherence [--meshes=a.stl,b.obj] [--volumes=aabb,dop24] [--steps=2000] [--strides=1,8,64]
//                   [--distances=0.6,1.0,1.4] [--judge=work|time] [--max_cold_run=128] [--max_jump=0.2]
//                   [--raise_hold=8] [benchmark flags]
//
// One iteration is one cold pass and one coherent pass over the same poses (a fresh state), in alternating
// order, each timed on its own: the ratio of each iteration's two passes is what is compared, so a stall
// of the machine touches both sides of one ratio or neither. Counters (over the iterations): the median
// speed-up cold/coherent and its interquartile range, each side's median microseconds per query, BV and
// triangle tests per query, the share of queries the remembered contact answered, pose jumps, the share
// of queries that started from the root because the front had cost more (cold_share), and the
// disagreements with the cold answers (the run fails unless 0).
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "bench/report_tables.hpp"
#include "engine/any_tree.hpp"
#include "engine/protocol.hpp"
#include "traversal/coherent_state.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct PoseSet {
  std::string label;
  std::vector<RigidTransform> poses;
};

std::vector<PoseSet> make_pose_sets(const std::vector<double>& distances, int steps,
                                    const std::vector<double>& strides) {
  std::vector<PoseSet> sets;
  for (double stride : strides)
    for (double d : distances) {
      PoseSet set;
      set.label =
          "d:" + std::to_string(d).substr(0, 3) + "/stride:" + std::to_string(static_cast<int>(stride));
      set.poses = protocol_poses(d, steps, static_cast<int>(stride));
      sets.push_back(std::move(set));
    }
  return sets;
}

/// One pass over the poses: its seconds, work and answers.
struct Pass {
  double seconds = 0;
  Counters work;
  std::vector<bool> answers;
};

/// One pass of `query` over `poses`, continuing `state` when given (a coherent query).
Pass timed_pass(const PreparedQuery& query, const std::vector<RigidTransform>& poses,
                CoherentState* state = nullptr) {
  Pass pass;
  pass.answers.resize(poses.size());
  const ResultSink record = [&](std::size_t k, const Result& r) {
    pass.work += r.counters;
    pass.answers[k] = r.collides;
  };
  const auto start = std::chrono::steady_clock::now();
  if (state)
    query.run(poses, record, *state);
  else
    query.run(poses, record);
  pass.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return pass;
}

struct Series {
  std::vector<double> cold_us, coherent_us, ratios;
  Counters cold_work, coherent_work;
  std::uint64_t witness_hits = 0, jumps = 0, cold_queries = 0, disagreements = 0;
};

void set_counters(benchmark::State& state, const Series& s, std::size_t queries) {
  using report_tables::quantile;
  const double n = static_cast<double>(queries);
  const double passes = static_cast<double>(s.ratios.size());
  state.counters["speedup"] = quantile(s.ratios, 0.5);
  state.counters["speedup_q1"] = quantile(s.ratios, 0.25);
  state.counters["speedup_q3"] = quantile(s.ratios, 0.75);
  state.counters["cold_us"] = quantile(s.cold_us, 0.5);
  state.counters["coherent_us"] = quantile(s.coherent_us, 0.5);
  state.counters["cold_bv"] = static_cast<double>(s.cold_work.bv_tests) / (n * passes);
  state.counters["coherent_bv"] = static_cast<double>(s.coherent_work.bv_tests) / (n * passes);
  state.counters["cold_tri"] = static_cast<double>(s.cold_work.triangle_tests) / (n * passes);
  state.counters["coherent_tri"] = static_cast<double>(s.coherent_work.triangle_tests) / (n * passes);
  state.counters["cold_nodes"] = static_cast<double>(s.cold_work.nodes_visited) / (n * passes);
  state.counters["coherent_nodes"] = static_cast<double>(s.coherent_work.nodes_visited) / (n * passes);
  state.counters["witness_share"] = static_cast<double>(s.witness_hits) / (n * passes);
  state.counters["jumps"] = static_cast<double>(s.jumps) / passes;
  state.counters["cold_share"] = static_cast<double>(s.cold_queries) / (n * passes);
  state.counters["disagreements"] = static_cast<double>(s.disagreements);
}

/// One iteration's two passes, added to the series.
void record(Series& s, const Pass& cold, const Pass& coherent, const CoherentState& state, double per_query) {
  s.cold_us.push_back(cold.seconds * per_query);
  s.coherent_us.push_back(coherent.seconds * per_query);
  s.ratios.push_back(cold.seconds / coherent.seconds);
  s.cold_work += cold.work;
  s.coherent_work += coherent.work;
  s.witness_hits += state.witness_hits();
  s.jumps += state.jumps();
  s.cold_queries += state.cold_queries();
  for (std::size_t k = 0; k < cold.answers.size(); ++k)
    s.disagreements += cold.answers[k] != coherent.answers[k];
}

/// Cold and coherent passes over `poses`, alternating which goes first.
/// The states' options, from --judge, --max_cold_run and --max_jump.
CoherenceOptions coherence_options;

/// The exact query of one tree against itself, cold and coherent (the run-time layer's, engine/any_tree.hpp).
struct Queries {
  std::unique_ptr<PreparedQuery> cold, coherent;
};

void run_series(benchmark::State& state, const Queries& q, const std::vector<RigidTransform>& poses) {
  Series s;
  bool cold_first = true;
  for (auto _ : state) {
    CoherentState coherence(coherence_options);
    Pass c, h;
    if (cold_first)
      c = timed_pass(*q.cold, poses), h = timed_pass(*q.coherent, poses, &coherence);
    else
      h = timed_pass(*q.coherent, poses, &coherence), c = timed_pass(*q.cold, poses);
    cold_first = !cold_first;
    record(s, c, h, coherence, 1e6 / static_cast<double>(poses.size()));
  }
  set_counters(state, s, poses.size());
  if (s.disagreements) state.SkipWithError("coherent answers differ from the cold ones");
}

void register_volume(const std::string& mesh_name, const Mesh& mesh, const std::string& bv,
                     const std::vector<PoseSet>& sets) {
  const AnyTree tree = AnyTree::build(mesh, MeshUnits{}, bv, density_spec("none", {}), BuildOptions{});
  StrategyVariant cold = strategy_variant("exact", {}, Budget{}), coherent = cold;
  coherent.coherent = true;
  auto queries =
      std::make_shared<const Queries>(Queries{tree.prepare(tree, cold), tree.prepare(tree, coherent)});
  for (const auto& set : sets) {
    const std::string name = mesh_name + "/" + bv + "/" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [queries, &set](benchmark::State& state) {
      run_series(state, *queries, set.poses);
    })->Unit(benchmark::kMillisecond);
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"jeep1.ms3d", "injector_pipes.stl"};
  std::vector<std::string> volumes{"aabb", "dop24", "obb", "rbox"};
  std::vector<double> distances{0.6, 1.0, 1.4};
  std::vector<double> strides{1, 8, 64};
  int steps = 2000;
  std::string judge_name = "work";
  int max_cold_run = static_cast<int>(CoherenceOptions{}.max_cold_run);
  double max_jump = CoherenceOptions{}.max_jump;
  int raise_hold = CoherenceOptions{}.raise_hold;
  if (auto exit = initialize_benchmark(
          "bench_coherence",
          {{"meshes", &meshes, "meshes to run"},
           {"volumes", &volumes, "bounding volumes"},
           {"distances", &distances, "protocol distances"},
           {"strides", &strides, "ask every m-th pose of the turn (step size)"},
           {"steps", &steps, "poses per full turn"},
           {"judge", &judge_name, "what decides front or root: work or time"},
           {"max_cold_run", &max_cold_run, "longest run of cold queries (0: none)"},
           {"max_jump", &max_jump, "a pose jump, in B's root radii, starts from the root"},
           {"raise_hold", &raise_hold, "queries a pair waits before raising is tried again (0 to 255)"}},
          argc, argv))
    return *exit;
  if (steps < 1 || std::any_of(strides.begin(), strides.end(), [](double m) { return !(m >= 1); })) {
    std::fprintf(stderr, "bench_coherence: --steps and every stride must be at least 1\n");
    return 2;
  }
  try {
    coherence_options.judge = judge_from_string(judge_name);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_coherence: --judge: %s\n", e.what());
    return 2;
  }
  if (max_cold_run < 0) {
    std::fprintf(stderr, "bench_coherence: --max_cold_run must be at least 0\n");
    return 2;
  }
  if (raise_hold < 0 || raise_hold > 255) {
    std::fprintf(stderr, "bench_coherence: --raise_hold must be 0 to 255\n");
    return 2;
  }
  coherence_options.raise_hold = static_cast<std::uint8_t>(raise_hold);
  coherence_options.max_cold_run = static_cast<std::uint32_t>(max_cold_run);
  coherence_options.max_jump = max_jump;
  try {
    coherence_options.validate();
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_coherence: --max_jump: %s\n", e.what());
    return 2;
  }
  static const std::vector<PoseSet> sets = make_pose_sets(distances, steps, strides);
  try {
    for (const auto& v : volumes) check_volume_name(v);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_coherence: --volumes: %s\n", e.what());
    return 2;
  }
  for_each_protocol_mesh("bench_coherence", meshes, [&](const std::string& label, const auto& mesh) {
    for (const auto& v : volumes) register_volume(label, *mesh, v, sets);
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
