// Threads: queries from several threads on shared trees give exactly the single-threaded answers, for every
// registered BV and every strategy (exact first and all contacts, ADB with p_min, ADB under a BV-test budget,
// guided exact; no deadlines, whose answers depend on timing), and the wide walk on shared wide trees.
// Loading, building and annotating concurrently give the same meshes and trees as doing it alone. Run under
// ThreadSanitizer by the tsan preset (label threads), which also catches races that happen not to change an
// answer.
#include "bvh/mesh_io.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "robust_support.hpp"
#include "support/meshes.hpp"
#include "traversal/wide_exact.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <fstream>
#include <thread>

#include <unistd.h>

namespace bvhlab::robust {
namespace {

constexpr int kThreads = 4;

// Everything a strategy reports, so "identical" means identical (probabilities bit for bit).
::testing::AssertionResult same(const Result& expected, const Result& got) {
  if (expected.collides != got.collides || expected.exact != got.exact ||
      expected.budget_exhausted != got.budget_exhausted)
    return ::testing::AssertionFailure()
           << "answer differs: collides " << got.collides << " exact " << got.exact;
  if (std::memcmp(&expected.probability, &got.probability, sizeof(double)) != 0)
    return ::testing::AssertionFailure()
           << "probability " << got.probability << " vs " << expected.probability;
  if (expected.witness != got.witness) return ::testing::AssertionFailure() << "witness differs";
  if (expected.contacts != got.contacts) return ::testing::AssertionFailure() << "contacts differ";
  const Counters &a = expected.counters, &b = got.counters;
  if (a.bv_tests != b.bv_tests || a.triangle_tests != b.triangle_tests ||
      a.nodes_visited != b.nodes_visited || a.probability_evaluations != b.probability_evaluations)
    return ::testing::AssertionFailure()
           << "work counters differ: bv tests " << b.bv_tests << " vs " << a.bv_tests;
  return ::testing::AssertionSuccess();
}

std::vector<RigidTransform> poses() {
  std::vector<RigidTransform> out;
  for (double d : {0.6, 1.0, 1.4, 1.8, 2.0})
    for (int k = 0; k < 12; ++k) out.push_back(protocol_pose(d, k, 12));
  return out;
}

// `r` with its contacts in order, so that two answers compare whatever order a walk found them in.
Result with_sorted_contacts(Result r) {
  std::sort(r.contacts.begin(), r.contacts.end());
  return r;
}

// query(i) for i < n from kThreads threads at once, each starting at another i: per thread its answers.
// Each thread keeps its own results; the caller compares after the join (gtest is not asked to be
// thread-safe on failures).
template <class Query>
std::vector<std::vector<Result>> answers_from_threads(std::size_t n, const Query& query) {
  std::vector<std::vector<Result>> got(kThreads, std::vector<Result>(n));
  std::vector<std::thread> threads;
  std::atomic<bool> go{false};
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      while (!go.load()) std::this_thread::yield();
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = (k + t * n / kThreads) % n;
        got[t][i] = query(i);
      }
    });
  go = true;
  for (auto& thread : threads) thread.join();
  return got;
}

// query(i) for every i < n from kThreads threads gives what it gives on one thread; describe(i) names i.
template <class Query, class Describe>
void expect_threads_answer_alone(std::size_t n, const Query& query, const Describe& describe) {
  std::vector<Result> reference(n);
  for (std::size_t i = 0; i < n; ++i) reference[i] = query(i);
  const auto got = answers_from_threads(n, query);
  for (int t = 0; t < kThreads; ++t)
    for (std::size_t i = 0; i < n; ++i)
      ASSERT_TRUE(same(reference[i], got[t][i])) << "thread " << t << ", " << describe(i);
}

TEST(Threads, SharedTreesAnswerAsSingleThreadedForEveryVolumeAndStrategy) {
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");
  const auto queries = poses();
  int volumes = 0;
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(jeep);
    const std::size_t n = queries.size() * kAllStrategies.size();
    auto query = [&](std::size_t i) {
      return with_sorted_contacts(
          run<BV>(kAllStrategies[i % kAllStrategies.size()], tree, tree, queries[i / kAllStrategies.size()]));
    };
    expect_threads_answer_alone(n, query, [](std::size_t i) {
      return to_string(kAllStrategies[i % kAllStrategies.size()]) + ", pose " +
             std::to_string(i / kAllStrategies.size());
    });
    ++volumes;
  });
  EXPECT_GT(volumes, 0);
}

