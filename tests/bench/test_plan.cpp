// The plan decides what a run loads, builds, annotates and runs: "only what the scene needs", tested here
// without building a tree.
#include "bench/pairs/plan.hpp"

#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

namespace bvhlab {
namespace {

class PlanTest : public ::testing::Test {
 protected:
  void SetUp() override { testing::write_obj(testing::make_torus(0.7, 0.25, 12, 6), dir / "torus.obj"); }
  Scene parse(const std::string& objects, const std::string& hierarchies, const std::string& strategies,
              const std::string& extra = "") {
    const std::string text = R"({"objects": )" + objects + R"(, "hierarchies": )" + hierarchies +
                             R"(, "strategies": )" + strategies +
                             R"(, "workload": {"distances": [0.8, 1.6], "steps": 10})" +
                             (extra.empty() ? "" : ", " + extra) + "}";
    return parse_scene(text, dir.path(), "plan.json");
  }
  testing::TempDir dir;
};

TEST_F(PlanTest, OnlyHierarchiesWhoseStrategiesNeedTheDensityAreAnnotated) {
  const Scene scene =
      parse(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}, {"bv": "dop24"}, {"bv": "obb"}])",
            R"([{"type": "exact", "hierarchies": ["aabb", "dop24"]},
                                {"type": "adb", "p_min": [0.5, 0.9], "hierarchies": ["aabb"]}])",
            R"("annotation": {"type": "adb", "grid": 3})");
  const RunPlan plan = plan_run(scene);
  ASSERT_EQ(plan.hierarchies.size(), 2u);  // obb runs nothing: neither built nor listed
  EXPECT_EQ(plan.hierarchies[0].hierarchy->name, "aabb");
  EXPECT_EQ(plan.hierarchies[0].density.label(), "adb grid=3 tau=0.25");
  EXPECT_EQ(plan.hierarchies[1].hierarchy->name, "dop24");
  EXPECT_EQ(plan.hierarchies[1].density.name, "none");
  EXPECT_EQ(plan.trees_to_annotate_per_object(), 1u);
  ASSERT_EQ(plan.hierarchies[0].variants.size(), 3u);  // exact, adb 0.5, adb 0.9
  EXPECT_EQ(plan.hierarchies[0].variants[2].label(), "adb p_min=0.9");
  // 1 pair x (3 + 1 series) x 2 distances x 10 poses.
  EXPECT_EQ(plan.total_queries, 4u * 2u * 10u);
}

TEST_F(PlanTest, AnExactOnlySceneAnnotatesNothing) {
  const Scene scene = parse(R"([{"mesh": "torus.obj"}])", R"([{"bv": "aabb"}])", R"([{"type": "exact"}])");
  const RunPlan plan = plan_run(scene);
  ASSERT_EQ(plan.hierarchies.size(), 1u);
  EXPECT_EQ(plan.trees_to_annotate_per_object(), 0u);
}

TEST_F(PlanTest, PairsWithAMissingOptionalMeshAreLeftOutOnce) {
  const Scene scene = parse(R"([{"mesh": "torus.obj"}, {"mesh": "absent.obj", "optional": true}])",
                            R"([{"bv": "aabb"}])", R"([{"type": "exact"}])",
                            R"("pairs": [["torus", "torus"], ["torus", "absent"], ["absent", "absent"]])");
  const RunPlan plan = plan_run(scene);
  ASSERT_EQ(plan.pairs.size(), 1u);
  EXPECT_EQ(plan.pairs[0]->label(), "torus");
  ASSERT_EQ(plan.skipped.size(), 1u);
  EXPECT_NE(plan.skipped[0].find("object absent skipped"), std::string::npos) << plan.skipped[0];
  EXPECT_EQ(plan.total_queries, 2u * 10u);
}

}  // namespace
}  // namespace bvhlab
