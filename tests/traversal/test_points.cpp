// Point clouds through the driver (traversal/point_leaves.hpp): exact_points against the exact answer on
// the meshes the clouds were sampled from, outside a band of about three point spacings around contact;
// ADB, guided exact and time-critical on the same trees; the leaf test kept per leaf against
// test_leaf_surfaces; and the refusals.
#include "adb/point_density.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/point_leaves.hpp"
#include "traversal/strategies.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace bvhlab {
namespace {

/// A mesh, a cloud sampled from it, and what a point query needs of the cloud.
struct Sampled {
  Sampled(Mesh source, std::size_t points, std::uint64_t seed)
      : mesh(std::move(source)),
        mesh_tree(Bvh<Aabb>::build(mesh)),
        cloud(sample_uniform(mesh, points, seed)),
        surface(cloud),
        tree(annotate_adb_points(Bvh<Aabb>::build(cloud), cloud, 2)),
        coverings(sphere_coverings(tree.bvh, surface)),
        spacing(std::sqrt(surface_area(mesh) / static_cast<double>(points))) {}
  [[nodiscard]] SurfaceSide side() const { return cloud_side(surface, coverings); }

  Mesh mesh;
  Bvh<Aabb> mesh_tree;
  PointCloud cloud;
  PointSurface surface;
  Tree<Aabb, AdbDensity> tree;
  std::vector<SphereCovering> coverings;
  double spacing;  ///< sqrt(area / N)
};

/// The mesh answer at `pose` when it is the same with B moved by `shift` along each axis both ways (the
/// objects are then at least about shift / sqrt(3) apart or inside each other); nullopt near contact.
std::optional<bool> clear_mesh_answer(const Bvh<Aabb>& a, const Bvh<Aabb>& b, const RigidTransform& pose,
                                      double shift) {
  const bool answer = query_exact(a, b, pose).collides;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {-1.0, 1.0}) {
      RigidTransform moved = pose;
      moved.translation[axis] += sign * shift;
      if (query_exact(a, b, moved).collides != answer) return std::nullopt;
    }
  return answer;
}

/// Poses whose mesh answer is clear by 3 spacings (shift 3 sqrt(3) spacings), with that answer.
std::vector<std::pair<RigidTransform, bool>> clear_poses(const Bvh<Aabb>& a, const Bvh<Aabb>& b,
                                                         double spacing, int count, double reach,
                                                         std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::pair<RigidTransform, bool>> out;
  for (int k = 0; k < count; ++k) {
    const RigidTransform pose = testing::random_pose(rng, reach);
    if (const auto answer = clear_mesh_answer(a, b, pose, 3 * std::sqrt(3.0) * spacing))
      out.emplace_back(pose, *answer);
  }
  return out;
}

struct Tally {
  int colliding = 0, separate = 0;
};

TEST(PointQueries, ExactPointsAgreesWithTheMeshesOutsideTheBand) {
  const Sampled a(testing::make_torus(0.7, 0.25, 40, 20), 3000, 1);
  const Sampled b(testing::make_torus(0.6, 0.2, 36, 18), 2000, 2);
  Tally tally;
  for (const auto& [pose, truth] :
       clear_poses(a.mesh_tree, b.mesh_tree, std::max(a.spacing, b.spacing), 80, 1.5, 3)) {
    const Result r = query_exact_points(a.tree.bvh, a.side(), b.tree.bvh, b.side(), pose);
    ASSERT_EQ(r.collides, truth) << "translation " << pose.translation.transpose();
    EXPECT_TRUE(r.exact);
    EXPECT_EQ(r.probability, truth ? 1.0 : 0.0);
    EXPECT_FALSE(r.witness.has_value()) << "no triangles to name";
    (truth ? tally.colliding : tally.separate) += 1;
  }
  // Both answers, or the agreement proves little.
  EXPECT_GE(tally.colliding, 8);
  EXPECT_GE(tally.separate, 8);
}

