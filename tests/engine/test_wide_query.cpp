// Wide queries through the run-time layer (StrategyVariant::wide): the walk over the trees' wide layout
// answers as the binary walk on every volume that has a layout, for trees of any density; it is refused by
// name where it does not run; and a refit never leaves it reading the volumes from before.
#include "engine/deforming.hpp"
#include "engine/policies.hpp"
#include "support/errors.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace bvhlab {
namespace {

using testing::error_of;

/// Tilted about x while B slides across A: contact, then apart.
std::vector<RigidTransform> sliding_poses() {
  std::vector<RigidTransform> poses;
  for (int i = 0; i < 40; ++i)
    poses.push_back(RigidTransform{Eigen::AngleAxisd(0.9, Vec3::UnitX()).toRotationMatrix(),
                                   Vec3(0.04 * i, 0.2, 0.01 * i)});
  return poses;
}

std::vector<Result> results_of(const AnyTree& a, const AnyTree& b, const StrategyVariant& variant,
                               const std::vector<RigidTransform>& poses) {
  std::vector<Result> out(poses.size());
  a.prepare(b, variant)->run(poses, [&](std::size_t i, const Result& r) { out[i] = r; });
  return out;
}

StrategyVariant wide(StrategyVariant variant) {
  variant.wide = true;
  return variant;
}

std::vector<TrianglePair> sorted_contacts(std::vector<TrianglePair> contacts) {
  std::sort(contacts.begin(), contacts.end(), [](const TrianglePair& x, const TrianglePair& y) {
    return std::pair(x.a, x.b) < std::pair(y.a, y.b);
  });
  return contacts;
}

TEST(WideQuery, AnswersAsTheBinaryWalkOnEveryVolumeWithALayout) {
  const Mesh torus_a = testing::make_torus(0.7, 0.25, 16, 8), torus_b = testing::make_torus(0.5, 0.2, 12, 8);
  const auto poses = sliding_poses();
  const StrategyVariant exact = strategy_variant("exact", {}, Budget{});
  const StrategyVariant all = strategy_variant("all_contacts", {}, Budget{});
  std::size_t volumes = 0, colliding = 0;
  for (const std::string& bv : volume_names()) {
    if (!wide_layout_refusal(bv).empty()) continue;
    SCOPED_TRACE(bv);
    ++volumes;
    // An adb tree serves too: exact reads the hierarchy alone.
    for (const char* density : {"none", "adb"}) {
      const AnyTree a = AnyTree::build(torus_a, MeshUnits{}, bv, density_spec(density, {}), BuildOptions{});
      const AnyTree b = AnyTree::build(torus_b, MeshUnits{}, bv, density_spec(density, {}), BuildOptions{});
      const auto binary = results_of(a, b, exact, poses), walked = results_of(a, b, wide(exact), poses);
      const auto contacts = results_of(a, b, all, poses), wide_contacts = results_of(a, b, wide(all), poses);
      bool other_walk = false;  // the wide walk visits other node pairs: it is not the binary one again
      for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(walked[i].collides, binary[i].collides) << density << ", pose " << i;
        EXPECT_TRUE(walked[i].exact);
        const auto expected = sorted_contacts(contacts[i].contacts);
        EXPECT_EQ(sorted_contacts(wide_contacts[i].contacts), expected) << density << ", pose " << i;
        if (walked[i].witness)
          EXPECT_TRUE(std::binary_search(expected.begin(), expected.end(), *walked[i].witness,
                                         [](const TrianglePair& x, const TrianglePair& y) {
                                           return std::pair(x.a, x.b) < std::pair(y.a, y.b);
                                         }))
              << density << ", pose " << i << ": the witness is not an intersecting pair";
        other_walk = other_walk || walked[i].counters.nodes_visited != binary[i].counters.nodes_visited;
        colliding += binary[i].collides;
      }
      EXPECT_TRUE(other_walk) << density;
    }
  }
  EXPECT_GE(volumes, 4u);  // aabb, the k-DOPs, obb, sphere
  EXPECT_GT(colliding, 0u);
  EXPECT_LT(colliding, volumes * 2 * poses.size());
}

