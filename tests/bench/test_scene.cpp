// Scene files: a full scene parses into what it says; every bad field is refused with its JSON path.
#include "bench/core/scene.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/strategies.hpp"

#include <gtest/gtest.h>

namespace bvhlab {
namespace {

using testing::TempDir;

class SceneTest : public testing::SceneParsing {
 protected:
  SceneTest() : SceneParsing("test.json") {}
  void SetUp() override { testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj"); }
};

// A minimal valid scene with one replaceable part, so each error case changes exactly one field.
std::string scene_with(
    const std::string& objects = R"([{"mesh": "torus.obj"}])",
    const std::string& hierarchies = R"([{"bv": "aabb"}, {"bv": "dop24"}])",
    const std::string& strategies = R"([{"type": "exact"}, {"type": "adb", "p_min": [0.5, 0.9]}])",
    const std::string& extra = R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5})") {
  return R"({"objects": )" + objects + R"(, "hierarchies": )" + hierarchies + R"(, "strategies": )" +
         strategies + (extra.empty() ? "" : ", " + extra) + "}";
}

// `count` numbers from `first` by `step`, comma separated: a sweep's list.
std::string sweep(double first, double step, int count) {
  std::string out;
  for (int k = 0; k < count; ++k) out += (k ? ", " : "") + std::to_string(first + k * step);
  return out;
}

TEST_F(SceneTest, ParsesWhatTheFileSays) {
  const Scene scene = parse(R"({
    "name": "t",
    "objects": [{"mesh": "torus.obj", "name": "ring", "scale": 0.5,
                 "placement": {"translation": [1, 2, 3], "axis_angle_deg": [0, 0, 1, 90]}},
                {"mesh": "torus.obj", "name": "other", "normalize": false}],
    "pairs": [["ring", "other"]],
    "hierarchies": [{"bv": "aabb", "split": "median", "max_leaf_triangles": 4}, {"bv": "dop24", "name": "dop"}],
    "annotation": {"type": "adb", "grid": 3, "tau": 0.25},
    "strategies": [{"type": "exact"}, {"type": "guided_exact", "hierarchies": ["aabb"]},
                   {"type": "adb", "p_min": [0.5, 0.8, 0.95], "hierarchies": ["aabb"]},
                   {"type": "time_critical", "p_min": 0.7, "budgets": [{"bv_tests": 10}, {"deadline_us": 5.5}],
                    "hierarchies": ["aabb"]},
                   {"type": "adb_dfs", "p_min": 0.9, "confirm_levels": [1, 3], "hierarchies": ["aabb"]}],
    "workload": {"type": "protocol", "distances": [0.5, 1.5], "steps": 7},
    "report": {"quality_distances": [1.0, 1.5], "cgal_sample": 3, "operating_point": {"p_min": 0.8},
               "baseline": {"hierarchy": "dop", "strategy": "exact"}}})");
  EXPECT_EQ(scene.name, "t");
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[0].name, "ring");
  EXPECT_DOUBLE_EQ(scene.objects[0].scale, 0.5);
  EXPECT_TRUE(scene.objects[0].placement.translation.isApprox(Vec3(1, 2, 3)));
  EXPECT_TRUE(scene.objects[0].placement.apply(Vec3(1, 0, 0)).isApprox(Vec3(1, 3, 3), 1e-12));
  EXPECT_FALSE(scene.objects[1].normalize);
  EXPECT_EQ(scene.objects[0].path, std::filesystem::absolute(dir / "torus.obj").lexically_normal());
  ASSERT_EQ(scene.pairs.size(), 1u);
  EXPECT_EQ(scene.pairs[0].label(), "ring|other");
  ASSERT_EQ(scene.hierarchies.size(), 2u);
  EXPECT_EQ(scene.hierarchies[0].build.split, SplitMethod::Median);
  EXPECT_EQ(scene.hierarchies[0].build.max_leaf_triangles, 4u);
  EXPECT_EQ(scene.hierarchies[1].name, "dop");
  EXPECT_EQ(scene.density.name, "adb");
  EXPECT_EQ(scene.density.values.at("grid"), 3);
  EXPECT_DOUBLE_EQ(scene.density.values.at("tau"), 0.25);
  EXPECT_EQ(scene.density.label(), "adb grid=3 tau=0.25");
  // Only the hierarchy a strategy that needs the density runs on is annotated.
  EXPECT_TRUE(scene.needs_density(scene.hierarchies[0]));
  EXPECT_FALSE(scene.needs_density(scene.hierarchies[1]));
  ASSERT_EQ(scene.strategies.size(), 5u);
  EXPECT_EQ(expand(scene.strategies[2]).size(), 3u);
  const auto confirmed = expand(scene.strategies[4]);  // one variant per level, in the label
  ASSERT_EQ(confirmed.size(), 2u);
  EXPECT_EQ(confirmed[1].label(), "adb_dfs p_min=0.9 confirm_levels=3");
  EXPECT_EQ(strategy_options<AdbDfsStrategy>(confirmed[1].values).confirm_levels, 3);
  EXPECT_EQ(strategy_options<AdbStrategy>(expand(scene.strategies[2])[0].values).confirm_levels,
            0);  // the paper
  const auto budgets = expand(scene.strategies[3]);
  ASSERT_EQ(budgets.size(), 2u);
  EXPECT_EQ(budgets[0].budget.max_bv_tests, 10u);
  EXPECT_DOUBLE_EQ(budgets[1].budget.deadline_us, 5.5);
  EXPECT_DOUBLE_EQ(budgets[1].value_or("p_min", -1), 0.7);
  EXPECT_EQ(budgets[1].label(), "time_critical p_min=0.7 deadline_us=5.5");
  EXPECT_EQ(budgets[0].budget_label(), "bv_tests=10");
  ASSERT_EQ(scene.workload.groups.size(), 2u);
  EXPECT_DOUBLE_EQ(scene.workload.groups[1].distance, 1.5);
  EXPECT_EQ(scene.workload.groups[1].poses.size(), 7u);
  EXPECT_EQ(scene.report.cgal_sample, 3);
  EXPECT_EQ(scene.report.operating_hierarchy, "aabb");
  EXPECT_DOUBLE_EQ(scene.report.operating_p_min, 0.8);
  EXPECT_EQ(scene.report.baseline_hierarchy, "dop");
}

