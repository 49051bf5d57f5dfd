// Distance queries on the protocol (adb/README.md, section 4) as Google Benchmark suites: mesh x BV x
// distance, with FCL 0.7's RSS and OBBRSS distance on the same meshes and poses in the same binary, so ratios
// come from one run. Only volumes with a distance bound (DistanceVolume) run; the others are skipped by name.
//
//   bench_distance [--meshes=a.stl,b.obj] [--steps=100] [--volumes=aabb,obb,rss] [benchmark flags]
//
// Each iteration runs every pose of one distance, so `time_per_query` is the mean time per query.
// Counters: BV tests and triangle-pair distances per query, the mean distance, and, on bvhlab's series, how
// many poses' distances differ from FCL OBBRSS's by more than 1e-9 relative (`fcl_disagree`), and the
// anytime distance's goal: the share of apart poses (distance > 0) whose interval, with a tenth of the full
// query's BV tests, is at most a tenth of the distance wide (`anytime_tenth`; -1 when no pose is apart),
// and the same with three tenths of the tests (`anytime_3tenths`).
// Each bvhlab series has a `/coherent` twin: the poses in order through query_distance_coherent.
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "traversal/distance.hpp"

#include <benchmark/benchmark.h>
#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_model.hpp"

#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct PoseSet {
  std::string label;
  std::vector<RigidTransform> poses;
  std::vector<double> reference;  ///< FCL OBBRSS's distance per pose (empty without FCL)
};

std::vector<PoseSet> make_pose_sets(int steps) {
  std::vector<PoseSet> sets;
  for (double d : ProtocolOptions{}.distances) {
    char label[16];
    std::snprintf(label, sizeof label, "%.1f", d);
    sets.push_back({label, protocol_poses(d, steps), {}});
  }
  return sets;
}

void set_counters(benchmark::State& state, std::size_t queries, const Counters& per_pass,
                  double distance_sum) {
  const double n = static_cast<double>(queries);
  state.counters["time_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["bv_tests"] = static_cast<double>(per_pass.bv_tests) / n;
  state.counters["tri_tests"] = static_cast<double>(per_pass.triangle_tests) / n;
  state.counters["mean_distance"] = distance_sum / n;
}

/// Poses whose distance differs from the reference by more than 1e-9 of the larger (and of 1e-12 absolute).
std::size_t disagreements(const std::vector<double>& distances, const std::vector<double>& reference) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < reference.size(); ++i)
    out += std::abs(distances[i] - reference[i]) >
           1e-9 * std::max({std::abs(distances[i]), std::abs(reference[i]), 1e-3});
  return out;
}

/// Share of the poses apart where query_distance_anytime, capped at `tenths` tenths of the full query's BV
/// tests, answers an interval at most a tenth of the distance wide; -1 when no pose is apart.
/// `full` holds each pose's full query.
template <class BV>
double anytime_share(const Bvh<BV>& tree, const std::vector<RigidTransform>& poses,
                     const std::vector<DistanceResult>& full, std::uint64_t tenths) {
  int apart = 0, narrow = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (!(full[i].distance > 0)) continue;
    ++apart;
    const Budget cap{std::max<std::uint64_t>(1, full[i].counters.bv_tests * tenths / 10), 0};
    const DistanceResult r = query_distance_anytime(tree, tree, poses[i], cap);
    narrow += r.distance - r.lower_bound <= 0.1 * full[i].distance;
  }
  return apart ? double(narrow) / apart : -1;
}

/// The same poses in order through query_distance_coherent, a fresh state each pass (its first pose is
/// cold); `coherent_disagree` counts poses whose distance is not the cold query's (it must be 0).
template <class BV>
void register_coherent(const std::string& name, const std::shared_ptr<const Bvh<BV>>& tree,
                       const PoseSet& set, const std::vector<double>& cold) {
  benchmark::RegisterBenchmark(name.c_str(), [tree, &set, cold](benchmark::State& state) {
    Counters pass;
    double sum = 0;
    std::size_t disagree = 0;
    for (auto _ : state) {
      pass = {};
      sum = 0;
      disagree = 0;
      CoherentState coherent;
      for (std::size_t i = 0; i < set.poses.size(); ++i) {
        const DistanceResult r = query_distance_coherent(*tree, *tree, set.poses[i], coherent);
        pass += r.counters;
        sum += r.distance;
        disagree += r.distance != cold[i];
      }
      benchmark::DoNotOptimize(sum);
    }
    set_counters(state, set.poses.size(), pass, sum);
    state.counters["coherent_disagree"] = static_cast<double>(disagree);
  })->Unit(benchmark::kMillisecond);
}