// ADB and time-critical walk the wide layouts of boxes, spheres, oriented boxes and k-DOPs through the
// engine: honest answers (an exact "no" is a proof, a "collision" lies above p_min), four BV tests a step,
// and the budget held to within a step.
TEST(WideQuery, AdbAndTimeCriticalWalkWideHonestly) {
  const Mesh torus_a = testing::make_torus(0.7, 0.25, 16, 8), torus_b = testing::make_torus(0.5, 0.2, 12, 8);
  const auto poses = sliding_poses();
  const StrategyVariant exact = strategy_variant("exact", {}, Budget{});
  const StrategyVariant adb = strategy_variant("adb", {{"p_min", 0.9}}, Budget{});
  const StrategyVariant budgeted = strategy_variant("time_critical", {}, Budget{9, 0});
  std::size_t volumes = 0;
  for (const std::string& bv : volume_names()) {
    if (!strategy_info("adb").wide_walk_refusal(bv).empty()) continue;
    SCOPED_TRACE(bv);
    ++volumes;
    const AnyTree a = AnyTree::build(torus_a, MeshUnits{}, bv, density_spec("adb", {}), BuildOptions{});
    const AnyTree b = AnyTree::build(torus_b, MeshUnits{}, bv, density_spec("adb", {}), BuildOptions{});
    const auto truth = results_of(a, b, exact, poses), binary = results_of(a, b, adb, poses),
               walked = results_of(a, b, wide(adb), poses), limited = results_of(a, b, wide(budgeted), poses);
    bool other_walk = false;  // the binary walk tests two or four children a step, the wide one four
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if (walked[i].exact) EXPECT_EQ(walked[i].collides, truth[i].collides) << "pose " << i;
      if (walked[i].collides) EXPECT_GT(walked[i].probability, 0.9) << "pose " << i;
      EXPECT_EQ(walked[i].counters.bv_tests % 4, 1u) << "the roots, then four a step; pose " << i;
      EXPECT_LE(limited[i].counters.bv_tests, 9u + 3u) << "pose " << i;
      other_walk = other_walk || walked[i].counters.bv_tests != binary[i].counters.bv_tests;
    }
    EXPECT_TRUE(other_walk);
  }
  EXPECT_GE(volumes, 4u);  // aabb, the k-DOPs, obb, sphere
}

// A saved tree loaded with its mesh walks wide as the tree it was saved from (the layout is derived from
// the binary tree, which is what the file keeps), and the contacts' geometry is the binary walk's.
TEST(WideQuery, ALoadedTreeAndContactGeometryWalkWideToo) {
  const Mesh torus = testing::make_torus(0.7, 0.25, 16, 8);
  const AnyTree built = AnyTree::build(torus, MeshUnits{}, "dop24", density_spec("none", {}), BuildOptions{});
  const AnyTree loaded = AnyTree::from_bytes(built.save_bytes("torus"), "torus", &torus);
  StrategyVariant all = strategy_variant("all_contacts", {}, Budget{});
  all.contact_geometry = true;
  const auto poses = sliding_poses();
  const auto binary = results_of(built, built, all, poses),
             walked = results_of(loaded, loaded, wide(all), poses);
  std::size_t contacts = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_EQ(walked[i].contact_geometry.size(), binary[i].contact_geometry.size()) << "pose " << i;
    const auto by_pair = [](const ContactGeometry& x, const ContactGeometry& y) {
      return std::pair(x.triangles.a, x.triangles.b) < std::pair(y.triangles.a, y.triangles.b);
    };
    auto expected = binary[i].contact_geometry, got = walked[i].contact_geometry;
    std::sort(expected.begin(), expected.end(), by_pair);
    std::sort(got.begin(), got.end(), by_pair);
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].triangles, expected[k].triangles);
      EXPECT_EQ(got[k].point, expected[k].point);
      EXPECT_EQ(got[k].normal, expected[k].normal);
    }
    contacts += got.size();
  }
  EXPECT_GT(contacts, 0u);
}