TEST_F(SceneTest, DefaultsFollowTheProtocol) {
  const Scene scene = parse(scene_with());
  ASSERT_EQ(scene.pairs.size(), 1u);
  EXPECT_EQ(scene.pairs[0].a, "torus");
  EXPECT_EQ(scene.pairs[0].b, "torus");
  EXPECT_EQ(scene.workload.steps, 5000);
  EXPECT_EQ(scene.workload.groups.size(), 9u);
  EXPECT_EQ(scene.report.baseline_hierarchy, "dop24");  // the paper's baseline when present
  EXPECT_DOUBLE_EQ(scene.report.operating_p_min, 0.9);  // the largest p_min <= 0.9
  EXPECT_TRUE(scene.needs_density(scene.hierarchies[1]));
}

// "wide": a strategy's variants walk the wide layout, on the hierarchies whose volume has one (others are
// left out, or refused when named); strategies without a wide walk, and coherent with wide, are refused.
TEST_F(SceneTest, WideStrategiesRunWhereTheVolumeHasALayout) {
#ifndef BVHLAB_LEAN_VOLUMES
  const std::string second_bv = "rss";
#else  // every volume of the sanitizer builds' lean registry has a wide layout: a second one that has one
  const std::string second_bv = "aabb";
#endif
  const std::string hierarchies = R"([{"bv": "obb"}, {"bv": ")" + second_bv + R"("}])";
  const Scene scene = parse(scene_with(R"([{"mesh": "torus.obj"}])", hierarchies,
                                       R"([{"type": "exact"}, {"type": "exact", "wide": true}])", ""));
  ASSERT_EQ(scene.strategies.size(), 2u);
  EXPECT_FALSE(scene.strategies[0].wide);
  EXPECT_TRUE(scene.strategies[1].wide);
  EXPECT_EQ(expand(scene.strategies[1]).at(0).label(), "exact wide");
  EXPECT_TRUE(scene.applies(scene.strategies[1], scene.hierarchies[0]));
  EXPECT_TRUE(scene.applies(scene.strategies[0], scene.hierarchies[1]));
  const auto refused = [&](const std::string& strategies, const std::string& expected) {
    const std::string message =
        error_of(scene_with(R"([{"mesh": "torus.obj"}])", hierarchies, strategies, ""));
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
#ifndef BVHLAB_LEAN_VOLUMES
  EXPECT_FALSE(scene.applies(scene.strategies[1], scene.hierarchies[1]));  // rss: no wide layout
  refused(R"([{"type": "exact", "wide": true, "hierarchies": ["rss"]}])",
          "/strategies/0/hierarchies/0: bounding volume 'rss' has no wide layout");
#endif
  refused(R"([{"type": "guided_exact", "wide": true}])",
          "/strategies/0/wide: strategy guided_exact does not run on wide trees");
  refused(R"([{"type": "exact", "wide": true, "coherent": true}])",
          "/strategies/0/wide: a coherent query walks the binary trees");
  refused(R"([{"type": "exact", "wide": "yes"}])", "/strategies/0/wide: expected true or false");
}

// A strategy whose wide walk takes only some layouts (the distance: oriented boxes) runs wide on those,
// leaves the others out, and refuses them when named.
TEST_F(SceneTest, WideDistanceRunsOnOrientedBoxesOnly) {
  const std::string hierarchies = R"([{"bv": "obb"}, {"bv": "aabb"}])";
  const Scene scene = parse(scene_with(R"([{"mesh": "torus.obj"}])", hierarchies,
                                       R"([{"type": "distance"}, {"type": "distance", "wide": true}])", ""));
  ASSERT_EQ(scene.strategies.size(), 2u);
  EXPECT_TRUE(scene.applies(scene.strategies[1], scene.hierarchies[0]));
  EXPECT_FALSE(scene.applies(scene.strategies[1], scene.hierarchies[1]));  // aabb: no four-lane bound
  EXPECT_TRUE(scene.applies(scene.strategies[0], scene.hierarchies[1]));
  const std::string message =
      error_of(scene_with(R"([{"mesh": "torus.obj"}])", hierarchies,
                          R"([{"type": "distance", "wide": true, "hierarchies": ["aabb"]}])", ""));
  EXPECT_NE(message.find("/strategies/0/hierarchies/0: strategy distance has no wide walk on 'aabb' trees"),
            std::string::npos)
      << message;
}

TEST_F(SceneTest, CoherentStrategiesAndProtocolStrides) {
  const Scene scene =
      parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                       R"([{"type": "exact"}, {"type": "all_contacts", "coherent": true}])",
                       R"("workload": {"distances": [0.8, 1.2], "steps": 100, "stride": 7})"));
  ASSERT_EQ(scene.strategies.size(), 2u);
  EXPECT_FALSE(scene.strategies[0].coherent);
  EXPECT_TRUE(scene.strategies[1].coherent);
  const auto variants = expand(scene.strategies[1]);
  ASSERT_EQ(variants.size(), 1u);
  EXPECT_TRUE(variants[0].coherent);
  EXPECT_EQ(variants[0].label(), "all_contacts coherent");
  // Every 7th of 100 steps: steps 0, 7, ..., 98, in order.
  ASSERT_EQ(scene.workload.groups.size(), 2u);
  const auto& poses = scene.workload.groups[1].poses;
  ASSERT_EQ(poses.size(), 15u);
  EXPECT_TRUE(poses[3].rotation.isApprox(protocol_pose(1.2, 21, 100).rotation));
  EXPECT_EQ(poses[3].translation, protocol_pose(1.2, 21, 100).translation);
  // The stride is part of the pose set's identity (the ground-truth cache's key).
  const Scene every_step =
      parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                       R"("workload": {"distances": [0.8, 1.2], "steps": 100})"));
  EXPECT_NE(scene.workload.identity, every_step.workload.identity);
  // The poses a scene generates count after the stride: a fine turn sampled sparsely fits the limit.
  auto turn = [&](int stride) {
    return scene_with(
        R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
        R"("workload": {"distances": [1.2], "steps": 10000000, "stride": )" + std::to_string(stride) + "}");
  };
  EXPECT_EQ(parse(turn(100000)).workload.groups[0].poses.size(), 100u);
  EXPECT_NE(error_of(turn(9)).find("1 distances of 1111112 poses make 1111112 poses"), std::string::npos)
      << error_of(turn(9));
  EXPECT_EQ(every_step.workload.groups[1].poses.size(), 100u);
}

