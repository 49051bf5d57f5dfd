// The run-time layer's tree handle: what a prepared query runs is what it times, a saved tree comes back
// as the same tree, every check happens before a pose is queried, and every registry names an unknown
// choice the same way.
#include "adb/update.hpp"
#include "bvh/triangle_distance.hpp"
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"
#include "support/errors.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/broad_phase/registry.hpp"
#include "traversal/frame_budget.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using testing::error_of;
using testing::poses_along_x;

AnyTree torus_tree(const std::string& bv, const std::string& density) {
  return AnyTree::build(testing::make_torus(0.7, 0.25, 24, 12), MeshUnits{}, bv, density_spec(density, {}),
                        BuildOptions{});
}

TEST(AnyTree, APreparedQueryTimesWhatItRuns) {
  const AnyTree a = torus_tree("dop24", "adb"), b = torus_tree("dop24", "adb");
  const auto poses = poses_along_x();
  const auto query = a.prepare(b, strategy_variant("adb", {{"p_min", 0.9}}, Budget{}));
  std::vector<Result> results(poses.size());
  query->run(poses, [&](std::size_t i, const Result& r) { results[i] = r; });
  std::vector<QueryRecord> records;
  query->time(poses, 3, records);
  ASSERT_EQ(records.size(), poses.size());
  std::size_t colliding = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(records[i].collides, results[i].collides) << i;
    EXPECT_EQ(records[i].counters.bv_tests, results[i].counters.bv_tests) << i;
    colliding += results[i].collides;
  }
  EXPECT_GT(colliding, 0u);  // the poses cover both answers
  EXPECT_LT(colliding, poses.size());
}

TEST(AnyTree, AnAnnotatedTreeIsACopyWithTheDensity) {
  const AnyTree plain = torus_tree("obb", "none");
  const AnyTree annotated = plain.annotated(density_spec("adb", {{"grid", 3}}), AnnotationContext{});
  EXPECT_EQ(plain.info().annotation, "none");
  EXPECT_EQ(annotated.info().density, "adb");
  EXPECT_EQ(annotated.info().annotation, density_spec("adb", {{"grid", 3}}).label());
  EXPECT_EQ(annotated.info().nodes, plain.info().nodes);
  EXPECT_GT(annotated.info().density_bytes, 0);
  EXPECT_THROW((void)annotated.annotated(density_spec("adb", {}), AnnotationContext{}), std::logic_error);
}

TEST(AnyTree, SavedBytesComeBackAsTheSameTree) {
  const Mesh mesh = testing::make_torus(0.7, 0.25, 24, 12);
  const AnyTree built = AnyTree::build(mesh, MeshUnits{}, "aabb", density_spec("adb", {}), BuildOptions{});
  const AnyTree loaded = AnyTree::from_bytes(built.save_bytes("torus"), "torus", &mesh);
  EXPECT_EQ(loaded.info().bv, "aabb");
  EXPECT_EQ(loaded.info().annotation, built.info().annotation);
  EXPECT_EQ(loaded.info().nodes, built.info().nodes);
  EXPECT_TRUE(loaded.info().polygons);
  const auto poses = poses_along_x();
  std::vector<char> from_built, from_loaded;
  built.prepare(built, StrategyVariant{})->run(poses, [&](std::size_t, const Result& r) {
    from_built.push_back(r.collides);
  });
  loaded.prepare(loaded, StrategyVariant{})->run(poses, [&](std::size_t, const Result& r) {
    from_loaded.push_back(r.collides);
  });
  EXPECT_EQ(from_built, from_loaded);
  // Without its mesh it has no polygons, and a strategy that tests triangles is refused before any pose.
  const AnyTree bare = AnyTree::from_bytes(built.save_bytes("torus"), "torus");
  EXPECT_NE(error_of([&] { (void)bare.prepare(bare, StrategyVariant{}); }).find("without polygons"),
            std::string::npos);
}

