// The exact-query protocol (adb/README.md, section 4) as Google Benchmark suites: mesh x BV x distance,
// with FCL 0.7's OBB and OBBRSS on the same meshes and poses in the same binary, so ratios come from one run.
//
//   bench_protocol [--meshes=a.stl,b.obj] [--steps=500] [--volumes=aabb,dop24] [--wide=false] [benchmark
//   flags]
//
// Each iteration runs every pose of one distance ("all": every distance), so `time_per_query` is the
// protocol's mean time per query. Each volume with a wide layout (all but rss) also runs its wide form
// (four children a node, traversal/wide_exact.hpp) as the series <volume>_wide, unless --wide=false. The
// queries are the run-time layer's (engine/any_tree.hpp), compiled once in the engine.
// Counters: BV tests and triangle tests per query, bytes per triangle.
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"
#include "engine/protocol.hpp"

#include <benchmark/benchmark.h>
#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_model.hpp"
#endif

#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct PoseSet {
  std::string label;  // distance, or "all"
  std::vector<RigidTransform> poses;
};

std::vector<PoseSet> make_pose_sets(int steps) {
  std::vector<PoseSet> sets;
  PoseSet all{"all", {}};
  for (double d : ProtocolOptions{}.distances) {
    char label[16];
    std::snprintf(label, sizeof label, "%.1f", d);
    sets.push_back({label, protocol_poses(d, steps)});
    all.poses.insert(all.poses.end(), sets.back().poses.begin(), sets.back().poses.end());
  }
  sets.push_back(std::move(all));
  return sets;
}

void set_per_query_counters(benchmark::State& state, std::size_t queries, const Counters& per_pass,
                            std::size_t colliding, double bytes_per_triangle) {
  const double n = static_cast<double>(queries);
  state.counters["time_per_query"] =
      benchmark::Counter(n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["bv_tests"] = static_cast<double>(per_pass.bv_tests) / n;
  state.counters["tri_tests"] = static_cast<double>(per_pass.triangle_tests) / n;
  state.counters["colliding"] = static_cast<double>(colliding) / n;
  if (bytes_per_triangle > 0) state.counters["bytes_per_tri"] = bytes_per_triangle;
}

/// One series per pose set: `query` over the set's poses per iteration.
void register_series(const std::string& prefix, const std::vector<PoseSet>& sets,
                     std::shared_ptr<const PreparedQuery> query, double bytes_per_triangle) {
  for (const auto& set : sets) {
    const std::string name = prefix + "/d:" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [query, bytes_per_triangle, &set](benchmark::State& state) {
      Counters pass;
      std::size_t colliding = 0;
      const ResultSink record = [&](std::size_t, const Result& r) {
        pass += r.counters;
        colliding += r.collides;
      };
      for (auto _ : state) {
        pass = {};
        colliding = 0;
        query->run(set.poses, record);
        benchmark::DoNotOptimize(colliding);
      }
      set_per_query_counters(state, set.poses.size(), pass, colliding, bytes_per_triangle);
    })->Unit(benchmark::kMillisecond);
  }
}

/// The exact query of volume `bv`'s tree of the mesh against itself, and of its wide form as the series
/// "<volume>_wide" (whose bytes per triangle count both forms: the wide walk reads the binary leaves).
void register_bvhlab(const std::string& mesh_name, const Mesh& mesh, const std::string& bv,
                     const std::vector<PoseSet>& sets, bool wide) {
  const AnyTree tree = AnyTree::build(mesh, MeshUnits{}, bv, density_spec("none", {}), BuildOptions{});
  StrategyVariant exact = strategy_variant("exact", {}, Budget{});
  const double triangles = double(tree.info().triangles);
  const std::string prefix = "exact/" + mesh_name + "/" + bv;
  register_series(prefix, sets, tree.prepare(tree, exact), tree.info().model_bytes / triangles);
  if (!wide || !wide_layout_refusal(bv).empty()) return;
  exact.wide = true;
  std::shared_ptr<const PreparedQuery> query = tree.prepare(tree, exact);
  register_series(prefix + "_wide", sets, std::move(query),
                  (tree.info().model_bytes + tree.wide_layout_bytes()) / triangles);
}

#ifdef BVHLAB_HAVE_FCL
template <class FclBV>
void register_fcl(const std::string& mesh_name, const std::string& bv_name,
                  const std::shared_ptr<const Mesh>& mesh, const std::vector<PoseSet>& sets) {
  const auto model = make_fcl_model<FclBV>(*mesh);
  for (const auto& set : sets) {
    const std::string name = "fcl/" + mesh_name + "/" + bv_name + "/d:" + set.label;
    benchmark::RegisterBenchmark(name.c_str(), [model, &set](benchmark::State& state) {
      const fcl::CollisionRequestd request(1, false);
      std::size_t colliding = 0;
      for (auto _ : state) {
        colliding = 0;
        for (const auto& pose : set.poses) {
          fcl::CollisionResultd result;
          fcl::collide(model.get(), fcl::Transform3d::Identity(), model.get(), fcl_transform(pose), request,
                       result);
          colliding += result.isCollision();
        }
        benchmark::DoNotOptimize(colliding);
      }
      set_per_query_counters(state, set.poses.size(), {}, colliding, 0);
    })->Unit(benchmark::kMillisecond);
  }
}
#endif

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"injector_pipes.stl", "occt_tr12j_housing.stl", "jeep1.ms3d", "bunny.obj"};
  std::vector<std::string> volumes = volume_names();
  int steps = 500;
  bool wide = true;
  if (auto exit = initialize_benchmark("bench_protocol",
                                       {{"meshes", &meshes, "meshes to run"},
                                        {"volumes", &volumes, "bounding volumes"},
                                        {"steps", &steps, "poses per distance"},
                                        {"wide", &wide, "also the wide form of volumes that have one"}},
                                       argc, argv))
    return *exit;
  if (steps < 1) {
    std::fprintf(stderr, "bench_protocol: --steps must be at least 1\n");
    return 2;
  }
  if (!volumes_known("bench_protocol", volumes)) return 2;
  static const std::vector<PoseSet> sets = make_pose_sets(steps);
  for_each_protocol_mesh("bench_protocol", meshes, [&](const std::string& label, const auto& mesh) {
    for (const auto& v : volumes) register_bvhlab(label, *mesh, v, sets, wide);
#ifdef BVHLAB_HAVE_FCL
    register_fcl<fcl::OBBd>(label, "fcl_obb", mesh, sets);
    register_fcl<fcl::OBBRSSd>(label, "fcl_obbrss", mesh, sets);
#endif
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