TEST_F(SceneTest, ExactOnlySceneNeedsNoAnnotation) {
  const Scene scene =
      parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])", ""));
  EXPECT_EQ(scene.density.name, "none");
  EXPECT_FALSE(scene.needs_density(scene.hierarchies[0]));
}

struct BadField {
  std::string scene;
  std::string expected;  // a substring of the error: the JSON path and what was expected
};

TEST_F(SceneTest, BadFieldsAreNamedByTheirJsonPath) {
  const std::vector<BadField> cases = {
      {"{", "test.json: not valid JSON"},
      {"[1]", "test.json: /: expected an object"},
      {R"({"hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}]})", "/objects: missing"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}, {"bv": "abb"}])"),
       "/hierarchies/1/bv: expected one of aabb, "},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "spilt": "sah"}])"),
       "/hierarchies/0/spilt: unknown field; expected one of bv, name, split"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "split": "fast"}])"),
       "/hierarchies/0/split: expected one of sah, median; got \"fast\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}, {"bv": "aabb"}])"),
       "/hierarchies/1/bv: duplicate hierarchy name \"aabb\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "max_leaf_triangles": 0}])"),
       "/hierarchies/0/max_leaf_triangles: expected an integer in [1, 255]; got 0"},
      {scene_with(R"([{"mesh": "nope.obj"}])"), "/objects/0/mesh: mesh \"nope.obj\" not found"},
      {scene_with(R"([{"mesh": "torus.obj", "scale": -2}])"), "/objects/0/scale: expected a number in [0, "},
      {scene_with(R"([{"mesh": "torus.obj", "placement": {"rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 2]]}}])"),
       "/objects/0/placement/rotation: not a rotation"},
      {scene_with(R"([{"mesh": "torus.obj", "placement": {"translation": [1, 2]}}])"),
       "/objects/0/placement/translation: expected an array of 3 numbers"},
      {scene_with(R"([{"mesh": "torus.obj"}, {"mesh": "torus.obj"}])"),
       "/objects/1/mesh: duplicate object name"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("pairs": [["torus", "ring"]])"),
       "/pairs/0/1: no object named \"ring\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "adb", "p_min": [0.5, 1.5]}])"),
       "/strategies/0/p_min/1: p_min must be a number in [0, 1], got 1.5"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "adb", "p_min": 0.9}])",
                  ""),
       "/strategies/0/type: \"adb\" needs a density it can estimate from (\"adb\", \"adb_paper\", "
       "\"adb_normal\"), the "
       "scene's is \"none\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "fastest"}])"),
       "/strategies/0/type: expected one of exact, all_contacts, guided_exact, adb, time_critical"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "time_critical", "budgets": [{}]}])"),
       "/strategies/0/budgets/0: expected \"bv_tests\" and/or \"deadline_us\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "exact", "hierarchies": ["dop24"]}])", ""),
       "/strategies/0/hierarchies/0: expected one of aabb; got \"dop24\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])"),
       "/annotation: a density is set but no strategy needs it"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "adb", "p_min": 0.9}])",
                  R"("annotation": {"type": "adb", "grid": 7})"),
       "/annotation/grid: grid must be an integer in [2, 4], got 7"},
      // Parameters come from the policies' tables: ranges, fields a policy does not take, combinations.
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "adb", "p_min": 0.9}])",
                  R"("annotation": {"type": "adb", "tau": 1.5})"),
       "/annotation/tau: tau must be a number in [0, 1], got 1.5"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("annotation": {"type": "none", "grid": 2})"),
       "/annotation/grid: unknown field; expected one of type"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact", "p_min": 0.9}])",
                  ""),
       "/strategies/0/p_min: unknown field; expected one of type, hierarchies"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "adb", "budgets": [{"bv_tests": 5}]}])"),
       "/strategies/0/budgets: unknown field; expected one of type, hierarchies, p_min, confirm_levels"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "adb", "p_min": 0.9, "confirm_levels": [2, 1.5]}])"),
       "/strategies/0/confirm_levels/1: confirm_levels must be an integer in [0, 32], got 1.5"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "time_critical"}])"),
       "/strategies/0/budgets: missing"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "time_critical", "p_min": [0.5, 0.9], "budgets": [{"bv_tests": 5}]}])"),
       "/strategies/0/p_min: expected a number; got an array"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"type": "protocol", "steps": 0})"),
       "/workload/steps: expected an integer in [1, 10000000]; got 0"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"type": "protocol", "steps": 100, "stride": 101})"),
       "/workload/stride: expected an integer in [1, 100]; got 101"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"distances": [1, 2, 3], "steps": 400000})"),
       "/workload: 3 distances of 400000 poses make 1200000 poses; a scene generates at most 1000000"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"type": "random", "count": 1000001, "box": [[0, 0, 0], [1, 1, 1]]})"),
       "/workload/count: expected an integer in [1, 1000000]; got 1000001"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"distances": [1, 2], "steps": 10},)"
                  R"( "calibration": {"training_seed": 2, "training_steps": 499991})"),
       "/calibration/training_steps: 2 training groups of 499991 poses and the workload's 20 make "
       "1000002 poses; a scene generates at most 1000000"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "adb", "p_min": [0.5, 0.9, 0.5]}])", R"("annotation": {"type": "adb"})"),
       "/strategies/0/p_min/2: p_min 0.5 is in the list already"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "adb", "p_min": [)" + sweep(0.01, 0.001, 100) +
                      R"(], "confirm_levels": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10]}])",
                  R"("annotation": {"type": "adb"})"),
       "/strategies/0: sweeps 1100 series; a strategy entry sweeps at most 1000"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                  R"([{"type": "exact", "coherent": 1}])", ""),
       "/strategies/0/coherent: expected true or false; got 1"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"distances": [1, "far"]})"),
       "/workload/distances/1: expected a number; got \"far\""},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("workload": {"type": "poses", "file": "missing.json"})"),
       "/workload/file: "},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "adb", "p_min": 0.9}])",
                  R"("annotation": {"type": "adb"}, "report": {"operating_point": {"p_min": 0.5}})"),
       "/report/operating_point/p_min: no \"adb\" strategy runs this p_min"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                  R"("report": {"quality_distances": [2, 1]})"),
       "/report/quality_distances: expected [min, max] with min <= max"},
  };
  for (const auto& c : cases) {
    const std::string message = error_of(c.scene);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "scene: " << c.scene << "\nerror: " << message << "\nexpected to contain: " << c.expected;
  }
}