TEST(PointQueries, CloudAgainstMeshEitherWayAgreesWithTheMeshes) {
  const Sampled cloud(generators::make_sphere(1.0, 64, 32), 3000, 4);
  const Mesh ball = generators::make_sphere(0.5, 32, 16);  // edges about 0.1, under the cloud's support
  const auto ball_tree = Bvh<Aabb>::build(ball);
  // Distances of the centres clear of contact (0.5 and 1.5) by more than 3 spacings, the ball inside the
  // cloud's sphere too: neither surface test nor triangle test sees a contact there.
  std::mt19937_64 rng(6);
  Tally tally;
  for (int k = 0; k < 40; ++k) {
    RigidTransform pose = testing::random_pose(rng, 1.0);
    const double centre = 2.2 * static_cast<double>(k) / 40;  // the ball inside, crossing, then outside
    pose.translation = centre * pose.translation.normalized();
    if (std::abs(centre - 0.5) < 3 * cloud.spacing || std::abs(centre - 1.5) < 3 * cloud.spacing) continue;
    const bool truth = query_exact(cloud.mesh_tree, ball_tree, pose).collides;
    EXPECT_EQ(truth, centre > 0.5 && centre < 1.5) << "the meshes' own answer, centre " << centre;
    EXPECT_EQ(query_exact_points(cloud.tree.bvh, cloud.side(), ball_tree, mesh_side(), pose).collides, truth)
        << "cloud A, mesh B, centre " << centre;
    EXPECT_EQ(
        query_exact_points(ball_tree, mesh_side(), cloud.tree.bvh, cloud.side(), pose.inverse()).collides,
        truth)
        << "mesh A, cloud B, centre " << centre;
    (truth ? tally.colliding : tally.separate) += 1;
  }
  EXPECT_GE(tally.colliding, 5);
  EXPECT_GE(tally.separate, 5);
}

TEST(PointQueries, AdbOnPointsIsExactWhereItSaysSoAndGuidedExactIsExactPoints) {
  const Sampled a(testing::make_torus(0.7, 0.25, 40, 20), 2000, 7);
  const Sampled b(testing::make_torus(0.6, 0.2, 36, 18), 1500, 8);
  std::mt19937_64 rng(9);
  AdbOptions guided;
  guided.p_min = 1;
  guided.exact_leaves = true;
  int inexact_no = 0, colliding = 0;
  for (int k = 0; k < 40; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.2);
    const bool points = query_exact_points(a.tree.bvh, a.side(), b.tree.bvh, b.side(), pose).collides;
    colliding += points;
    // Every leaf pair reached is tested and nothing is pruned by estimate: exact_points' answer, any pose.
    const Result g = query_adb_points(a.tree, a.side(), b.tree, b.side(), pose, guided);
    EXPECT_EQ(g.collides, points) << "guided exact, pose " << k;
    EXPECT_TRUE(g.exact);
    for (double p_min : {0.5, 0.9, 0.99}) {
      AdbOptions options;
      options.p_min = p_min;
      const Result r = query_adb_points(a.tree, a.side(), b.tree, b.side(), pose, options);
      EXPECT_GE(r.probability, 0) << "p_min " << p_min;
      EXPECT_LE(r.probability, 1) << "p_min " << p_min;
      // A "no" is exact only when every overlapping pair reached a leaf test, which then agrees.
      if (r.exact) {
        EXPECT_EQ(r.collides, points) << "p_min " << p_min << ", pose " << k;
      }
      if (points && !r.collides) {
        EXPECT_FALSE(r.exact) << "a missed crossing must not be reported exact";
        ++inexact_no;
      }
      // A leaf test's crossing, or an estimate above p_min: nothing else says "collides".
      if (r.collides && !r.exact) {
        EXPECT_GT(r.probability, p_min);
      }
    }
  }
  EXPECT_GE(colliding, 8);
  EXPECT_LT(colliding, 36);
  // Misses come only from pairs dropped on a zero estimate: rare on trees whose nodes all hold points.
  EXPECT_LE(inexact_no, 3);
}

TEST(PointQueries, ConfirmLevelsOnPointsOnlyTakeFalseCollisionsAway) {
  const Sampled a(testing::make_torus(0.7, 0.25, 40, 20), 2000, 7);
  const Sampled b(testing::make_torus(0.6, 0.2, 36, 18), 1500, 8);
  std::mt19937_64 rng(12);
  int removed = 0, false_literal = 0, false_confirmed = 0;
  for (int k = 0; k < 60; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.2);
    const bool points = query_exact_points(a.tree.bvh, a.side(), b.tree.bvh, b.side(), pose).collides;
    AdbOptions literal;
    literal.p_min = 0.9;
    AdbOptions confirm = literal;
    confirm.confirm_levels = 3;
    const Result l = query_adb_points(a.tree, a.side(), b.tree, b.side(), pose, literal);
    const Result c = query_adb_points(a.tree, a.side(), b.tree, b.side(), pose, confirm);
    if (c.collides) {
      EXPECT_TRUE(l.collides) << "pose " << k;  // a literal "no" stays "no"
    }
    if (points) {
      EXPECT_EQ(c.collides, l.collides) << "a crossing is found either way, pose " << k;
    }
    removed += l.collides && !c.collides;
    false_literal += l.collides && !points;
    false_confirmed += c.collides && !points;
  }
  EXPECT_GT(removed, 0);  // the option must matter here, or the test shows nothing
  EXPECT_LT(false_confirmed, false_literal);
}

