// One budget per frame (traversal/frame_budget.hpp): the frame scheduler's policies at equal frame budgets.
// Frames of 20 to 100 candidate pairs of the bundled meshes (pinion, jeep, teapot; protocol-normalised, ADB
// on AABB trees, g = 2) at random poses near contact, about a third colliding (deterministic seed); ground
// truth per pair from the exact strategy. For each frame size, policy and frame budget (BV tests: fractions
// of what the frame's ADB answers cost without a budget; or microseconds), the benchmark reports the time
// per frame and, as counters, the missed and the false colliding pairs per frame; budget "none" is ADB's own
// error without a budget (every policy gives the same answers then), beside the same pairs through query_adb
// one after the other (the scheduler's overhead). The summary adds the
// median and 90th percentile of a frame's wall time and compares every policy's misses with equal_split's.
//
//   bench_frame_budget [--pairs=20,50,100] [--frames=10] [--fractions=0.0625,0.125,0.25,0.5]
//                      [--deadlines=25,50,100,200] [--p-min=0.9] [--threshold=0.5] [--seed=1]
//                      [benchmark flags]
// --threshold: the best-effort rule on exhaustion ("collision" iff the best estimate left is at least it;
// set it to p_min for the strict rule).
#include "adb/adb_density.hpp"
#include "bench/core/bench_flags.hpp"
#include "engine/mesh_catalog.hpp"
#include "traversal/exact.hpp"
#include "traversal/frame_schedule.hpp"
#include "volumes/aabb.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {
namespace {

using AdbTree = Tree<Aabb, AdbDensity>;
using Frame = std::vector<FramePair<Aabb, AdbDensity>>;

/// The frames of one size, their ground truth, and what their answers cost without a budget.
struct FrameSet {
  std::shared_ptr<const std::vector<AdbTree>> trees;  // what the frames point into
  std::vector<Frame> frames;
  std::vector<std::vector<char>> truth;  // per frame, per pair
  std::uint64_t adb_cost = 0;            // BV tests of every frame under ADB without a budget, in total
  std::uint64_t exact_cost = 0;          // BV tests of the exact strategy on every pair
  std::size_t pairs = 0, colliding = 0;
};

/// B's pose: a random rotation, B's centre at `distance` from A's in a random direction.
RigidTransform pose_at(std::mt19937_64& rng, double distance) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.normalize();
  RigidTransform pose;
  pose.rotation = q.toRotationMatrix();
  pose.translation = distance * Vec3(normal(rng), normal(rng), normal(rng)).normalized();
  return pose;
}

/// `count` frames of `n` pairs near contact: centres 0.8 to 2.2 apart (longest sides 2), root boxes
/// overlapping, every third pair colliding (drawn until the exact answer fits).
FrameSet make_frames(const std::shared_ptr<const std::vector<AdbTree>>& trees, int n, int count,
                     std::uint64_t seed, const FrameOptions& unlimited) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> mesh(0, trees->size() - 1);
  std::uniform_real_distribution<double> distance(0.8, 2.2);
  FrameSet set;
  set.trees = trees;
  for (int f = 0; f < count; ++f) {
    Frame& frame = set.frames.emplace_back();
    auto& truth = set.truth.emplace_back();
    while (static_cast<int>(frame.size()) < n) {
      const bool colliding = frame.size() % 3 == 0;
      FramePair<Aabb, AdbDensity> pair{&(*trees)[mesh(rng)], &(*trees)[mesh(rng)],
                                       pose_at(rng, distance(rng)), std::nullopt};
      const Result exact = query_exact(pair.a->bvh, pair.b->bvh, pair.b_to_a);
      if (exact.collides != colliding || exact.counters.bv_tests < 3) continue;
      set.exact_cost += exact.counters.bv_tests;
      frame.push_back(pair);
      truth.push_back(colliding);
    }
    for (const auto& o : schedule_frame<Aabb, AdbDensity>(frame, unlimited))
      set.adb_cost += o.counters.bv_tests;
    set.pairs += frame.size();
    set.colliding += static_cast<std::size_t>(std::count(truth.begin(), truth.end(), 1));
  }
  return set;
}