TEST_F(SceneTest, AHierarchyMayCarryItsOwnAnnotation) {
  const Scene scene = parse(scene_with(
      R"([{"mesh": "torus.obj"}])",
      R"([{"bv": "aabb"}, {"bv": "aabb", "name": "paper", "annotation": {"type": "adb_paper", "grid": 3}}])",
      R"([{"type": "adb", "p_min": 0.9}])"));
  ASSERT_EQ(scene.hierarchies.size(), 2u);
  EXPECT_EQ(scene.density_of(scene.hierarchies[0]).label(), "adb grid=2 tau=0.5");
  EXPECT_EQ(scene.density_of(scene.hierarchies[1]).label(), "adb_paper grid=3 tau=0.25");
}

TEST_F(SceneTest, HierarchyAnnotationsAreCheckedLikeTheScenes) {
  const std::vector<BadField> cases = {
      {scene_with(R"([{"mesh": "torus.obj"}])",
                  R"([{"bv": "aabb", "annotation": {"type": "adb", "grid": 9}}])"),
       "/hierarchies/0/annotation/grid: grid must be an integer in [2, 4], got 9"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "annotation": {"type": "magic"}}])"),
       "/hierarchies/0/annotation/type: expected one of none, adb, adb_paper, adb_normal"},
#ifdef BVHLAB_HAVE_FCL  // a build without FCL refuses the "bv" first
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "fcl_obb", "annotation": {"type": "adb"}}])",
                  R"([{"type": "exact"}])", ""),
       "/hierarchies/0/annotation: FCL hierarchies run \"exact\" only"},