TEST(AnyTree, PrepareRefusesWhatCannotRun) {
  const AnyTree plain = torus_tree("aabb", "none"), adb = torus_tree("aabb", "adb");
  const AnyTree obb = torus_tree("obb", "none");
  EXPECT_EQ(
      error_of([&] { (void)plain.prepare(plain, strategy_variant("adb", {}, Budget{})); }),
      "strategy adb does not run on trees with density 'none' (it runs on: adb, adb_paper, adb_normal)");
  EXPECT_NE(error_of([&] { (void)plain.prepare(obb, StrategyVariant{}); }).find("differ in BV or density"),
            std::string::npos);
  EXPECT_NE(error_of([&] { (void)plain.prepare(adb, StrategyVariant{}); }).find("differ in BV or density"),
            std::string::npos);
}

/// Every pose's result of `variant` between a and b.
std::vector<Result> results_of(const AnyTree& a, const AnyTree& b, const StrategyVariant& variant,
                               const std::vector<RigidTransform>& poses) {
  std::vector<Result> out(poses.size());
  a.prepare(b, variant)->run(poses, [&](std::size_t i, const Result& r) { out[i] = r; });
  return out;
}

TEST(AnyTree, TheDistanceStrategiesRunThroughTheRegistry) {
  const AnyTree a = torus_tree("dop24", "adb"), b = torus_tree("dop24", "adb");  // any density serves
  std::vector<RigidTransform> poses;
  for (int i = 0; i < 40; ++i) poses.push_back(RigidTransform::translate(Vec3(0.1 * i, 0.02 * i, 0)));
  const auto exact = results_of(a, b, StrategyVariant{}, poses);
  const auto distance = results_of(a, b, strategy_variant("distance", {}, Budget{}), poses);
  StrategyVariant coherent = strategy_variant("distance", {}, Budget{});
  coherent.coherent = true;
  const auto warm = results_of(a, b, coherent, poses);
  const auto within = results_of(a, b, strategy_variant("tolerance", {{"tolerance", 0.2}}, Budget{}), poses);
  const auto anytime = results_of(a, b, strategy_variant("distance_anytime", {}, Budget{20, 0}), poses);
  int touching = 0, apart = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_TRUE(distance[i].proximity.has_value()) << i;
    const Proximity& p = *distance[i].proximity;
    EXPECT_EQ(distance[i].collides, exact[i].collides) << i;
    EXPECT_EQ(p.distance == 0, exact[i].collides) << i;
    EXPECT_EQ(p.lower_bound, p.distance) << i;
    EXPECT_EQ(distance[i].witness.has_value(), exact[i].collides) << i;
    ASSERT_TRUE(p.triangles.has_value()) << i;
    const Vec3 gap(p.on_a[0] - p.on_b[0], p.on_a[1] - p.on_b[1], p.on_a[2] - p.on_b[2]);
    EXPECT_NEAR(gap.norm(), p.distance, 1e-12) << i;
    EXPECT_EQ(warm[i].proximity->distance, p.distance) << i;
    EXPECT_EQ(within[i].collides, p.distance <= 0.2) << i;
    EXPECT_FALSE(within[i].proximity.has_value());
    ASSERT_TRUE(anytime[i].proximity.has_value()) << i;
    EXPECT_LE(anytime[i].proximity->lower_bound, p.distance) << i;
    EXPECT_GE(anytime[i].proximity->distance, p.distance) << i;
    EXPECT_LE(anytime[i].counters.bv_tests, 20u) << i;
    (p.distance == 0 ? touching : apart) += 1;
  }
  EXPECT_GT(touching, 5);
  EXPECT_GT(apart, 5);
}