struct Measured {
  double missed = 0, false_colliding = 0, flagged = 0, bv_tests = 0;  // per frame
  double median_us = 0, p90_us = 0;                                   // wall time of one schedule_frame call
};
// (pairs, budget label) -> policy -> measured. Filled by the benchmark bodies; read by the summary, in the
// order the budgets were registered.
std::map<std::pair<int, std::string>, std::map<std::string, Measured>> g_measured;
std::vector<std::pair<int, std::string>> g_budgets;

/// The q-quantile of `values` (reordered).
double quantile(std::vector<double>& values, double q) {
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

/// The frame's pairs one after the other through query_adb, without a budget: the scheduler's overhead is
/// the difference to schedule_frame without a budget.
std::vector<PairOutcome> pair_by_pair(const Frame& frame, const FrameOptions& options) {
  std::vector<PairOutcome> outcomes;
  for (const auto& p : frame) {
    const Result r = query_adb(*p.a, *p.b, p.b_to_a, options.pair_options());
    outcomes.push_back({r.collides, r.probability, r.budget_exhausted, r.exact, r.counters});
  }
  return outcomes;
}

void run_frames(benchmark::State& state, const FrameSet& set, const FrameOptions& options, bool scheduled,
                Measured& out) {
  double missed = 0, false_colliding = 0, flagged = 0, bv_tests = 0;
  std::vector<double> frame_us;
  for (auto _ : state) {
    for (std::size_t f = 0; f < set.frames.size(); ++f) {
      const auto start = std::chrono::steady_clock::now();
      const auto outcomes = scheduled ? schedule_frame<Aabb, AdbDensity>(set.frames[f], options)
                                      : pair_by_pair(set.frames[f], options);
      frame_us.push_back(
          std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
      for (std::size_t k = 0; k < outcomes.size(); ++k) {
        const bool truth = set.truth[f][k];
        missed += truth && !outcomes[k].collides;
        false_colliding += !truth && outcomes[k].collides;
        flagged += outcomes[k].budget_exhausted;
        bv_tests += static_cast<double>(outcomes[k].counters.bv_tests);
      }
    }
  }
  const double frames = static_cast<double>(frame_us.size());
  out = {missed / frames, false_colliding / frames, flagged / frames, bv_tests / frames, 0, 0};
  out.median_us = quantile(frame_us, 0.5);
  out.p90_us = quantile(frame_us, 0.9);
  state.counters["time_per_frame"] =
      benchmark::Counter(static_cast<double>(set.frames.size()),
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["missed"] = out.missed;
  state.counters["false_colliding"] = out.false_colliding;
  state.counters["flagged"] = out.flagged;
  state.counters["bv_tests"] = out.bv_tests;
}

/// Registers the frames of `set` under `options` for every policy, or for the policies `only` names.
void register_budget(int n, const std::shared_ptr<const FrameSet>& set, const std::string& label,
                     const FrameOptions& options, const std::vector<std::string_view>& only = {}) {
  g_budgets.emplace_back(n, label);
  for (const FramePolicy& policy : frame_policies()) {
    if (!only.empty() && std::find(only.begin(), only.end(), policy.name) == only.end()) continue;
    FrameOptions with_policy = options;
    with_policy.policy = policy.name;
    const std::string name =
        "frame/pairs:" + std::to_string(n) + "/" + label + "/" + std::string(policy.name);
    benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
      run_frames(state, *set, with_policy, true, g_measured[{n, label}][with_policy.policy]);
    })->Unit(benchmark::kMicrosecond);
  }
}

void print_summary() {
  std::printf(
      "\n=== Frame budget summary (means per frame; missed: colliding pairs answered \"no\"; false: "
      "pairs apart answered \"collision\") ===\n");
  std::printf("%-6s %-14s %-22s %8s %8s %8s %9s %10s %8s %10s\n", "pairs", "budget", "policy", "missed",
              "false", "flagged", "BV tests", "median us", "p90 us", "missed vs");
  std::printf("%102s\n", "equal_split");
  for (const auto& key : g_budgets) {
    const auto& policies = g_measured[key];
    const auto equal = policies.find("equal_split");
    for (const auto& [policy, m] : policies) {
      std::printf("%-6d %-14s %-22s %8.2f %8.2f %8.2f %9.0f %10.1f %8.1f", key.first, key.second.c_str(),
                  policy.c_str(), m.missed, m.false_colliding, m.flagged, m.bv_tests, m.median_us, m.p90_us);
      if (equal != policies.end() && equal->second.missed > 0 && policy != "equal_split")
        std::printf(" %+9.0f%%", 100 * (m.missed / equal->second.missed - 1));
      std::printf("\n");
    }
  }
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<double> pair_counts{20, 50, 100}, fractions{0.0625, 0.125, 0.25, 0.5},
      deadlines{25, 50, 100, 200};
  int frames = 10;
  std::uint64_t seed = 1;
  FrameOptions options;
  if (auto exit = initialize_benchmark(
          "bench_frame_budget",
          {{"pairs", &pair_counts, "pairs per frame"},
           {"frames", &frames, "frames per set"},
           {"fractions", &fractions, "BV-test budgets, as fractions of ADB's unbudgeted cost"},
           {"deadlines", &deadlines, "frame deadlines in microseconds"},
           {"p-min", &options.p_min, "p_min of every schedule"},
           {"threshold", &options.adb.best_effort_threshold, "best-effort answer threshold"},
           {"seed", &seed, "seed of the frames"}},
          argc, argv))
    return *exit;
  try {
    if (frames < 1) throw std::invalid_argument("--frames must be at least 1");
    for (double n : pair_counts)
      if (!(n >= 1)) throw std::invalid_argument("--pairs must be at least 1");
    for (double f : fractions)
      if (!(f > 0)) throw std::invalid_argument("--fractions must be positive");
    for (double d : deadlines)
      if (!(d > 0)) throw std::invalid_argument("--deadlines must be positive microseconds");
    options.validate();

    auto trees = std::make_shared<std::vector<AdbTree>>();
    for (const char* file : {"pinion.off", "jeep1.ms3d", "teapot.obj"})
      trees->push_back(annotate_adb(Bvh<Aabb>::build(load_protocol_mesh(file)), 2));
    for (double count : pair_counts) {
      const int n = static_cast<int>(count);
      const auto set = std::make_shared<const FrameSet>(
          make_frames(trees, n, frames, seed + static_cast<std::uint64_t>(n), options));
      std::fprintf(stderr,
                   "bench_frame_budget: %d frames of %d pairs, %zu of %zu colliding; without a budget ADB "
                   "spends %.0f BV tests per frame, the exact strategy %.0f\n",
                   frames, n, set->colliding, set->pairs, double(set->adb_cost) / frames,
                   double(set->exact_cost) / frames);
      register_budget(n, set, "none", options, {"adb_probability"});  // ADB's own error: the floor
      benchmark::RegisterBenchmark(
          ("frame/pairs:" + std::to_string(n) + "/none/query_adb").c_str(),
          [=](benchmark::State& state) {
            run_frames(state, *set, options, false, g_measured[{n, "none"}]["query_adb"]);
          })
          ->Unit(benchmark::kMicrosecond);
      for (double fraction : fractions) {
        FrameOptions budgeted = options;
        budgeted.budget.max_bv_tests =
            std::max<std::uint64_t>(1, static_cast<std::uint64_t>(fraction * double(set->adb_cost) / frames));
        char label[64];
        std::snprintf(label, sizeof label, "tests:%.4g", fraction);
        register_budget(n, set, label, budgeted);
      }
      for (double us : deadlines) {
        FrameOptions budgeted = options;
        budgeted.budget.deadline_us = us;
        char label[64];
        std::snprintf(label, sizeof label, "us:%g", us);
        register_budget(n, set, label, budgeted);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_frame_budget: %s\n", e.what());
    return 2;
  }
  benchmark::RunSpecifiedBenchmarks();
  print_summary();
  benchmark::Shutdown();
  return 0;
}
