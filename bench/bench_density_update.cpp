// ADB counts under deformation (adb/update.hpp): per density-update policy, the cost of following a
// deforming mesh (refit + update), the counts' error against an exact recount, and the ADB query's errors,
// against rebuilding and re-annotating the tree every frame.
//
//   bench_density_update [--mesh=bunny.obj] [--frames=6] [--twist=60] [--poses=64] [--threads=2]
//                        [benchmark flags]
//
// The mesh (protocol normalisation; a 72k-triangle wavy grid when the file is missing) twists about its
// y axis: at frame f of F the slice at height y turns by twist * f / F degrees times (y - y_min) / height.
// Every policy follows all frames in order on its own refitted tree. Per frame, untimed: the exact counts of
// the refitted tree (annotation from scratch) and the exact answer at `poses` poses of a second copy
// (protocol poses at d = 1.4 .. 2.0, the tree against itself). Timed: refit + update per policy, the
// rebuild + annotation, and the ADB queries (p_min 0.9 and 0.99) on each tree. Count errors are per node:
// mean |pc - exact|, the share of nodes whose count differs, the share under-counted (the ones that can hide
// a collision). The table's ratio is (refit + update + query) / (rebuild + annotate + query), summed over the
// frames.
#include "adb/adb_density.hpp"
#include "adb/update.hpp"
#include "bench/core/bench_flags.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/protocol.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct Settings {
  std::string mesh = "bunny.obj";
  int frames = 6;
  double twist_degrees = 60;
  int poses = 64;
  unsigned threads = 2;
  std::vector<double> p_mins{0.9, 0.99};
} g_settings;

/// A policy with its parameters, as one row of the table.
struct Variant {
  std::string label;
  std::string policy;
  ParamValues params;
};

const std::vector<Variant> kVariants = {
    {"stale", "stale", {}},
    {"recount_all", "recount_all", {}},
    {"recount_moved f=0.25", "recount_moved", {{"fraction", 0.25}}},
    {"recount_moved f=0.25 shape", "recount_moved", {{"fraction", 0.25}, {"ignore_translation", 1}}},
    {"recount_moved f=1 shape", "recount_moved", {{"fraction", 1}, {"ignore_translation", 1}}},
    {"samples 4 from_rest", "samples", {{"per_triangle", 4}, {"from_rest", 1}}},
    {"samples 4", "samples", {{"per_triangle", 4}, {"from_rest", 0}}},
    {"samples 16", "samples", {{"per_triangle", 16}, {"from_rest", 0}}},
    {"samples 64", "samples", {{"per_triangle", 64}, {"from_rest", 0}}},
};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A wavy square grid of 2 * 190^2 = 72,200 triangles in [-1, 1]^2: the stand-in for a missing mesh.
Mesh wavy_grid() {
  constexpr int n = 190;
  Mesh m;
  m.name = "wavy_grid";
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = -1 + 2.0 * i / n, z = -1 + 2.0 * j / n;
      m.vertices.emplace_back(x, 0.1 * std::sin(3 * x) * std::cos(2 * z), z);
    }
  auto id = [](int i, int j) { return static_cast<std::uint32_t>(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// The mesh twisted about its vertical (y) axis by `radians` from its bottom to its top.
Mesh twisted(const Mesh& rest, double radians) {
  const Box bounds = rest.bounds();
  const double height = std::max(1e-12, bounds.max.y() - bounds.min.y());
  Mesh out = rest;
  for (Vec3& v : out.vertices) {
    const double a = radians * (v.y() - bounds.min.y()) / height, c = std::cos(a), s = std::sin(a);
    v = Vec3(c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z());
  }
  return out;
}

/// Sums over the frames for one row.
struct Row {
  double refit_s = 0, update_s = 0, query_s = 0;              // for the rebuild row: build, annotate, query
  double abs_diff = 0, differ = 0, under = 0;                 // per-node means, summed over frames
  std::vector<std::size_t> false_negatives, false_positives;  // per p_min
  std::vector<double> query_p_s;                              // per p_min
  std::size_t queries = 0, recounted = 0, nodes = 0;
  Row()
      : false_negatives(g_settings.p_mins.size()),
        false_positives(g_settings.p_mins.size()),
        query_p_s(g_settings.p_mins.size()) {}
};

void add_count_errors(Row& row, const std::vector<std::uint8_t>& counts,
                      const std::vector<std::uint8_t>& exact) {
  double abs_diff = 0, differ = 0, under = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    const int d = int(counts[i]) - int(exact[i]);
    abs_diff += std::abs(d);
    differ += d != 0;
    under += d < 0;
  }
  const double n = static_cast<double>(exact.size());
  row.abs_diff += abs_diff / n;
  row.differ += differ / n;
  row.under += under / n;
}

/// ADB answers at the poses, per p_min: adds the time, false negatives and false positives to `row`; the
/// time of the first p_min is the row's query time.
void query(Row& row, const Tree<Aabb, AdbDensity>& tree, const std::vector<RigidTransform>& poses,
           const std::vector<bool>& truth) {
  for (std::size_t p = 0; p < g_settings.p_mins.size(); ++p) {
    AdbOptions options;
    options.p_min = g_settings.p_mins[p];
    const auto start = std::chrono::steady_clock::now();
    std::vector<bool> answers;
    answers.reserve(poses.size());
    for (const RigidTransform& pose : poses) answers.push_back(query_adb(tree, tree, pose, options).collides);
    const double seconds = seconds_since(start);
    row.query_p_s[p] += seconds;
    if (p == 0) row.query_s += seconds;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      row.false_negatives[p] += truth[k] && !answers[k];
      row.false_positives[p] += !truth[k] && answers[k];
    }
  }
  row.queries += poses.size();
}