// The wide walk on shared wide trees (bvh/wide_bvh.hpp): every volume with a four-lane layout, first and
// all contacts, from several threads at once, gives the single-threaded answers and work counters.
TEST(Threads, SharedWideTreesAnswerAsSingleThreaded) {
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");
  const auto queries = poses();
  int volumes = 0;
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    if constexpr (HasWideLayout<BV>) {
      SCOPED_TRACE(std::string(BV::name()));
      const auto tree = Bvh<BV>::build(jeep);
      const auto wide = WideTreeOf<BV>::build(tree);
      const std::size_t n = queries.size() * 2;
      auto query = [&](std::size_t i) {
        const ContactMode mode = i % 2 == 0 ? ContactMode::First : ContactMode::All;
        return with_sorted_contacts(query_exact_wide(tree, wide, tree, wide, queries[i / 2], mode));
      };
      expect_threads_answer_alone(n, query, [](std::size_t i) { return "query " + std::to_string(i); });
      ++volumes;
    }
  });
  EXPECT_GE(volumes, 4);  // boxes, the k-DOPs, spheres, OBBs
}

// The loader installs one process-wide assimp logger and captures messages per thread; concurrent loads must
// neither mix their warnings nor their meshes.
TEST(Threads, ConcurrentLoadsGiveTheSameMeshesAndReports) {
  std::vector<std::filesystem::path> files = {testing::bundled_mesh("pinion.off"),
                                              testing::bundled_mesh("jeep1.ms3d"),
                                              testing::bundled_mesh("teapot.obj")};
  // Plus a file whose load warns (far from the origin) and one that is refused, so messages flow too.
  const auto dir = std::filesystem::temp_directory_path() / ("bvhlab-threads-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "far.obj") << "v 1e7 0 0\nv 10000001 0 0\nv 1e7 1 0\nf 1 2 3\n";
  std::ofstream(dir / "bad.off") << "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  files.push_back(dir / "far.obj");
  files.push_back(dir / "bad.off");

  struct Outcome {
    std::vector<Vec3> vertices;
    std::vector<TriangleIndices> triangles;
    std::vector<std::string> warnings;
    std::string error;
    bool operator==(const Outcome&) const = default;
  };
  auto load = [&](std::size_t i) {
    Outcome o;
    try {
      LoadedMesh m = load_mesh(files[i]);
      o.vertices = std::move(m.mesh.vertices);
      o.triangles = std::move(m.mesh.triangles);
      o.warnings = std::move(m.report.warnings);
    } catch (const MeshError& e) {
      o.error = e.what();
    }
    return o;
  };
  std::vector<Outcome> reference;
  for (std::size_t i = 0; i < files.size(); ++i) reference.push_back(load(i));
  ASSERT_FALSE(reference[3].warnings.empty());
  ASSERT_FALSE(reference[4].error.empty());
  constexpr int kRounds = 3;
  std::vector<std::vector<Outcome>> got(kThreads, std::vector<Outcome>(files.size() * kRounds));
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (std::size_t k = 0; k < files.size() * kRounds; ++k) got[t][k] = load((k + t) % files.size());
    });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t)
    for (std::size_t k = 0; k < files.size() * kRounds; ++k)
      EXPECT_TRUE(got[t][k] == reference[(k + t) % files.size()])
          << files[(k + t) % files.size()] << " thread " << t;
  std::filesystem::remove_all(dir);
}

// Builds and annotations running side by side (each also multi-threaded inside) give the trees one gets
// alone.
TEST(Threads, ConcurrentBuildsAndAnnotationsAreIdentical) {
  const Mesh teapot = load_protocol_mesh("teapot.obj");
  auto make = [&] {
    AnnotateOptions options;
    options.threads = 2;
    BuildOptions build;
    build.threads = 2;
    return annotate_adb(Bvh<Aabb>::build(teapot, build), kGrid, options);
  };
  const auto reference = make();
  std::vector<Annotated<Aabb>> got(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back([&, t] { got[t] = make(); });
  for (auto& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) {
    const auto& tree = got[t];
    ASSERT_EQ(tree.bvh.nodes().size(), reference.bvh.nodes().size());
    for (std::size_t i = 0; i < tree.bvh.nodes().size(); ++i) {
      ASSERT_EQ(tree.bvh.node(i).first, reference.bvh.node(i).first);
      ASSERT_EQ(tree.bvh.node(i).count, reference.bvh.node(i).count);
      ASSERT_EQ(std::memcmp(&tree.bvh.volume(i), &reference.bvh.volume(i), sizeof(Aabb)), 0) << "node " << i;
    }
    EXPECT_EQ(tree.bvh.triangle_ids(), reference.bvh.triangle_ids());
    EXPECT_EQ(tree.density.possible_collision_cells, reference.density.possible_collision_cells);
  }
}

}  // namespace
}  // namespace bvhlab::robust