#endif
      {scene_with(R"([{"mesh": "torus.obj"}])",
                  R"([{"bv": "aabb"}, {"bv": "obb", "annotation": {"type": "adb_paper"}}])",
                  R"([{"type": "exact"}, {"type": "adb", "hierarchies": ["aabb"]}])"),
       "/hierarchies/1/annotation: a density is set but no strategy on this hierarchy needs it"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "annotation": {"type": "adb_paper"}}])",
                  R"([{"type": "adb"}])"),
       "/annotation: a density is set but no strategy needs it"},
      {scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb", "annotation": {"type": "none"}}])",
                  R"([{"type": "adb"}])"),
       "/strategies/0/type: \"adb\" needs a density it can estimate from (\"adb\", \"adb_paper\", "
       "\"adb_normal\"), hierarchy "
       "\"aabb\"'s is \"none\""},
  };
  for (const auto& c : cases) {
    const std::string message = error_of(c.scene);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "scene: " << c.scene << "\nerror: " << message << "\nexpected to contain: " << c.expected;
  }
}

TEST_F(SceneTest, RandomPosesAreSeededAndInsideTheirBox) {
  auto random_scene = [&](const std::string& workload) {
    return parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                            R"("workload": )" + workload));
  };
  const Scene a =
      random_scene(R"({"type": "random", "count": 200, "seed": 7, "box": [[-1, 0, 2], [1, 0.5, 3]]})");
  const Scene same =
      random_scene(R"({"type": "random", "count": 200, "seed": 7, "box": [[-1, 0, 2], [1, 0.5, 3]]})");
  const Scene other =
      random_scene(R"({"type": "random", "count": 200, "seed": 8, "box": [[-1, 0, 2], [1, 0.5, 3]]})");
  ASSERT_EQ(a.workload.groups.size(), 1u);
  const auto& poses = a.workload.groups[0].poses;
  ASSERT_EQ(poses.size(), 200u);
  Vec3 mean_row = Vec3::Zero();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_TRUE((poses[k].translation.array() >= Vec3(-1, 0, 2).array()).all() &&
                (poses[k].translation.array() <= Vec3(1, 0.5, 3).array()).all())
        << poses[k].translation.transpose();
    EXPECT_NO_THROW(poses[k].validate());
    EXPECT_EQ(poses[k].rotation, same.workload.groups[0].poses[k].rotation);
    mean_row += poses[k].rotation.row(0).transpose();
  }
  // Uniform rotations: the image of x has no preferred direction (mean near 0, not near a fixed axis).
  EXPECT_LT((mean_row / 200.0).norm(), 0.2);
  EXPECT_NE(a.workload.identity, other.workload.identity);
  EXPECT_NE(poses[0].translation, other.workload.groups[0].poses[0].translation);
  EXPECT_EQ(a.workload.identity, same.workload.identity);

  EXPECT_NE(
      error_of(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                          R"("workload": {"type": "random", "count": 5, "box": [[1, 0, 0], [0, 1, 1]]})"))
          .find("/workload/box: expected the box's lower corner first"),
      std::string::npos);
  EXPECT_NE(
      error_of(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                          R"("workload": {"type": "random", "count": 0, "box": [[0, 0, 0], [1, 1, 1]]})"))
          .find("/workload/count: expected an integer in [1, "),
      std::string::npos);
  EXPECT_NE(error_of(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                                R"("workload": {"type": "random", "count": 3})"))
                .find("/workload/box: missing"),
            std::string::npos);
}