template <class BV>
void register_bvhlab(const std::string& mesh_name, const std::shared_ptr<const Mesh>& mesh,
                     const std::vector<PoseSet>& sets) {
  auto tree = std::make_shared<const Bvh<BV>>(Bvh<BV>::build(*mesh));
  for (const auto& set : sets) {
    std::vector<DistanceResult> full;
    std::vector<double> distances;
    for (const auto& pose : set.poses) {
      full.push_back(query_distance(*tree, *tree, pose));
      distances.push_back(full.back().distance);
    }
    const double disagree = static_cast<double>(disagreements(distances, set.reference));
    const double anytime_tenth = anytime_share(*tree, set.poses, full, 1);
    const double anytime_3tenths = anytime_share(*tree, set.poses, full, 3);
    const std::string name = "distance/" + mesh_name + "/" + std::string(BV::name()) + "/d:" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [tree, &set, disagree, anytime_tenth,
                                                anytime_3tenths](benchmark::State& state) {
      Counters pass;
      double sum = 0;
      for (auto _ : state) {
        pass = {};
        sum = 0;
        for (const auto& pose : set.poses) {
          const DistanceResult r = query_distance(*tree, *tree, pose);
          pass += r.counters;
          sum += r.distance;
        }
        benchmark::DoNotOptimize(sum);
      }
      set_counters(state, set.poses.size(), pass, sum);
      if (!set.reference.empty()) state.counters["fcl_disagree"] = disagree;
      state.counters["anytime_tenth"] = anytime_tenth;
      state.counters["anytime_3tenths"] = anytime_3tenths;
    })->Unit(benchmark::kMillisecond);
    register_coherent(name + "/coherent", tree, set, distances);
  }
}

#ifdef BVHLAB_HAVE_FCL
template <class FclBV>
void register_fcl(const std::string& mesh_name, const std::string& bv_name,
                  const std::shared_ptr<const Mesh>& mesh, const std::vector<PoseSet>& sets) {
  const auto model = make_fcl_model<FclBV>(*mesh);
  for (const auto& set : sets) {
    const std::string name = "fcl/" + mesh_name + "/" + bv_name + "/d:" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [model, &set](benchmark::State& state) {
      double sum = 0;
      for (auto _ : state) {
        sum = 0;
        for (const auto& pose : set.poses) sum += fcl_distance(*model, *model, pose).distance;
        benchmark::DoNotOptimize(sum);
      }
      set_counters(state, set.poses.size(), {}, sum);
    })->Unit(benchmark::kMillisecond);
  }
}
#endif

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"injector_pipes.stl", "jeep1.ms3d", "bunny.obj"};
  std::vector<std::string> volumes{"aabb", "dop24", "obb", "sphere", "rss"};
  int steps = 100;
  if (auto exit =
          initialize_benchmark("bench_distance",
                               {{"meshes", &meshes, "meshes to run"},
                                {"volumes", &volumes, "bounding volumes (those with a distance bound)"},
                                {"steps", &steps, "poses per distance"}},
                               argc, argv))
    return *exit;
  if (steps < 1) {
    std::fprintf(stderr, "bench_distance: --steps must be at least 1\n");
    return 2;
  }
  for_each_protocol_mesh("bench_distance", meshes, [&](const std::string& label, const auto& mesh) {
    // One pose list per mesh, kept to the end of main: the benchmarks hold references into it.
    static std::deque<std::vector<PoseSet>> per_mesh;
    auto& sets = per_mesh.emplace_back(make_pose_sets(steps));
#ifdef BVHLAB_HAVE_FCL
    const auto reference = make_fcl_model<fcl::OBBRSSd>(*mesh);
    for (auto& set : sets)
      for (const auto& pose : set.poses)
        set.reference.push_back(fcl_distance(*reference, *reference, pose).distance);
#endif
    for (const auto& v : volumes) {
      with_volume(v, [&]<class BV>(std::type_identity<BV>) {
        if constexpr (DistanceVolume<BV>)
          register_bvhlab<BV>(label, mesh, sets);
        else
          std::fprintf(stderr, "bench_distance: skipping %s (no distance bound)\n", v.c_str());
      });
    }
#ifdef BVHLAB_HAVE_FCL
    register_fcl<fcl::RSSd>(label, "fcl_rss", mesh, sets);
    register_fcl<fcl::OBBRSSd>(label, "fcl_obbrss", mesh, sets);
#endif
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
