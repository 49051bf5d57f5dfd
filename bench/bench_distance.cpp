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
// and the same with three tenths of the tests (`anytime_3tenths`), and the share no search of these trees
// can exceed with a tenth, the upper end given (`anytime_limit_tenth`, anytime_limit below).
// Each bvhlab series has a `/coherent` twin: the poses in order, each starting where the last one ended;
// and, for volumes with a wide distance walk (obb), a `<bv>_wide` twin on the trees' wide layout.
// bvhlab's queries are the run-time layer's prepared queries (engine/any_tree.hpp), compiled once there.
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"
#include "engine/protocol.hpp"
#include "traversal/coherent_state.hpp"

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
#include <span>
#include <stdexcept>
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

/// A tree's distance queries (the run-time layer's, engine/any_tree.hpp): full, full coherent, and full on
/// the wide layout (null where the volume has no wide distance walk).
struct Queries {
  std::unique_ptr<PreparedQuery> full, coherent, wide;
};

/// The wide variant's prepared query, or null where the strategy refuses it for this volume.
std::unique_ptr<PreparedQuery> prepare_wide(const AnyTree& tree, StrategyVariant variant) {
  variant.wide = true;
  try {
    return tree.prepare(tree, variant);
  } catch (const std::invalid_argument&) {
    return nullptr;
  }
}

/// Each pose's proximity under `query`; its work added to `work`.
std::vector<Proximity> proximities(const PreparedQuery& query, std::span<const RigidTransform> poses,
                                   Counters& work, CoherentState* state = nullptr) {
  std::vector<Proximity> out(poses.size());
  const ResultSink record = [&](std::size_t k, const Result& r) {
    out[k] = *r.proximity;
    work += r.counters;
  };
  if (state)
    query.run(poses, record, *state);
  else
    query.run(poses, record);
  return out;
}

/// The share of the poses apart (full distance above 0) for which `holds(i)` is true; -1 when none is apart.
template <class Predicate>
double share_of_apart(const std::vector<Proximity>& full, Predicate holds) {
  int apart = 0, count = 0;
  for (std::size_t i = 0; i < full.size(); ++i) {
    if (!(full[i].distance > 0)) continue;
    ++apart;
    count += holds(i);
  }
  return apart ? double(count) / apart : -1;
}

/// Share of the poses apart where the anytime distance, capped at `tenths` tenths of the full query's BV
/// tests, answers an interval at most a tenth of the distance wide; -1 when no pose is apart.
/// `full` and `full_work` hold each pose's full query.
double anytime_share(const AnyTree& tree, const std::vector<RigidTransform>& poses,
                     const std::vector<Proximity>& full, const std::vector<Counters>& full_work,
                     std::uint64_t tenths) {
  return share_of_apart(full, [&](std::size_t i) {
    const Budget cap{std::max<std::uint64_t>(1, full_work[i].bv_tests * tenths / 10), 0};
    Counters work;
    const auto query = tree.prepare(tree, strategy_variant("distance_anytime", {}, cap));
    const Proximity r = proximities(*query, std::span(poses).subspan(i, 1), work).front();
    return r.distance - r.lower_bound <= 0.1 * full[i].distance;
  });
}

/// The share of the poses apart where even a known distance d would close the interval to a tenth of it
/// within `tenths` tenths of the full query's BV tests; -1 when no pose is apart. Certifying a lower end of
/// 0.9 d means expanding every pair whose bound is below it, whatever the order (a front's smallest bound
/// rises only when that pair is expanded): the tolerance query at 0.9 d, which finds no pair within it,
/// does exactly that work. So no search over these trees' volume bounds, splitting pairs as the distance
/// query does, narrows more poses with that budget, even one handed the nearest pair for free.
double anytime_limit(const AnyTree& tree, const std::vector<RigidTransform>& poses,
                     const std::vector<Proximity>& full, const std::vector<Counters>& full_work,
                     std::uint64_t tenths) {
  return share_of_apart(full, [&](std::size_t i) {
    const auto query =
        tree.prepare(tree, strategy_variant("tolerance", {{"tolerance", 0.9 * full[i].distance}}, {}));
    Counters work;
    query->run(std::span(poses).subspan(i, 1), [&](std::size_t, const Result& r) {
      if (r.collides) throw std::logic_error("bench_distance: a pair within 0.9 of the distance");
      work = r.counters;
    });
    return work.bv_tests * 10 <= full_work[i].bv_tests * tenths;
  });
}

