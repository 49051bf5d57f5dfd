// Point clouds on the tumbling protocol, as tables on stdout: each mesh against a copy of itself, clouds
// sampled from it at several densities. The measuring is bench/points/run.cpp (its header says what is
// counted and timed), the one `bvhlab report` runs on a scene with "points" (bench/scenes/points.json); this
// program takes its parameters as flags instead of a scene.
//
//   bench_points [--meshes=pinion.off] [--points=5000,20000] [--steps=200] [--band=1]
//                [--p-min=0.5,0.7,0.9,0.95,0.99] [--distances=0.4,...,2.0] [--leaf=16] [--octree-res=1,2]
#include "bench/core/bench_flags.hpp"
#include "bench/points/points.hpp"
#include "engine/mesh_catalog.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

void check(const PointsSpec& spec) {
  if (spec.steps < 1) throw std::invalid_argument("--steps must be at least 1");
  if (!(spec.band >= 0)) throw std::invalid_argument("--band must be at least 0 spacings");
  if (spec.leaf < 1) throw std::invalid_argument("--leaf must be at least 1");
  for (double n : spec.bv_tests)
    if (!(n >= 1 && n <= 1e9 && n == std::floor(n)))
      throw std::invalid_argument("--bv-tests must be whole numbers from 1 to 10^9");
  for (double r : spec.octree_res)
    if (!(r > 0 && r <= 1e3)) throw std::invalid_argument("--octree-res must be in (0, 1000] spacings");
  for (double p : spec.p_mins)
    if (!(p > 0 && p <= 1)) throw std::invalid_argument("--p-min must be in (0, 1]");
  for (double n : spec.densities)
    if (!(n >= 11 && n <= 1e7 && n == std::floor(n)))
      throw std::invalid_argument("--points must be whole numbers from 11 to 10^7");
}

/// One mesh against a copy of itself, normalised as the protocol's distances assume.
Scene mesh_scene(const std::string& file, const std::filesystem::path& path, const PointsSpec& spec) {
  Scene scene;
  scene.name = file;
  SceneObject object;
  object.name = object.mesh = file;
  object.path = path;
  object.normalize = true;
  scene.objects.push_back(object);
  scene.pairs.push_back({file, file});
  scene.points = spec;
  return scene;
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::vector<std::string> meshes{"pinion.off"};
  PointsSpec spec;
  spec.octree_res = {1, 2};  // without FCL the octree series are left out
  spec.cgal_sample = 0;
  if (auto exit = initialize_benchmark(
          "bench_points",
          {{"meshes", &meshes, "meshes to sample"},
           {"points", &spec.densities, "points per cloud, one cloud per value"},
           {"p-min", &spec.p_mins, "ADB's p_min values"},
           {"distances", &spec.distances, "protocol distances"},
           {"steps", &spec.steps, "poses per distance"},
           {"band", &spec.band, "ambiguous band, in point spacings"},
           {"leaf", &spec.leaf, "points per leaf"},
           {"bv-tests", &spec.bv_tests, "time-critical series: BV-test budgets at p_min 0.9"},
           {"octree-res", &spec.octree_res, "FCL octree voxel sides in point spacings (built with FCL)"}},
          argc, argv))
    return *exit;
  try {
    check(spec);
    for (const auto& file : meshes) {
      const auto path = find_mesh(file);
      if (!path) {
        std::fprintf(stderr, "bench_points: skipping %s (not found; run meshes/fetch.sh)\n", file.c_str());
        continue;
      }
      const PointsOutput output = run_points(mesh_scene(file, *path, spec), true);
      std::printf("\n=== %s: %d steps x %zu distances ===\n%s", file.c_str(), spec.steps,
                  spec.distances.size(), points_text(output).c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_points: %s\n", e.what());
    return 2;
  }
  return 0;
}
