// The series of bench_bv_test (bench/bench_bv_test.cpp): per volume, the exact query's BV tests recorded,
// then timed inside the query and alone. Included by the part files only, each of which instantiates the
// series of some of the registered volumes (series_part0.cpp, series_part1.cpp): with all ten in one unit
// it took 30 s to compile.
#pragma once

#include "bench/bv_test/series.hpp"
#include "bench/report_tables.hpp"
#include "engine/registry.hpp"
#include "traversal/exact.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace bvhlab::bv_test {

using Clock = std::chrono::steady_clock;

/// The exact strategy's hooks, also keeping every pair whose volumes are tested and the test's answer.
template <TreeVolume BV>
class RecordingHooks : public ExactHooks<BV> {
 public:
  RecordingHooks(const TreePair<BV>& trees, Result& result, std::vector<QueuedPair<BV>>& pairs,
                 std::vector<bool>& answers)
      : ExactHooks<BV>(trees, result, ContactMode::First), trees_(trees), pairs_(pairs), answers_(answers) {}
  bool evaluate(const QueuedPair<BV>& p) {
    const bool overlap = trees_.overlap(p);
    pairs_.push_back(p);
    answers_.push_back(overlap);
    return overlap;
  }

 private:
  const TreePair<BV>& trees_;
  std::vector<QueuedPair<BV>>& pairs_;
  std::vector<bool>& answers_;
};

/// The BV tests one pose's query made, in its order.
template <TreeVolume BV>
struct Recorded {
  RigidTransform pose;
  std::vector<QueuedPair<BV>> pairs;
  std::vector<bool> answers;
};

template <TreeVolume BV>
Recorded<BV> record(const Bvh<BV>& tree, const RigidTransform& pose) {
  Recorded<BV> out{pose, {}, {}};
  Result result;
  const auto context = VolumeWalker<BV>::make_context(pose);
  const TreePair<BV> trees(tree, tree, pose, context, result.counters);
  RecordingHooks<BV> hooks(trees, result, out.pairs, out.answers);
  Unlimited limit;
  traverse<DepthFirst, SplitLarger>(trees, hooks, limit);
  return out;
}

/// Replays every recorded test; returns how many answered otherwise.
template <TreeVolume BV>
std::uint64_t replay(const Bvh<BV>& tree, const std::vector<Recorded<BV>>& all) {
  std::uint64_t disagreements = 0;
  for (const Recorded<BV>& r : all) {
    const auto context = VolumeWalker<BV>::make_context(r.pose);
    for (std::size_t k = 0; k < r.pairs.size(); ++k) {
      const QueuedPair<BV>& p = r.pairs[k];
      disagreements += VolumeWalker<BV>::overlap(tree, p.a, p.wa, tree, p.b, p.wb, context) != r.answers[k];
    }
  }
  return disagreements;
}

template <TreeVolume BV>
void run_series(benchmark::State& state, const Bvh<BV>& tree, const std::vector<RigidTransform>& poses) {
  std::vector<Recorded<BV>> recorded;
  std::uint64_t tests = 0;
  for (const RigidTransform& pose : poses) {
    recorded.push_back(record(tree, pose));
    tests += recorded.back().pairs.size();
  }
  std::vector<double> in_query, alone, ratio;
  Counters work;
  std::uint64_t disagreements = 0;
  bool queries_first = true;
  for (auto _ : state) {
    double query_seconds = 0, replay_seconds = 0;
    const auto queries = [&] {
      const auto start = Clock::now();
      for (const RigidTransform& pose : poses) work += query_exact(tree, tree, pose).counters;
      query_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    };
    const auto tests_alone = [&] {
      const auto start = Clock::now();
      disagreements += replay(tree, recorded);
      replay_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    };
    if (queries_first)
      queries(), tests_alone();
    else
      tests_alone(), queries();
    queries_first = !queries_first;
    in_query.push_back(1e9 * query_seconds / static_cast<double>(tests));
    alone.push_back(1e9 * replay_seconds / static_cast<double>(tests));
    ratio.push_back(query_seconds / replay_seconds);
  }
  using report_tables::quantile;
  const double queries = static_cast<double>(poses.size() * in_query.size());
  state.counters["ns_in_query"] = quantile(in_query, 0.5);
  state.counters["ns_alone"] = quantile(alone, 0.5);
  state.counters["ns_alone_q1"] = quantile(alone, 0.25);
  state.counters["ns_alone_q3"] = quantile(alone, 0.75);
  state.counters["query_over_tests"] = quantile(ratio, 0.5);
  state.counters["bv_tests"] = static_cast<double>(work.bv_tests) / queries;
  state.counters["triangle_tests"] = static_cast<double>(work.triangle_tests) / queries;
  state.counters["disagreements"] = static_cast<double>(disagreements);
  if (work.bv_tests != tests * in_query.size())
    state.SkipWithError("the queries made other BV tests than recorded");
  if (disagreements) state.SkipWithError("a replayed BV test answered otherwise than in the query");
}

template <class BV>
void register_volume(const std::string& mesh_name, const std::shared_ptr<const Mesh>& mesh,
                     const std::vector<RigidTransform>& poses) {
  auto tree = std::make_shared<const Bvh<BV>>(Bvh<BV>::build(*mesh));
  const std::string name = mesh_name + "/" + std::string(BV::name());
  benchmark::RegisterBenchmark(name.c_str(), [tree, &poses](benchmark::State& state) {
    run_series(state, *tree, poses);
  })->Unit(benchmark::kMillisecond);
}

template <std::size_t Part>
bool register_volume_part(const std::string& volume, const std::string& mesh_name,
                          const std::shared_ptr<const Mesh>& mesh, const std::vector<RigidTransform>& poses) {
  return with_volume(volume, [&]<class BV>(std::type_identity<BV>) {
    if constexpr (type_index<BV>(RegisteredVolumes{}) % kParts == Part) {
      register_volume<BV>(mesh_name, mesh, poses);
      return true;
    } else {
      return false;
    }
  });
}

}  // namespace bvhlab::bv_test
