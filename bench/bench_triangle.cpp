// Triangle-triangle test: the certified fast path against CGAL on the same pre-generated pair sets, so
// the speed ratio comes from one run. Each iteration tests every pair of a set once.
//
//   bench_triangle --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Sets (argument "set"): 0 "mixed" (general position, ~40% intersecting), 1 "near_miss" (gaps of 1e-9..1e-6
// at unit size, still decidable in double), 2 "touching" (exact contacts on a grid: the fast path must fall
// back to CGAL), 3 "axis_aligned" (triangles in axis planes, as in CAD meshes).
#include "bench/core/generators.hpp"
#include "bvh/triangle_intersection.hpp"
#include "bvh/triangle_intersection_fast.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

namespace bvhlab {
namespace {

using Rng = std::mt19937_64;
constexpr std::size_t kPairs = 4096;

struct PairSet {
  std::vector<TrianglePoints> p, q;
};

using generators::random_triangle;
using generators::uniform;
using generators::uniform_point;

PairSet mixed_set() {
  Rng rng(1);
  PairSet set;
  for (std::size_t i = 0; i < kPairs; ++i) {
    set.p.push_back(random_triangle(rng, uniform_point(rng, 0.0, 0.6)));
    set.q.push_back(random_triangle(rng, uniform_point(rng, 0.0, 0.6)));
  }
  return set;
}

// Half: Q's apex hovers 1e-9..1e-6 above P's face, the rest of Q beyond it (plane test nearly zero).
// Half: Q crosses P's plane just outside an edge of P (interval test nearly zero).
PairSet near_miss_set() {
  Rng rng(2);
  PairSet set;
  for (std::size_t i = 0; i < kPairs; ++i) {
    const TrianglePoints p = random_triangle(rng, Vec3::Zero());
    const Vec3 n = (p[1] - p[0]).cross(p[2] - p[0]).normalized();
    const double gap = std::pow(10.0, uniform(rng, -9, -6));
    TrianglePoints q;
    if (i % 2 == 0) {
      const double a = uniform(rng, 0.1, 0.8), b = uniform(rng, 0.1, 0.9 - a);
      const Vec3 apex = p[0] + a * (p[1] - p[0]) + b * (p[2] - p[0]) + gap * n;
      q = {apex, apex + 0.8 * n + uniform_point(rng, -0.4, 0.4),
           apex + 0.8 * n + uniform_point(rng, -0.4, 0.4)};
    } else {
      const Vec3 edge_point = p[0] + uniform(rng, 0.1, 0.9) * (p[1] - p[0]);
      const Vec3 outward =
          (p[1] - p[0]).cross(n).normalized() * ((p[2] - p[0]).dot((p[1] - p[0]).cross(n)) > 0 ? -1 : 1);
      const Vec3 base = edge_point + gap * outward;
      const Vec3 along = (p[1] - p[0]).normalized();
      q = {base + 0.5 * n, base - 0.5 * n + 0.3 * along, base + outward * uniform(rng, 0.1, 0.5) + 0.1 * n};
    }
    set.p.push_back(p);
    set.q.push_back(q);
  }
  return set;
}

// Exact contacts on an integer grid: shared vertices and edges. The filter cannot prove a zero.
PairSet touching_set() {
  Rng rng(3);
  PairSet set;
  const auto grid = [&rng] {
    return Vec3{double(std::uniform_int_distribution<int>(-8, 8)(rng)),
                double(std::uniform_int_distribution<int>(-8, 8)(rng)),
                double(std::uniform_int_distribution<int>(-8, 8)(rng))};
  };
  while (set.p.size() < kPairs) {
    const TrianglePoints p = {grid(), grid(), grid()};
    TrianglePoints q = {p[0], set.p.size() % 2 ? p[1] : grid(), grid()};
    if ((p[1] - p[0]).cross(p[2] - p[0]).isZero(0.0) || (q[1] - q[0]).cross(q[2] - q[0]).isZero(0.0))
      continue;
    set.p.push_back(p);
    set.q.push_back(q);
  }
  return set;
}

// Triangles in axis planes (CAD-like meshes): exact zeros inside the normals, general position otherwise.
PairSet axis_aligned_set() {
  Rng rng(4);
  PairSet set;
  const auto triangle = [&rng] {
    const int axis = std::uniform_int_distribution<int>(0, 2)(rng);
    const double level = uniform(rng, 0, 1);
    TrianglePoints t = {uniform_point(rng, 0, 1), uniform_point(rng, 0, 1), uniform_point(rng, 0, 1)};
    for (Vec3& v : t) v[axis] = level;
    return t;
  };
  for (std::size_t i = 0; i < kPairs; ++i) {
    set.p.push_back(triangle());
    set.q.push_back(triangle());
  }
  return set;
}

const PairSet& pair_set(int which) {
  static const PairSet sets[4] = {mixed_set(), near_miss_set(), touching_set(), axis_aligned_set()};
  return sets[which];
}

template <bool (*Test)(const TrianglePoints&, const TrianglePoints&)>
void run(benchmark::State& state) {
  const PairSet& set = pair_set(int(state.range(0)));
  std::size_t hits = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < set.p.size(); ++i) hits += Test(set.p[i], set.q[i]);
    benchmark::DoNotOptimize(hits);
  }
  state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(set.p.size()));
  // CPU seconds per pair (printed with an SI prefix, e.g. "21.0ns").
  state.counters["time_per_pair"] = benchmark::Counter(
      double(set.p.size()), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["intersecting"] = double(hits) / double(state.iterations() * set.p.size());
}

bool fast_inline(const TrianglePoints& p, const TrianglePoints& q) {
  return triangles_intersect_fast(p, q);
}

void set_names(benchmark::internal::Benchmark* b) {
  b->ArgName("set");
  for (int i = 0; i < 4; ++i) b->Arg(i);
}

// set: 0 = mixed, 1 = near_miss, 2 = touching, 3 = axis_aligned
BENCHMARK(run<fast_inline>)->Name("fast_inline")->Apply(set_names);
BENCHMARK(run<triangles_intersect>)->Name("fast_out_of_line")->Apply(set_names);
BENCHMARK(run<triangles_intersect_exact>)->Name("cgal_exact")->Apply(set_names);

}  // namespace
}  // namespace bvhlab

BENCHMARK_MAIN();