/// What two runs of one strategy must share: the answer, its witnesses and distance, and the work.
void expect_same_results(const std::vector<Result>& got, const std::vector<Result>& want,
                         const std::string& label) {
  ASSERT_EQ(got.size(), want.size()) << label;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].collides, want[i].collides) << label << ", pose " << i;
    EXPECT_EQ(got[i].witness, want[i].witness) << label << ", pose " << i;
    EXPECT_EQ(got[i].contacts, want[i].contacts) << label << ", pose " << i;
    EXPECT_EQ(got[i].counters.bv_tests, want[i].counters.bv_tests) << label << ", pose " << i;
    ASSERT_EQ(got[i].proximity.has_value(), want[i].proximity.has_value()) << label << ", pose " << i;
    if (got[i].proximity) {
      EXPECT_EQ(got[i].proximity->distance, want[i].proximity->distance) << label;
    }
  }
}

// The strategies that run on every density read only the trees' hierarchies: the engine compiles their
// queries once per volume (engine/volume_slot.cpp.in), in the file of the first two densities, and the trees
// of every other density use that code. On each volume and density, cold and coherent, they answer as on
// the plain trees, and exact answers as guided exact (which reads the density: the other code path) does.
TEST(AnyTree, AStrategyOfEveryDensityAnswersOnEachAsOnThePlainTree) {
  // Tilted about x as they move apart: the trees' roles do not commute (B turned about A is not A about B).
  std::vector<RigidTransform> poses;
  for (int i = 0; i < 40; ++i)
    poses.push_back(RigidTransform{Eigen::AngleAxisd(0.9, Vec3::UnitX()).toRotationMatrix(),
                                   Vec3(0.04 * i, 0.2, 0.01 * i)});
  const Mesh torus_a = testing::make_torus(0.7, 0.25, 16, 8), torus_b = testing::make_torus(0.5, 0.2, 12, 8);
  std::size_t compared = 0, colliding = 0;
  for (const std::string& bv : strategy_info("exact").volumes) {
    const DensitySpec none = density_spec("none", {});
    const AnyTree a = AnyTree::build(torus_a, MeshUnits{}, bv, none, BuildOptions{});
    const AnyTree b = AnyTree::build(torus_b, MeshUnits{}, bv, none, BuildOptions{});
    for (const DensityInfo& density : density_table()) {
      if (density.name == "none") continue;
      const DensitySpec spec = density_spec(density.name, {});
      const AnyTree a_dense = a.annotated(spec, AnnotationContext{});
      const AnyTree b_dense = b.annotated(spec, AnnotationContext{});
      for (const StrategyInfo& s : strategy_table()) {
        if (s.densities.size() != density_table().size() || !s.volume_refusal(bv).empty()) continue;
        const ParamValues values =
            s.parameter("tolerance") ? ParamValues{{"tolerance", 0.05}} : ParamValues{};
        StrategyVariant variant =
            strategy_variant(s.name, values, s.budget == BudgetUse::Required ? Budget{30, 0} : Budget{});
        for (const bool coherent : {false, true}) {
          if (coherent && !s.coherent) continue;
          variant.coherent = coherent;
          const std::string label =
              s.name + (coherent ? " coherent" : "") + " on " + bv + ", " + density.name;
          expect_same_results(results_of(a_dense, b_dense, variant, poses), results_of(a, b, variant, poses),
                              label);
          ++compared;
        }
      }
      const auto exact = results_of(a_dense, b_dense, StrategyVariant{}, poses);
      const auto guided = results_of(a_dense, b_dense, strategy_variant("guided_exact", {}, Budget{}), poses);
      for (std::size_t i = 0; i < poses.size(); ++i) {
        EXPECT_EQ(exact[i].collides, guided[i].collides) << bv << ", " << density.name << ", pose " << i;
        colliding += exact[i].collides;
      }
    }
  }
  // At least exact and all contacts, cold and coherent, on every volume and density: fewer would mean that
  // one was left out. And the poses cover both answers.
  const std::size_t series = strategy_info("exact").volumes.size() * (density_table().size() - 1);
  EXPECT_GE(compared, series * 4);
  EXPECT_GT(colliding, 0u);
  EXPECT_LT(colliding, series * poses.size());
}