TEST_F(SceneTest, CalibrationDrawsHeldOutTrainingPoses) {
  const std::string workload = R"("workload": {"distances": [0.8, 1.6], "steps": 40})";
  auto with = [&](const std::string& calibration, const std::string& w) {
    return scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                      R"([{"type": "exact"}, {"type": "adb", "p_min": 0.9}])",
                      R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5}, )" + w + ", " + calibration);
  };
  const Scene scene = parse(with(R"("calibration": {"training_seed": 3, "training_steps": 25})", workload));
  ASSERT_TRUE(scene.calibration);
  const WorkloadSpec& training = scene.calibration->training;
  ASSERT_EQ(training.groups.size(), 2u);
  for (std::size_t g = 0; g < 2; ++g) {
    EXPECT_EQ(training.groups[g].distance, scene.workload.groups[g].distance);
    ASSERT_EQ(training.groups[g].poses.size(), 25u);
    for (const RigidTransform& p : training.groups[g].poses) {
      EXPECT_EQ(p.translation, Vec3(training.groups[g].distance, 0, 0));
      EXPECT_NO_THROW(p.validate());
      for (const RigidTransform& q : scene.workload.groups[g].poses)  // held out: no test pose repeated
        EXPECT_FALSE(p.rotation == q.rotation) << "a training pose is a test pose";
    }
  }
  EXPECT_NE(training.identity, scene.workload.identity);
  const Scene other = parse(with(R"("calibration": {"training_seed": 4, "training_steps": 25})", workload));
  EXPECT_NE(other.calibration->training.groups[0].poses[0].rotation, training.groups[0].poses[0].rotation);
  EXPECT_NE(other.calibration->training.identity, training.identity);
  EXPECT_FALSE(parse(with(R"("name": "x")", workload)).calibration);

  const std::string random =
      R"("workload": {"type": "random", "count": 30, "seed": 5, "box": [[1, 0, 0], [2, 1, 1]]})";
  const Scene drawn = parse(with(R"("calibration": {"training_seed": 6, "training_steps": 40})", random));
  ASSERT_EQ(drawn.calibration->training.groups.size(), 1u);
  EXPECT_EQ(drawn.calibration->training.groups[0].poses.size(), 40u);
  EXPECT_NE(drawn.calibration->training.groups[0].poses[0].translation,
            drawn.workload.groups[0].poses[0].translation);

  const std::vector<std::pair<std::string, std::string>> bad = {
      {with(R"("calibration": {"training_seed": 5, "training_steps": 40})", random),
       "/calibration/training_seed: must differ from the workload's seed"},
      {with(R"("calibration": {"training_seed": 1})", workload), "/calibration/training_steps: missing"},
      {with(R"("calibration": {"training_seed": 1, "training_steps": 0})", workload),
       "/calibration/training_steps: expected an integer in [1, "},
      {with(R"("calibration": {"training_seed": 1, "training_steps": 5, "seed": 2})", workload),
       "/calibration/seed: unknown field"},
  };
  for (const auto& [text, expected] : bad)
    EXPECT_NE(error_of(text).find(expected), std::string::npos) << error_of(text);
  testing::write_text(dir / "poses.json", R"({"poses": [{"translation": [1, 0, 0]}]})");
  EXPECT_NE(error_of(with(R"("calibration": {"training_seed": 1, "training_steps": 5})",
                          R"("workload": {"type": "poses", "file": "poses.json"})"))
                .find("/calibration: needs a protocol or random workload"),
            std::string::npos);
}