/// One policy variant following the frames: its tree and its state.
struct Follower {
  Variant variant;
  std::shared_ptr<Tree<Aabb, AdbDensity>> tree;  // shared with `frame`
  std::function<void(const Mesh&, Row&)> frame;  // refit + update, timed into row
};

Follower make_follower(const Variant& variant, const Tree<Aabb, AdbDensity>& rest) {
  Follower f{variant, std::make_shared<Tree<Aabb, AdbDensity>>(rest), {}};
  with_density_update(variant.policy, [&](auto type) {
    using U = typename decltype(type)::type;
    auto state = std::make_shared<typename U::State>(
        U::start(f.tree->bvh, f.tree->density, update_params<U>(variant.params)));
    f.frame = [tree = f.tree, state](const Mesh& deformed, Row& row) {
      const auto start = std::chrono::steady_clock::now();
      tree->bvh.refit(deformed);
      row.refit_s += seconds_since(start);
      const auto update_start = std::chrono::steady_clock::now();
      DensityUpdateStats stats;
      U::update(tree->bvh, tree->density, *state, AnnotationContext{g_settings.threads, {}}, &stats);
      row.update_s += seconds_since(update_start);
      row.recounted += stats.recounted_nodes;
      row.nodes += stats.nodes;
    };
  });
  return f;
}

void print_table(const Mesh& mesh, const std::vector<Follower>& followers, const std::vector<Row>& rows,
                 const Row& rebuild, std::size_t colliding) {
  const double frames = g_settings.frames;
  const double base = rebuild.refit_s + rebuild.update_s + rebuild.query_s;
  const Row* exact_row = nullptr;
  for (std::size_t k = 0; k < followers.size(); ++k)
    if (followers[k].variant.policy == "recount_all") exact_row = &rows[k];
  auto rate = [](std::size_t n, std::size_t of) { return of ? 100.0 * double(n) / double(of) : 0.0; };
  std::printf(
      "\n%s: %zu triangles, twist %g deg over %d frames, %zu queries (%.1f%% colliding), %u threads\n",
      mesh.name.c_str(), mesh.triangle_count(), g_settings.twist_degrees, g_settings.frames, rebuild.queries,
      rate(colliding, rebuild.queries), g_settings.threads);
  std::printf("%-27s %8s %9s %8s %7s %8s %7s %7s %6s", "per frame", "refit ms", "update ms", "query ms",
              "ratio", "recount%", "|diff|", "differ%", "under%");
  for (const double p : g_settings.p_mins) std::printf(" | p%-5g FN%%  FP%% dFNpp", p);
  std::printf("\n");
  auto errors = [&](const Row& r) {
    for (std::size_t p = 0; p < g_settings.p_mins.size(); ++p) {
      const double fn = rate(r.false_negatives[p], r.queries);
      const double exact_fn = exact_row ? rate(exact_row->false_negatives[p], exact_row->queries) : fn;
      std::printf(" | %11.2f %5.2f %+5.2f", fn, rate(r.false_positives[p], r.queries), fn - exact_fn);
    }
    std::printf("\n");
  };
  std::printf("%-27s %8.1f %9.1f %8.3f %7.3f %8s %7s %7s %6s", "rebuild + annotate",
              1e3 * rebuild.refit_s / frames, 1e3 * rebuild.update_s / frames, 1e3 * rebuild.query_s / frames,
              1.0, "", "", "", "");
  errors(rebuild);
  for (std::size_t k = 0; k < followers.size(); ++k) {
    const Row& r = rows[k];
    std::printf("%-27s %8.1f %9.1f %8.3f %7.3f %8.1f %7.4f %7.2f %6.2f", followers[k].variant.label.c_str(),
                1e3 * r.refit_s / frames, 1e3 * r.update_s / frames, 1e3 * r.query_s / frames,
                (r.refit_s + r.update_s + r.query_s) / base, rate(r.recounted, r.nodes), r.abs_diff / frames,
                100 * r.differ / frames, 100 * r.under / frames);
    errors(r);
  }
  std::printf(
      "(rebuild row: refit ms = build, update ms = annotate. ratio = (refit + update + query) / (build + "
      "annotate + query), queries at p_min %g. dFNpp: FN minus recount_all's, percentage points)\n",
      g_settings.p_mins[0]);
}