TEST(AnyTree, TheDistanceStrategiesRefuseAVolumeWithoutADistanceBound) {
  const AnyTree rbox = torus_tree("rbox", "none");
  for (const char* name : {"distance", "tolerance"}) {
    const ParamValues values =
        std::string(name) == "tolerance" ? ParamValues{{"tolerance", 0.1}} : ParamValues{};
    const std::string message =
        error_of([&] { (void)rbox.prepare(rbox, strategy_variant(name, values, Budget{})); });
    EXPECT_EQ(message.rfind("strategy " + std::string(name) +
                                " does not run on trees of volume 'rbox', which has no distance bound "
                                "(it runs on: aabb, ",
                            0),
              0u)
        << message;
  }
  const StrategyInfo& info = strategy_info("distance");
  EXPECT_EQ(std::count(info.volumes.begin(), info.volumes.end(), "rbox"), 0);
  EXPECT_EQ(std::count(info.volumes.begin(), info.volumes.end(), "obb"), 1);
  // The tolerance is checked before any pose, as every parameter is.
  EXPECT_NE(error_of([] {
              (void)strategy_variant("tolerance", {{"tolerance", -1}}, Budget{});
            }).find("tolerance"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)strategy_variant("distance_anytime", {}, Budget{}); }).find("needs a budget"),
            std::string::npos);
}

/// How far `p` lies from triangle `t` (a point is a degenerate triangle).
double gap(const std::array<double, 3>& p, const TrianglePoints& t) {
  const Vec3 v(p[0], p[1], p[2]);
  return triangle_distance({v, v, v}, t).distance;
}

TEST(AnyTree, ContactGeometryLiesOnBothTrianglesOfEachContact) {
  const Mesh torus = testing::make_torus(0.7, 0.25, 24, 12);
  const AnyTree a = AnyTree::build(torus, MeshUnits{}, "obb", density_spec("none", {}), BuildOptions{});
  StrategyVariant all = strategy_variant("all_contacts", {}, Budget{});
  StrategyVariant first = StrategyVariant{};
  all.contact_geometry = first.contact_geometry = true;
  const auto poses = poses_along_x();
  const auto plain = results_of(a, a, strategy_variant("all_contacts", {}, Budget{}), poses);
  const auto listed = results_of(a, a, all, poses);
  const auto witnessed = results_of(a, a, first, poses);
  std::size_t checked = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_TRUE(plain[i].contact_geometry.empty()) << i;  // only when asked for
    ASSERT_EQ(listed[i].contacts, plain[i].contacts) << i;
    ASSERT_EQ(listed[i].contact_geometry.size(), listed[i].contacts.size()) << i;
    ASSERT_EQ(witnessed[i].contact_geometry.size(), witnessed[i].witness ? 1u : 0u) << i;
    if (witnessed[i].witness) {
      EXPECT_EQ(witnessed[i].contact_geometry[0].triangles, *witnessed[i].witness);
    }
    for (std::size_t k = 0; k < listed[i].contacts.size(); ++k) {
      const ContactGeometry& g = listed[i].contact_geometry[k];
      ASSERT_EQ(g.triangles, listed[i].contacts[k]);
      const TrianglePoints ta = torus.triangle(g.triangles.a);
      const TrianglePoints source = torus.triangle(g.triangles.b);
      const TrianglePoints tb = {poses[i].apply(source[0]), poses[i].apply(source[1]),
                                 poses[i].apply(source[2])};
      for (const auto& end : {g.from, g.to, g.point}) {
        EXPECT_LE(gap(end, ta), 1e-12) << i << " " << k;
        EXPECT_LE(gap(end, tb), 1e-12) << i << " " << k;
      }
      const Vec3 n(g.normal[0], g.normal[1], g.normal[2]);
      EXPECT_NEAR(n.norm(), 1, 1e-12) << i << " " << k;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100u);  // the poses cross the torus: many contacts are checked
}