TEST(PointQueries, TimeCriticalOnPointsKeepsItsBudget) {
  const Sampled a(testing::make_torus(0.7, 0.25, 40, 20), 2000, 10);
  std::mt19937_64 rng(11);
  AdbOptions free;
  free.p_min = 0.99;
  AdbOptions capped = free;
  capped.budget.max_bv_tests = 3;
  int exhausted = 0;
  for (int k = 0; k < 40; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.0);
    const Result r = query_adb_points(a.tree, a.side(), a.tree, a.side(), pose, capped);
    EXPECT_LE(r.counters.bv_tests, 3u);
    EXPECT_GE(r.probability, 0);
    EXPECT_LE(r.probability, 1);
    exhausted += r.budget_exhausted;
    // Not stopped: the same traversal as without a budget, so the same answer.
    if (!r.budget_exhausted) {
      EXPECT_EQ(r.collides, query_adb_points(a.tree, a.side(), a.tree, a.side(), pose, free).collides);
    }
  }
  EXPECT_GE(exhausted, 5);
}

TEST(PointQueries, TheLeafTestKeptPerLeafIsTestLeafSurfaces) {
  const Sampled a(testing::make_torus(0.7, 0.25, 40, 20), 2000, 12);
  const Sampled b(testing::make_torus(0.6, 0.2, 36, 18), 1500, 13);
  std::vector<std::uint32_t> leaves_a, leaves_b;
  for (std::uint32_t i = 0; i < a.tree.bvh.nodes().size(); ++i)
    if (a.tree.bvh.node(i).is_leaf()) leaves_a.push_back(i);
  for (std::uint32_t j = 0; j < b.tree.bvh.nodes().size(); ++j)
    if (b.tree.bvh.node(j).is_leaf()) leaves_b.push_back(j);
  std::mt19937_64 rng(14);
  int crossings = 0;
  for (int k = 0; k < 4; ++k) {
    RigidTransform pose = testing::random_pose(rng, 0.3);
    const SurfaceLeaves<Aabb> kept(a.tree.bvh, a.side(), b.tree.bvh, b.side(), pose);
    for (int n = 0; n < 250; ++n) {  // leaves repeat: the kept halves are reused
      const std::uint32_t i = leaves_a[rng() % leaves_a.size()], j = leaves_b[rng() % leaves_b.size()];
      const bool expected = test_leaf_surfaces(a.surface, node_points(a.tree.bvh, i), b.surface,
                                               node_points(b.tree.bvh, j), pose)
                                .crossing;
      ASSERT_EQ(kept.crossing(i, j), expected) << "leaves " << i << ", " << j;
      crossings += expected;
    }
  }
  EXPECT_GT(crossings, 0);
}

template <class F>
void expect_refused(F&& f, const std::string& words) {
  try {
    f();
    ADD_FAILURE() << "not refused; expected: " << words;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(PointQueries, MixingPointsAndPolygonsIsRefusedNamingTheProblem) {
  const Sampled a(generators::make_sphere(1.0, 24, 12), 300, 15);
  const Sampled other(generators::make_sphere(1.0, 24, 12), 200, 16);
  const RigidTransform pose = RigidTransform::translate(Vec3(0.5, 0, 0));
  // Strategies that test triangles.
  expect_refused([&] { query_exact(a.tree.bvh, a.mesh_tree, pose); }, "tree A holds a point cloud");
  expect_refused([&] { ExactStrategy::query(a.tree, a.tree, pose, ContactMode::First); },
                 "holds a point cloud, not triangles");
  expect_refused(
      [&] { GuidedExactStrategy::query(a.tree, a.tree, pose, strategy_options<GuidedExactStrategy>()); },
      "adb: guided exact: tree A holds a point cloud");
  // Point queries given the wrong sides.
  expect_refused([&] { query_exact_points(a.mesh_tree, mesh_side(), a.mesh_tree, mesh_side(), pose); },
                 "neither side is a cloud");
  expect_refused([&] { query_exact_points(a.tree.bvh, a.side(), a.tree.bvh, mesh_side(), pose); },
                 "tree B holds points but was given no surface");
  expect_refused([&] { query_exact_points(a.mesh_tree, a.side(), a.tree.bvh, a.side(), pose); },
                 "tree A is given a surface but holds no points");
  expect_refused([&] { query_exact_points(a.tree.bvh, other.side(), a.tree.bvh, a.side(), pose); },
                 "tree A was built over 300 points, its surface over 200");
  expect_refused(
      [&] {
        query_exact_points(a.tree.bvh, cloud_side(a.surface, std::span(a.coverings).first(3)), a.tree.bvh,
                           a.side(), pose);
      },
      "sphere coverings");
  expect_refused(
      [&] {
        query_exact(a.tree.bvh, a.tree.bvh, pose, ContactMode::All,
                    SurfaceLeaves<Aabb>(a.tree.bvh, a.side(), a.tree.bvh, a.side(), pose));
      },
      "no triangle pairs to list");
}

}  // namespace
}  // namespace bvhlab