TEST_F(SceneTest, AdbRunsOnEveryRegisteredVolume) {
  for (const std::string& bv : volume_names()) {
    const std::string text = scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": ")" + bv + R"("}])",
                                        R"([{"type": "adb", "p_min": 0.9}])");
    EXPECT_NO_THROW(parse(text)) << bv;
  }
}

TEST_F(SceneTest, PoseFileErrorsNameTheFileAndThePath) {
  testing::write_text(dir / "poses.json",
                      R"({"poses": [{"translation": [1, 0, 0]}, {"translation": [1, 0]}]})");
  const std::string message =
      error_of(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                          R"("workload": {"type": "poses", "file": "poses.json"})"));
  EXPECT_NE(message.find("/workload/file: "), std::string::npos) << message;
  EXPECT_NE(message.find("poses.json: /poses/1/translation: expected an array of 3 numbers"),
            std::string::npos)
      << message;
}

TEST_F(SceneTest, PoseFileGroupsByDistance) {
  testing::write_text(dir / "poses.json", R"({"poses": [
      {"translation": [1, 0, 0], "group": 1.0},
      {"translation": [0, 2, 0]},
      {"translation": [1, 0, 0.1], "axis_angle_deg": [0, 1, 0, 45], "group": 1.0},
      {"translation": [0, 0, 0], "rotation": [[0, -1, 0], [1, 0, 0], [0, 0, 1]], "group": 0.5}]})");
  const Scene scene =
      parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                       R"("workload": {"type": "poses", "file": "poses.json"})"));
  const auto& groups = scene.workload.groups;
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_DOUBLE_EQ(groups[0].distance, 0.5);
  EXPECT_DOUBLE_EQ(groups[1].distance, 1.0);
  EXPECT_EQ(groups[1].poses.size(), 2u);
  EXPECT_DOUBLE_EQ(groups[2].distance, 2.0);  // no group: the translation's length
  EXPECT_TRUE(
      groups[0].poses[0].rotation.isApprox(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()).toRotationMatrix()));
  EXPECT_NE(scene.workload.identity.find("poses:"), std::string::npos);
}

// Objects are in their mesh files' units unless the scene asks for the protocol normalisation; the tau of
// the LB table's first row (0: every cell with some area) is a value like any other.
TEST_F(SceneTest, ObjectsKeepTheirFilesUnitsUnlessNormalised) {
  const Scene raw = parse(scene_with());
  EXPECT_FALSE(raw.objects[0].normalize);
  const Scene normalised = parse(scene_with(R"([{"mesh": "torus.obj", "normalize": true}])"));
  EXPECT_TRUE(normalised.objects[0].normalize);
  const Scene tau0 = parse(scene_with(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])",
                                      R"([{"type": "adb"}])", R"("annotation": {"type": "adb", "tau": 0})"));
  EXPECT_EQ(tau0.density.label(), "adb grid=2 tau=0");
}

// The protocol's distances assume normalised objects: every shipped scene that runs the protocol asks for
// the normalisation on each object, explicitly (its results must not change with the default), but
// real_units.json, whose point is objects of different size in their files' own units.
TEST_F(SceneTest, ShippedProtocolScenesNormaliseEveryObject) {
  const char* source = std::getenv("BVHLAB_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "run through ctest, which sets BVHLAB_SOURCE_DIR";
  int protocol_scenes = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(source) / "bench" / "scenes")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "example_poses.json") continue;
    const Scene scene = load_scene(entry.path());
    if (scene.workload.kind != WorkloadSpec::Kind::Protocol || entry.path().filename() == "real_units.json")
      continue;
    ++protocol_scenes;
    for (const SceneObject& o : scene.objects) EXPECT_TRUE(o.normalize) << entry.path() << ": " << o.name;
  }
  EXPECT_GE(protocol_scenes, 4);
}