// The distance strategy walks wide trees of oriented boxes (the layout with a four-lane distance bound):
// the binary walk's distances, bit for bit; on boxes it is refused by name, and its anytime form (whose
// budget and dives walk the binary trees) does not run wide.
TEST(WideQuery, DistanceAnswersAsTheBinaryWalkOnOrientedBoxes) {
  const Mesh torus_a = testing::make_torus(0.7, 0.25, 16, 8), torus_b = testing::make_torus(0.5, 0.2, 12, 8);
  const auto obb = AnyTree::build(torus_a, MeshUnits{}, "obb", density_spec("none", {}), BuildOptions{});
  const auto obb_b = AnyTree::build(torus_b, MeshUnits{}, "obb", density_spec("none", {}), BuildOptions{});
  std::vector<RigidTransform> poses = sliding_poses();
  for (RigidTransform& pose : sliding_poses())
    poses.push_back({pose.rotation, pose.translation + Vec3(0, 1, 0)});
  const StrategyVariant distance = strategy_variant("distance", {}, Budget{});
  const auto binary = results_of(obb, obb_b, distance, poses),
             walked = results_of(obb, obb_b, wide(distance), poses);
  int apart = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_TRUE(walked[i].proximity.has_value());
    EXPECT_EQ(walked[i].proximity->distance, binary[i].proximity->distance) << "pose " << i;
    EXPECT_EQ(walked[i].collides, binary[i].collides) << "pose " << i;
    apart += binary[i].proximity->distance > 0;
  }
  EXPECT_GT(apart, 10);
  EXPECT_LT(apart, int(poses.size()) - 5);

  const auto aabb = AnyTree::build(torus_a, MeshUnits{}, "aabb", density_spec("none", {}), BuildOptions{});
  EXPECT_EQ(error_of([&] { (void)aabb.prepare(aabb, wide(distance)); }),
            "strategy distance has no wide walk on 'aabb' trees (the volumes it walks wide: obb)");
  EXPECT_EQ(strategy_info("distance").wide_walk_refusal("aabb"),
            "strategy distance has no wide walk on 'aabb' trees (the volumes it walks wide: obb)");
  EXPECT_EQ(strategy_info("distance").wide_walk_refusal("obb"), "");
  EXPECT_EQ(strategy_info("exact").wide_walk_refusal("aabb"), "");
  const StrategyVariant anytime = wide(strategy_variant("distance_anytime", {}, Budget{100, 0}));
  EXPECT_NE(error_of([&] { (void)obb.prepare(obb, anytime); }).find("does not run on wide trees"),
            std::string::npos);
}

TEST(WideQuery, IsRefusedByNameWhereItDoesNotRun) {
  const auto tree = [](const std::string& bv, const char* density) {
    return AnyTree::build(testing::make_torus(0.7, 0.25, 12, 6), MeshUnits{}, bv, density_spec(density, {}),
                          BuildOptions{});
  };
  const std::string no_walk =
      "strategy adb_dfs does not run on wide trees (the strategies that do: exact, all_contacts, adb, "
      "time_critical, distance)";
  StrategyVariant dfs = wide(strategy_variant("adb_dfs", {}, Budget{}));
  EXPECT_EQ(error_of([&] { check_strategy_options(dfs); }), no_walk);
  const AnyTree adb_tree = tree("aabb", "adb");
  EXPECT_EQ(error_of([&] { (void)adb_tree.prepare(adb_tree, dfs); }), no_walk);
  // ADB's wide walk reads a lane's box from its binary node alone: not the restricted boxtree's.
  const AnyTree rbox = tree("rbox", "adb");
  const std::string no_rbox =
      error_of([&] { (void)rbox.prepare(rbox, wide(strategy_variant("adb", {}, {}))); });
  EXPECT_EQ(
      no_rbox.rfind("strategy adb has no wide walk on 'rbox' trees (the volumes it walks wide: aabb, ", 0),
      0u)
      << no_rbox;

#ifndef BVHLAB_LEAN_VOLUMES  // every volume of the sanitizer builds' lean registry has a wide layout
  const AnyTree rss = tree("rss", "none");
  const std::string no_layout = error_of([&] { (void)rss.prepare(rss, wide(StrategyVariant{})); });
  EXPECT_EQ(no_layout.rfind("bounding volume 'rss' has no wide layout (the volumes that do: aabb, ", 0), 0u)
      << no_layout;
  EXPECT_EQ(wide_layout_refusal("rss"), no_layout);
#endif
  EXPECT_EQ(wide_layout_refusal("obb"), "");
  EXPECT_EQ(wide_layout_refusal("rbox"), "");
  EXPECT_NE(error_of([] { (void)wide_layout_refusal("octagon"); }).find("unknown bounding volume"),
            std::string::npos);

  StrategyVariant both = wide(StrategyVariant{});
  both.coherent = true;
  EXPECT_NE(error_of([&] { check_strategy_options(both); }).find("coherent or wide, not both"),
            std::string::npos);
  const AnyTree obb = tree("obb", "none");
  EXPECT_NE(error_of([&] { (void)obb.prepare(obb, both); }).find("coherent or wide, not both"),
            std::string::npos);
  EXPECT_EQ(wide(StrategyVariant{}).label(), "exact wide");
}

