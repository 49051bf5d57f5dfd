// Time per BV test by volume: inside the exact traversal, and alone. What a faster test (vectorised, wider
// nodes) has to beat, and how much of a query is the test at all.
//
//   bench_bv_test [--meshes=jeep1.ms3d,bunny.obj] [--volumes=aabb,dop24,obb] [--distances=0.8,1.2,1.6,2.0]
//                 [--steps=200] [benchmark flags]
//
// Per mesh and volume, the exact first-contact query (query_exact, a mesh against itself) runs once on the
// protocol's poses of every distance and records, per pose, the node pairs whose volumes it tested (through
// the driver's hooks: the same traversal, the pairs with their walkers' state). One iteration then makes
// two passes over every pose, in alternating order, each timed as a whole: the queries, and the recorded
// tests alone (the volume's test and its walker, without queue, descent or triangles). Counters, medians
// over the iterations (q1, q3: quartiles): ns per BV test in the query (the pass's time over its BV tests:
// traversal and leaves included), ns per BV test alone, their ratio (the share of a query that is the test
// is its inverse), and BV and triangle tests per query. A replayed test that answers otherwise than the
// recorded one ends the run with an error (disagreements).
//
// The series are compiled in bench/bv_test/ (two units, half the volumes each).
#include "bench/bv_test/series.hpp"
#include "bench/core/bench_flags.hpp"
#include "bench/core/protocol_meshes.hpp"
#include "engine/protocol.hpp"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"jeep1.ms3d", "bunny.obj"};
  std::vector<std::string> volumes{"aabb", "dop24", "obb", "sphere", "rbox", "rss"};
  std::vector<double> distances{0.8, 1.2, 1.6, 2.0};
  int steps = 200;
  if (auto exit = initialize_benchmark("bench_bv_test",
                                       {{"meshes", &meshes, "meshes to run"},
                                        {"volumes", &volumes, "bounding volumes"},
                                        {"distances", &distances, "protocol distances"},
                                        {"steps", &steps, "poses per full turn"}},
                                       argc, argv))
    return *exit;
  if (steps < 1) {
    std::fprintf(stderr, "bench_bv_test: --steps must be at least 1\n");
    return 2;
  }
  if (!volumes_known("bench_bv_test", volumes)) return 2;
  static std::vector<RigidTransform> poses;
  for (double d : distances)
    for (const RigidTransform& pose : protocol_poses(d, steps)) poses.push_back(pose);
  for_each_protocol_mesh("bench_bv_test", meshes, [&](const std::string& label, const auto& mesh) {
    static_assert(bv_test::kParts == 2, "one call for each unit of the series");
    for (const auto& v : volumes)
      if (!bv_test::register_volume_part<0>(v, label, mesh, poses))
        bv_test::register_volume_part<1>(v, label, mesh, poses);
  });
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