TEST_F(SceneTest, PoseListsTakeThreeSevenOrTwelveNumbersPerLine) {
  const auto poses = parse_pose_list(
      "# x y z [axis degrees] or [R | t]\n"
      "1 2 3\n"
      "\n"
      "  0.5,0,0, 0,0,1, 90\r\n"
      "0 -1 0 4  1 0 0 5  0 0 1 6\n",
      "p.txt");
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_EQ(poses[0].line, 2u);
  EXPECT_EQ(poses[0].pose.translation, Vec3(1, 2, 3));
  EXPECT_EQ(poses[0].pose.rotation, Mat3::Identity());
  EXPECT_EQ(poses[1].line, 4u);
  EXPECT_TRUE(poses[1].pose.apply(Vec3(1, 0, 0)).isApprox(Vec3(0.5, 1, 0), 1e-15));
  EXPECT_EQ(poses[2].line, 5u);
  EXPECT_EQ(poses[2].pose.translation, Vec3(4, 5, 6));
  EXPECT_EQ(poses[2].pose.apply(Vec3(1, 0, 0)), Vec3(4, 6, 6));  // R's first column is (0, 1, 0)
  // The same numbers as --pose gives them (pose_from_numbers is the one reader of both).
  const std::vector<double> seven{0.5, 0, 0, 0, 0, 1, 90};
  EXPECT_EQ(pose_from_numbers(seven).rotation, poses[1].pose.rotation);
}

TEST_F(SceneTest, MalformedPoseListLinesAreNamedByFileAndLine) {
  const std::pair<std::string, std::string> cases[] = {
      {"1 2 3\n1 2\n", "p.txt:2: expected 3 numbers (TX TY TZ), 7 (TX TY TZ AX AY AZ DEGREES) or 12"},
      {"1 2 x\n", "p.txt:1: 'x' is not a number"},
      {"1 2 3\n\n# c\n1 2 nan\n", "p.txt:4: expected finite numbers; got nan"},
      {"1 2 1e999\n", "p.txt:1: '1e999' is beyond the range of a double"},
      {"1 2 3 junk4\n", "p.txt:1: 'junk4' is not a number"},
      {"0 0 0 0 0 0 90\n", "p.txt:1: the rotation axis must be finite and not zero"},
      {"2 0 0 0 0 1 0 0 0 0 1 0\n", "p.txt:1: not a rotation"},
      {"-1 0 0 0 0 1 0 0 0 0 1 0\n", "p.txt:1: not a rotation"},
      {"# nothing\n\n", "p.txt: no pose"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      parse_pose_list(text, "p.txt");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(expected, 0), 0u) << e.what() << "\nexpected: " << expected;
    }
  }
  EXPECT_THROW(load_pose_list(dir / "absent.txt"), SceneError);
}

TEST_F(SceneTest, OptionalPartsAreSkippedWithANote) {
  const Scene scene =
      parse(scene_with(R"([{"mesh": "torus.obj"}, {"mesh": "absent.stl", "optional": true}])",
                       R"([{"bv": "aabb"}, {"bv": "not_a_volume", "optional": true}])",
                       R"([{"type": "exact"}, {"type": "exact", "hierarchies": ["not_a_volume"]}])", ""));
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_TRUE(scene.objects[1].path.empty());
  ASSERT_EQ(scene.hierarchies.size(), 1u);
  EXPECT_EQ(scene.strategies.size(), 1u);
  ASSERT_EQ(scene.notes.size(), 2u);
  EXPECT_NE(scene.notes[0].find("not_a_volume"), std::string::npos);
}

TEST_F(SceneTest, ShippedScenesParse) {
  const char* source = std::getenv("BVHLAB_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "run through ctest, which sets BVHLAB_SOURCE_DIR";
  int parsed = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(source) / "bench" / "scenes")) {
    if (entry.path().extension() != ".json" || entry.path().filename() == "example_poses.json") continue;
    EXPECT_NO_THROW(load_scene(entry.path())) << entry.path();
    ++parsed;
  }
  EXPECT_GE(parsed, 4);
}

}  // namespace
}  // namespace bvhlab
