// Depth: a million triangles strung along a line build deep, unbalanced trees, and a tree assembled from
// parts (as a loaded file may be) can be a chain a million nodes deep. Nothing may recurse on depth (stack
// overflow) or do work quadratic in the triangle count. Time is not asserted here (speed belongs in
// benchmarks); a quadratic builder or traversal on 10^6 triangles would take hours and hit the ctest timeout,
// and the work counters are bounded linearly instead.
#include "robust_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace bvhlab::robust {
namespace {

constexpr std::size_t kTriangles = 1'000'000;

// Triangle i spans [x(i), x(i+1)] on the x axis, with its third corner at height h (h = 0: a degenerate,
// collinear triangle; h < 0: |h| times the triangle's length, a well-shaped triangle at any scale).
Mesh line_mesh(const std::function<double(std::size_t)>& x, double h) {
  Mesh m;
  m.name = "line";
  m.vertices.reserve(3 * kTriangles);
  m.triangles.reserve(kTriangles);
  for (std::size_t i = 0; i < kTriangles; ++i) {
    const auto b = static_cast<std::uint32_t>(m.vertices.size());
    const double x0 = x(i), x1 = x(i + 1);
    m.vertices.emplace_back(x0, 0, 0);
    m.vertices.emplace_back(x1, 0, 0);
    const double height = h < 0 ? -h * std::abs(x1 - x0) : h;
    m.vertices.emplace_back(h != 0 ? x0 : 0.5 * (x0 + x1), height, 0);
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

// with_stand_in_annotation (robust_support.hpp): the real annotation clips every triangle once per tree
// level, which on these trees is the annotation's own cost, not what this test is about.

// One small triangle standing across the line at x = at: it touches exactly the line's triangles around at.
Mesh probe_at(double at) {
  Mesh m;
  m.vertices = {Vec3(at, -0.5, -0.5), Vec3(at, 0.5, -0.5), Vec3(at, 0, 0.5)};
  m.triangles = {{0, 1, 2}};
  return m;
}

struct LineCase {
  std::string name;
  std::function<double(std::size_t)> x;
  double height;
  SplitMethod split;
};

void PrintTo(const LineCase& c, std::ostream* os) {
  *os << c.name;
}

class DeepLineTree : public ::testing::TestWithParam<LineCase> {};

TEST_P(DeepLineTree, BuildsAndAnswersWithoutDeepRecursionOrQuadraticWork) {
  const LineCase& c = GetParam();
  const Mesh line = line_mesh(c.x, c.height);
  BuildOptions build;
  build.split = c.split;
  const auto tree = with_stand_in_annotation(Bvh<Aabb>::build(line, build));
  const BvhStats stats = tree.bvh.stats();
  std::printf("[deep] %-26s depth %u, %zu nodes, built in %.2f s\n", c.name.c_str(), stats.depth, stats.nodes,
              stats.build_seconds);
  EXPECT_EQ(stats.nodes, 2 * kTriangles - 1);
  EXPECT_EQ(stats.leaves, kTriangles);
  EXPECT_LT(stats.depth, 1024u) << "the builder degenerated toward a chain";

  // A probe crossing the line in the middle of triangle k touches it (and, for the clustered line, the other
  // triangles spanning the same stretch).
  const std::size_t k = kTriangles / 3;
  const double at = 0.5 * (c.x(k) + c.x(k + 1));
  const Annotated<Aabb> probe = with_stand_in_annotation(Bvh<Aabb>::build(probe_at(at)));
  const std::uint64_t linear_budget = 64 * kTriangles;
  for (Strategy s : kAllStrategies) {
    const Result r = run<Aabb>(s, tree, probe, {}, 0.9, 1000);
    ASSERT_TRUE(honest(r, true)) << to_string(s);
    EXPECT_LT(r.counters.bv_tests, linear_budget) << to_string(s);
    if (is_exact(s)) {
      ASSERT_TRUE(r.collides) << to_string(s);
      ASSERT_TRUE(r.witness.has_value()) << to_string(s);
      EXPECT_TRUE(triangles_intersect_exact(line.triangle(r.witness->a), probe_at(at).triangle(0)))
          << to_string(s);
    }
  }
  // The whole line against itself, shifted by half a triangle: every triangle meets its neighbours, so
  // listing all contacts is linear work, and the first contact is found at once.
  const RigidTransform shift = RigidTransform::translate(Vec3(0.5 * (c.x(k + 1) - c.x(k)), 0, 0));
  const Result first = query_exact(tree.bvh, tree.bvh, shift);
  EXPECT_TRUE(first.collides);
  EXPECT_LT(first.counters.bv_tests, 4096u);
}

INSTANTIATE_TEST_SUITE_P(
    Lines, DeepLineTree,
    ::testing::Values(
        LineCase{"uniform_sah", [](std::size_t i) { return 1e-6 * static_cast<double>(i); }, 1e-6,
                 SplitMethod::Sah},
        // Collinear, zero-area triangles: every SAH cost is 0, the deepest tree the builder makes (~180).
        LineCase{"collinear_degenerate_sah", [](std::size_t i) { return 1e-6 * static_cast<double>(i); }, 0.0,
                 SplitMethod::Sah},
        // Exponentially spaced: the SAH bins see almost every centroid in the first bin.
        LineCase{"exponential_sah", [](std::size_t i) { return std::pow(1.00002, static_cast<double>(i)); },
                 1e-6, SplitMethod::Sah},
        LineCase{"exponential_median",
                 [](std::size_t i) { return std::pow(1.00002, static_cast<double>(i)); }, 1e-6,
                 SplitMethod::Median}),
    [](const ::testing::TestParamInfo<LineCase>& info) { return info.param.name; });

// A tree assembled from parts may be a chain: inner node 2i has the leaf 2i+1 and the inner node 2i+2 as
// children, so the depth is a million. Traversals keep their own stacks and queues, so this is only work
// proportional to the depth, never a stack overflow.
TEST(DeepChainTree, MillionDeepChainIsTraversedIteratively) {
  constexpr std::size_t n = kTriangles;
  const Mesh line = line_mesh([](std::size_t i) { return 1e-6 * static_cast<double>(i); }, 1e-6);
  std::vector<TreeNode> nodes(2 * n - 1);
  std::vector<Aabb> volumes(2 * n - 1);
  std::vector<std::uint32_t> ids(n);
  std::vector<TrianglePoints> triangles(n);
  for (std::size_t t = 0; t < n; ++t) {
    ids[t] = static_cast<std::uint32_t>(t);
    triangles[t] = line.triangle(t);
  }
  // Leaves first (bottom-up), so each inner node's volume merges its two children's.
  Box suffix;
  for (std::size_t t = n; t-- > 0;) {
    const std::size_t leaf = t + 1 < n ? 2 * t + 1 : 2 * t;  // the last triangle is the chain's final node
    nodes[leaf] = {static_cast<std::uint32_t>(t), 1};
    volumes[leaf] = Aabb::fit(triangles[t]);
    suffix.extend(volumes[leaf].bounding_box());
    if (t + 1 < n) {
      nodes[2 * t] = {static_cast<std::uint32_t>(2 * t + 1), 0};
      volumes[2 * t] = Aabb::from_box(suffix);
    }
  }
  // Children must be stored after their parent: inner 2t -> (2t+1, 2t+2). Node 2t+2 is the next inner node,
  // or the final leaf 2(n-1).
  const auto chain =
      Bvh<Aabb>::from_parts(std::move(nodes), std::move(volumes), std::move(ids), std::move(triangles));
  EXPECT_EQ(chain.stats().depth, n - 1);
  const auto tree = with_stand_in_annotation(chain);

  const std::size_t k = n - 7;  // deep down the chain
  const Annotated<Aabb> probe = with_stand_in_annotation(Bvh<Aabb>::build(probe_at(1e-6 * (k + 0.5))));
  for (Strategy s : kAllStrategies) {
    const Result r = run<Aabb>(s, tree, probe, {}, 0.9, 1000);
    ASSERT_TRUE(honest(r, true)) << to_string(s);
    EXPECT_LT(r.counters.bv_tests, 8 * n) << to_string(s);
    if (is_exact(s)) {
      ASSERT_TRUE(r.collides) << to_string(s);
    }
  }
  // And the other way round: the chain as B.
  for (Strategy s : kAllStrategies) {
    const Result r = run<Aabb>(s, probe, tree, {}, 0.9, 1000);
    ASSERT_TRUE(honest(r, true)) << to_string(s) << " (chain as B)";
  }
}

}  // namespace
}  // namespace bvhlab::robust