TEST(WideQuery, APointCloudsTreeIsRefused) {
  UnitCloud cloud;  // points on a ball (star-shaped: the normals are estimated from its centre)
  for (int i = 0; i < 300; ++i) {
    const double z = 1 - (2 * i + 1) / 300.0, r = std::sqrt(1 - z * z), phi = 2.399963 * i;
    cloud.positions.push_back(0.5 * Vec3(r * std::cos(phi), r * std::sin(phi), z));
  }
  const AnyTree points = AnyTree::build_points(cloud, "aabb", density_spec("none", {}), BuildOptions{});
  const AnyTree mesh = AnyTree::build(testing::make_torus(0.7, 0.25, 12, 6), MeshUnits{}, "aabb",
                                      density_spec("none", {}), BuildOptions{});
  for (const auto& sides : {std::pair{&points, &mesh}, std::pair{&mesh, &points}})
    EXPECT_EQ(error_of([&] { (void)sides.first->prepare(*sides.second, wide(StrategyVariant{})); }),
              "a wide query tests triangles at the leaves; a point cloud's tree has none");
}

// Each tree builds its wide layout on the first wide query, under its lock: threads preparing at once on
// fresh trees, from either side, all get the binary walk's answers. (The ThreadSanitizer stage builds no
// engine; tests/robustness/test_threads.cpp covers the typed queries there.)
TEST(WideQuery, ThreadsPreparingAtOnceAnswerAsTheBinaryWalk) {
  const AnyTree a = AnyTree::build(testing::make_torus(0.7, 0.25, 24, 12), MeshUnits{}, "obb",
                                   density_spec("none", {}), BuildOptions{});
  const AnyTree b = AnyTree::build(testing::make_torus(0.5, 0.2, 16, 8), MeshUnits{}, "obb",
                                   density_spec("none", {}), BuildOptions{});
  const auto poses = sliding_poses();
  const StrategyVariant all = strategy_variant("all_contacts", {}, Budget{});
  const std::vector<Result> ab = results_of(a, b, all, poses), ba = results_of(b, a, all, poses);
  constexpr int kThreads = 4;
  std::vector<std::vector<Result>> got(kThreads);
  std::vector<std::thread> threads;
  std::atomic<bool> go{false};
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      while (!go.load()) std::this_thread::yield();
      got[t] = t % 2 ? results_of(b, a, wide(all), poses) : results_of(a, b, wide(all), poses);
    });
  go = true;
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t)
    for (std::size_t i = 0; i < poses.size(); ++i)
      EXPECT_EQ(sorted_contacts(got[t][i].contacts), sorted_contacts((t % 2 ? ba : ab)[i].contacts))
          << "thread " << t << ", pose " << i;
}

TEST(WideQuery, ARefitDropsTheLayoutOfTheVolumesBefore) {
  const Mesh rest = testing::make_torus(0.7, 0.25, 24, 12);
  Mesh moved = rest;  // the same triangles, half of the tube pulled outward
  for (Vec3& v : moved.vertices)
    if (v.x() > 0) v.x() += 0.6;
  const AnyTree other = AnyTree::build(rest, MeshUnits{}, "obb", density_spec("none", {}), BuildOptions{});
  DeformingTree tree(rest, "obb", BuildOptions{});
  const StrategyVariant exact = wide(strategy_variant("exact", {}, Budget{}));
  (void)tree.tree().prepare(other, exact);  // the wide layout of the rest shape is built and kept
  tree.refit(moved, RefitMethod::Fit);
  const AnyTree truth = AnyTree::build(moved, MeshUnits{}, "obb", density_spec("none", {}), BuildOptions{});
  std::vector<RigidTransform> poses;  // B slides off A's pulled side: apart at 1.9 at rest, 2.5 refitted
  for (int i = 0; i < 40; ++i) poses.push_back(RigidTransform::translate(Vec3(0.1 * i, 0.05, 0)));
  const auto walked = results_of(tree.tree(), other, exact, poses);
  const auto expected = results_of(truth, other, strategy_variant("exact", {}, Budget{}), poses);
  std::size_t differ_from_rest = 0;
  const auto at_rest = results_of(other, other, strategy_variant("exact", {}, Budget{}), poses);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(walked[i].collides, expected[i].collides) << "pose " << i;
    differ_from_rest += expected[i].collides != at_rest[i].collides;
  }
  EXPECT_GT(differ_from_rest, 0u);  // the refit changed answers: a stale layout would show
}

}  // namespace
}  // namespace bvhlab
