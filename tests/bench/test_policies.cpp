// The test-only density and strategy (tests/support/test_density.hpp, test_strategy.hpp) through the whole
// bench: they are added by their header and one registry line each, and this binary is built with
// BVHLAB_TEST_POLICIES. Everything below reaches them by name only: the tables, a scene, the runner, saved
// trees and the report.
#include "bench/pairs/report.hpp"
#include "bench/run.hpp"
#include "engine/policies.hpp"
#include "scene_fixtures.hpp"
#include "support/errors.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace bvhlab {
namespace {

class TestPolicies : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
    options.log = [](const std::string&) {};
    options.threads = 2;
    options.warmup_queries = 1;
  }
  testing::TempDir dir;
  RunOptions options;
};

TEST_F(TestPolicies, TheTablesListThemWithTheirParameters) {
  const DensityInfo& density = density_info("tricount");
  ASSERT_EQ(density.parameters.size(), 1u);
  EXPECT_EQ(density.parameters[0].name, "cap");
  const StrategyInfo& strategy = strategy_info("root_overlap");
  EXPECT_FALSE(strategy.exact);
  EXPECT_FALSE(strategy.needs_polygons);
  EXPECT_TRUE(strategy.accepts("tricount"));
  // Without a query_coherent of its own, it does not run coherent, and says so wherever it is asked to.
  EXPECT_FALSE(strategy.coherent);
  const std::string refusal = "strategy root_overlap does not run coherent (the strategies that do: exact, ";
  EXPECT_EQ(strategy.coherent_refusal().rfind(refusal, 0), 0u) << strategy.coherent_refusal();
  const std::string scene = R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "root_overlap", "coherent": true}]})";
  EXPECT_NE(testing::error_of([&] {
              (void)parse_scene(scene, dir.path(), "c.json");
            }).find("c.json: /strategies/0/coherent: " + refusal),
            std::string::npos);
  // The shipped ADB strategy runs on the new density: it is a ProbabilityDensity.
  EXPECT_TRUE(strategy_info("adb").accepts("tricount"));
  EXPECT_TRUE(strategy_info("guided_exact").accepts("tricount"));
}

TEST_F(TestPolicies, ASceneRunsAndReportsThem) {
  const Scene scene = parse_scene(R"({"name": "policies", "objects": [{"mesh": "torus.obj"}],
      "hierarchies": [{"bv": "aabb"}, {"bv": "aabb", "name": "aabb_wide", "max_leaf_triangles": 8}],
      "annotation": {"type": "tricount", "cap": 4},
      "strategies": [{"type": "exact"}, {"type": "root_overlap"}, {"type": "adb", "p_min": [0.5, 0.9]},
                     {"type": "guided_exact", "hierarchies": ["aabb_wide"]}],
      "workload": {"distances": [0.8, 1.6, 3.5], "steps": 16}, "report": {"cgal_sample": 4}})",
                                  dir.path(), "policies.json");
  EXPECT_EQ(scene.report.operating_strategy, "adb");
  const RunOutput run = run_scene(scene, options);
  std::size_t root_rows = 0, adb_rows = 0;
  for (const ResultRow& r : run.rows) {
    if (r.strategy == "root_overlap") {
      ++root_rows;
      EXPECT_FALSE(r.exact_strategy);
      EXPECT_EQ(r.label, "root_overlap");
      EXPECT_EQ(r.fn_rate, 0.0);  // overlapping roots never miss a contact
      EXPECT_EQ(r.bv_tests_per_query, 1.0);
    }
    if (r.strategy == "adb") {
      ++adb_rows;
      EXPECT_EQ(r.annotation, "tricount cap=4");
    }
    if (r.strategy == "exact" || r.strategy == "guided_exact") {
      EXPECT_EQ(r.fp_rate, 0.0) << r.hierarchy << " " << r.label;
      EXPECT_EQ(r.fn_rate, 0.0) << r.hierarchy << " " << r.label;
    }
  }
  EXPECT_EQ(root_rows, 2u * 3u);
  EXPECT_EQ(adb_rows, 2u * 2u * 3u);
  EXPECT_EQ(run.stats.trees_annotated, 2u);
  // At d = 3.5 even rotated root boxes of the tori (outer radius 0.95) are apart: the root test says so.
  for (const ResultRow& r : run.rows) {
    if (r.strategy == "root_overlap" && r.distance == 3.5) {
      EXPECT_EQ(r.answer_colliding_rate, 0.0);
    }
  }

  ReportOptions report_options;
  report_options.figures = false;
  const ReportFiles files = write_report(run, dir / "report", report_options);
  const std::string readme = testing::read_text(files.readme);
  EXPECT_NE(readme.find("root_overlap"), std::string::npos);
  EXPECT_NE(readme.find("adb p_min=0.9"), std::string::npos);
  EXPECT_NE(readme.find("tricount cap=4"), std::string::npos);
}

TEST_F(TestPolicies, SavedTreesKeepTheDensityByName) {
  const SceneObject torus = testing::object_from(dir / "torus.obj");
  const HierarchySpec aabb = testing::hierarchy_of("aabb");
  const DensitySpec density{"tricount", {{"cap", 5}}};
  build_tree_file(torus, aabb, density, dir / "torus.tree", 1);
  const SavedTreeInfo info = peek_saved_tree(dir / "torus.tree");
  EXPECT_EQ(info.density, "tricount");
  EXPECT_EQ(info.annotation, "tricount cap=5");
  StrategyVariant root{"root_overlap", {}, {}};
  EXPECT_TRUE(run_query_on_trees(dir / "torus.tree", dir / "torus.tree", root, RigidTransform{})
                  .answers[0]
                  .result.collides);
  StrategyVariant adb{"adb", {{"p_min", 0.5}}, {}};
  const QueryOutcome q = run_query_on_trees(dir / "torus.tree", dir / "torus.tree", adb, RigidTransform{});
  EXPECT_GT(q.answers[0].result.counters.probability_evaluations, 0u);
  EXPECT_EQ(q.model_a.annotation, "tricount cap=5");
}

}  // namespace
}  // namespace bvhlab