Mesh load_mesh(benchmark::State& state) {
  try {
    return load_protocol_mesh(g_settings.mesh);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_density_update: %s missing (%s): using a wavy grid\n",
                 g_settings.mesh.c_str(), e.what());
    state.SetLabel("wavy_grid");
    return wavy_grid();
  }
}

void BM_DensityUpdate(benchmark::State& state) {
  const Mesh rest = load_mesh(state);
  const AnnotationContext context{g_settings.threads, {}};
  const auto params = density_params<AdbDensity>();
  const Tree<Aabb, AdbDensity> rest_tree = annotate_tree<AdbDensity>(Bvh<Aabb>::build(rest), params, context);
  std::vector<Follower> followers;
  for (const Variant& v : kVariants) followers.push_back(make_follower(v, rest_tree));
  std::vector<Row> rows(followers.size());
  Row rebuild;
  std::size_t colliding = 0;
  for (auto _ : state) {
    for (int f = 1; f <= g_settings.frames; ++f) {
      const double radians = g_settings.twist_degrees * std::numbers::pi / 180 * f / g_settings.frames;
      const Mesh deformed = twisted(rest, radians);
      // Untimed references: the refitted tree's exact counts, the exact answers.
      Bvh<Aabb> reference = rest_tree.bvh;
      reference.refit(deformed);
      const std::vector<std::uint8_t> exact =
          AdbDensity::annotate(reference, params, context, nullptr).possible_collision_cells;
      std::vector<RigidTransform> poses;
      std::vector<bool> truth;
      const int per_distance = std::max(1, g_settings.poses / 4);
      for (const double d : {1.4, 1.6, 1.8, 2.0})
        for (int k = 0; k < per_distance; ++k) {
          poses.push_back(protocol_pose(d, k * g_settings.frames + f, per_distance * g_settings.frames));
          truth.push_back(query_exact(reference, reference, poses.back()).collides);
          colliding += truth.back();
        }
      // Rebuild and re-annotate.
      auto start = std::chrono::steady_clock::now();
      Bvh<Aabb> built = Bvh<Aabb>::build(deformed);
      rebuild.refit_s += seconds_since(start);
      start = std::chrono::steady_clock::now();
      const Tree<Aabb, AdbDensity> rebuilt = annotate_tree<AdbDensity>(std::move(built), params, context);
      rebuild.update_s += seconds_since(start);
      query(rebuild, rebuilt, poses, truth);
      for (std::size_t k = 0; k < followers.size(); ++k) {
        followers[k].frame(deformed, rows[k]);
        add_count_errors(rows[k], followers[k].tree->density.possible_collision_cells, exact);
        query(rows[k], *followers[k].tree, poses, truth);
      }
    }
  }
  print_table(rest, followers, rows, rebuild, colliding);
  const double base = rebuild.refit_s + rebuild.update_s + rebuild.query_s;
  for (std::size_t k = 0; k < followers.size(); ++k)
    state.counters["ratio " + followers[k].variant.label] =
        (rows[k].refit_s + rows[k].update_s + rows[k].query_s) / base;
}

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using bvhlab::g_settings;
  if (auto exit = bvhlab::initialize_benchmark("bench_density_update",
                                               {{"mesh", &g_settings.mesh, "the twisting mesh"},
                                                {"frames", &g_settings.frames, "frames"},
                                                {"twist", &g_settings.twist_degrees, "twist in degrees"},
                                                {"poses", &g_settings.poses, "poses per frame"},
                                                {"threads", &g_settings.threads, "annotation threads"}},
                                               argc, argv))
    return *exit;
  try {
    if (g_settings.frames < 1) throw std::invalid_argument("--frames must be at least 1");
    if (g_settings.poses < 4) throw std::invalid_argument("--poses must be at least 4");
    if (!std::isfinite(g_settings.twist_degrees)) throw std::invalid_argument("--twist must be finite");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_density_update: %s\n", e.what());
    return 2;
  }
  benchmark::RegisterBenchmark("BM_DensityUpdate", bvhlab::BM_DensityUpdate)
      ->Iterations(1)
      ->Unit(benchmark::kSecond)
      ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