TEST(AnyTree, ContactGeometryGoesOnlyToIntersectingPairs) {
  // The tori (outer radius 0.95) 2 apart along x leave a gap of 0.1: the tolerance query names a witness
  // within 0.2, whose triangles do not meet, so it gets no geometry.
  const AnyTree a = torus_tree("obb", "none");
  StrategyVariant within = strategy_variant("tolerance", {{"tolerance", 0.2}}, Budget{});
  within.contact_geometry = true;
  const auto r = results_of(a, a, within, {RigidTransform::translate(Vec3(2, 0, 0))});
  ASSERT_TRUE(r[0].collides);
  ASSERT_TRUE(r[0].witness.has_value());
  EXPECT_TRUE(r[0].contact_geometry.empty());
}

TEST(AnyTree, ContactGeometryIsRefusedWhereNoTrianglesMeet) {
  const AnyTree adb = torus_tree("aabb", "adb");
  StrategyVariant estimate = strategy_variant("adb", {}, Budget{});
  estimate.contact_geometry = true;
  const std::string message = error_of([&] { check_strategy_options(estimate); });
  EXPECT_EQ(message.rfind("strategy adb tests no triangles", 0), 0u) << message;
  EXPECT_EQ(error_of([&] { (void)adb.prepare(adb, estimate); }), message);
}

TEST(AnyTree, AFrameBudgetRunsOnOneTypeOfTreesWithProbabilities) {
  const AnyTree a = torus_tree("aabb", "adb"), b = torus_tree("aabb", "adb");
  const AnyTree other = torus_tree("obb", "adb"), plain = torus_tree("aabb", "none");
  FrameOptions options;
  options.budget.max_bv_tests = 1000;
  const RigidTransform near = RigidTransform::translate(Vec3(0.3, 0, 0));
  const std::vector<FramePairRef> good{{&a, &b, near, 1}, {&b, &a, near, 2}};
  const auto outcomes = AnyTree::schedule_frame(good, options);
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_TRUE(outcomes[0].collides);
  const std::vector<FramePairRef> mixed{{&a, &b, near, 1}, {&other, &other, near, 2}};
  EXPECT_NE(error_of([&] { (void)AnyTree::schedule_frame(mixed, options); }).find("one volume and density"),
            std::string::npos);
  const std::vector<FramePairRef> without{{&plain, &plain, near, 1}};
  EXPECT_NE(error_of([&] { (void)AnyTree::schedule_frame(without, options); }).find("with probabilities"),
            std::string::npos);
}

TEST(Registries, AnUnknownNameReadsTheSameInEveryRegistry) {
  const auto starts = [](const std::string& message, const std::string& prefix) {
    return message.rfind(prefix, 0) == 0 && message.back() == ')';
  };
  EXPECT_TRUE(starts(error_of([] { (void)torus_tree("abb", "none"); }),
                     "unknown bounding volume 'abb' (known: aabb, "));
  EXPECT_TRUE(
      starts(error_of([] { (void)density_spec("adbb", {}); }), "unknown density 'adbb' (known: none, "));
  EXPECT_TRUE(starts(error_of([] { (void)strategy_variant("fastest", {}, Budget{}); }),
                     "unknown strategy 'fastest' (known: exact, "));
  EXPECT_TRUE(
      starts(error_of([] { (void)make_broad_phase("grid"); }), "unknown broad phase 'grid' (known: "));
  EXPECT_TRUE(starts(error_of([] { with_density_update("magic", [](auto) {}); }),
                     "unknown density update 'magic' (known: stale, "));
  EXPECT_TRUE(
      starts(error_of([] { (void)frame_policy("fastest"); }), "unknown frame policy 'fastest' (known: "));
}

}  // namespace
}  // namespace bvhlab