/// A twin of the full query's series: the same poses through the coherent query (in order, a fresh state
/// each pass, its first pose cold) or through the wide walk; `<twin>_disagree` counts poses whose distance
/// is not the binary cold query's (it must be 0: the same triangle pairs, measured alike).
enum class Twin { Coherent, Wide };
void register_twin(const std::string& name, const std::shared_ptr<const Queries>& q, Twin twin,
                   const PoseSet& set, const std::vector<double>& cold) {
  benchmark::RegisterBenchmark(name.c_str(), [q, twin, &set, cold](benchmark::State& state) {
    Counters pass;
    double sum = 0;
    std::size_t disagree = 0;
    for (auto _ : state) {
      pass = {};
      sum = 0;
      disagree = 0;
      CoherentState coherent;
      const std::vector<Proximity> got = twin == Twin::Coherent
                                             ? proximities(*q->coherent, set.poses, pass, &coherent)
                                             : proximities(*q->wide, set.poses, pass);
      for (std::size_t i = 0; i < got.size(); ++i) {
        sum += got[i].distance;
        disagree += got[i].distance != cold[i];
      }
      benchmark::DoNotOptimize(sum);
    }
    set_counters(state, set.poses.size(), pass, sum);
    state.counters[twin == Twin::Coherent ? "coherent_disagree" : "wide_disagree"] =
        static_cast<double>(disagree);
  })->Unit(benchmark::kMillisecond);
}

void register_bvhlab(const std::string& mesh_name, const Mesh& mesh, const std::string& bv,
                     const std::vector<PoseSet>& sets) {
  // The prepared queries keep the tree alive.
  const AnyTree tree = AnyTree::build(mesh, MeshUnits{}, bv, density_spec("none", {}), BuildOptions{});
  StrategyVariant full = strategy_variant("distance", {}, Budget{}), coherent = full;
  coherent.coherent = true;
  const auto q = std::make_shared<const Queries>(
      Queries{tree.prepare(tree, full), tree.prepare(tree, coherent), prepare_wide(tree, full)});
  for (const auto& set : sets) {
    std::vector<Proximity> first(set.poses.size());
    std::vector<Counters> first_work(set.poses.size());
    q->full->run(set.poses, [&](std::size_t k, const Result& r) {
      first[k] = *r.proximity;
      first_work[k] = r.counters;
    });
    std::vector<double> distances;
    for (const Proximity& p : first) distances.push_back(p.distance);
    const double disagree = static_cast<double>(disagreements(distances, set.reference));
    const double anytime_tenth = anytime_share(tree, set.poses, first, first_work, 1);
    const double anytime_3tenths = anytime_share(tree, set.poses, first, first_work, 3);
    const double limit_tenth = anytime_limit(tree, set.poses, first, first_work, 1);
    const std::string name = "distance/" + mesh_name + "/" + bv + "/d:" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [q, &set, disagree, anytime_tenth, anytime_3tenths,
                                                limit_tenth](benchmark::State& state) {
      Counters pass;
      double sum = 0;
      for (auto _ : state) {
        pass = {};
        sum = 0;
        for (const Proximity& p : proximities(*q->full, set.poses, pass)) sum += p.distance;
        benchmark::DoNotOptimize(sum);
      }
      set_counters(state, set.poses.size(), pass, sum);
      if (!set.reference.empty()) state.counters["fcl_disagree"] = disagree;
      state.counters["anytime_tenth"] = anytime_tenth;
      state.counters["anytime_3tenths"] = anytime_3tenths;
      state.counters["anytime_limit_tenth"] = limit_tenth;
    })->Unit(benchmark::kMillisecond);
    register_twin(name + "/coherent", q, Twin::Coherent, set, distances);
    if (q->wide)
      register_twin("distance/" + mesh_name + "/" + bv + "_wide/d:" + set.label, q, Twin::Wide, set,
                    distances);
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
  try {
    for (const auto& v : volumes) check_volume_name(v);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_distance: --volumes: %s\n", e.what());
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
      const std::string refusal = strategy_info("distance").volume_refusal(v);
      if (refusal.empty())
        register_bvhlab(label, *mesh, v, sets);
      else
        std::fprintf(stderr, "bench_distance: skipping %s (%s)\n", v.c_str(), refusal.c_str());
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
