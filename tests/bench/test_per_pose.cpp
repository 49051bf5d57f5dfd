// Per-pose output (run/report --per-pose): one record per query or per wrong answer, consistent with the
// aggregated rows, and a pose column that reads back into the very pose the run queried, with the same
// answer from the library.
#include "bench/core/scene.hpp"
#include "bench/pairs/plan.hpp"
#include "bench/pairs/write.hpp"
#include "bench/run.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <stdexcept>

namespace bvhlab {
namespace {

using testing::TempDir;

class PerPoseOutput : public ::testing::Test {
 protected:
  void SetUp() override {
    // A torus against a copy of itself: at these distances some poses collide and some do not, and ADB at a
    // low p_min (with a coarse annotation) answers some of them wrongly.
    testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
    options.cache_dir = dir / "cache";
    options.log = [](const std::string&) {};
    options.threads = 2;
    options.warmup_queries = 1;
    scene = parse_scene(R"({"name": "t", "objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
        "annotation": {"type": "adb", "grid": 2, "tau": 0.5},
        "strategies": [{"type": "exact"}, {"type": "adb", "p_min": [0.3, 0.9]},
                       {"type": "time_critical", "p_min": 0.9, "budgets": [{"bv_tests": 8}]}],
        "workload": {"distances": [0.8, 1.2, 1.6], "steps": 24}, "report": {"cgal_sample": 0}})",
                        dir.path(), "t.json");
  }

  RunOutput run(PerPose mode) {
    options.per_pose = mode;
    return run_scene(scene, options);
  }

  /// Column `name` of a CSV table's header.
  static std::size_t column(const std::vector<std::string>& header, const std::string& name) {
    const auto at = std::find(header.begin(), header.end(), name);
    EXPECT_NE(at, header.end()) << name;
    return static_cast<std::size_t>(at - header.begin());
  }

  TempDir dir;
  RunOptions options;
  Scene scene;
};

TEST_F(PerPoseOutput, ModesAreParsedByNameAndABadOneIsRefused) {
  EXPECT_EQ(parse_per_pose("none"), PerPose::none);
  EXPECT_EQ(parse_per_pose("all"), PerPose::all);
  EXPECT_EQ(parse_per_pose("wrong"), PerPose::wrong);
  try {
    (void)parse_per_pose("Wrong");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("got \"Wrong\""), std::string::npos) << e.what();
  }
}

TEST_F(PerPoseOutput, NothingIsKeptUnlessAsked) {
  const RunOutput out = run(PerPose::none);
  EXPECT_FALSE(out.rows.empty());
  EXPECT_TRUE(out.poses.empty());
  EXPECT_EQ(out.poses.capacity(), 0u);
}

// `all`: a row per series and pose, in results order, whose times and counters average to the aggregates.
TEST_F(PerPoseOutput, AllHasARowPerQueryThatAveragesToTheResults) {
  const RunOutput out = run(PerPose::all);
  write_results_csv(out, dir / "out" / "results.csv");
  write_poses_csv(out, dir / "out" / "poses.csv");
  const auto csv = testing::read_csv(dir / "out" / "poses.csv");
  ASSERT_FALSE(csv.empty());
  // The schema is a contract with users' scripts: spelled out here, not copied.
  const std::vector<std::string> header{"mesh",
                                        "hierarchy",
                                        "bv",
                                        "strategy",
                                        "label",
                                        "p_min",
                                        "budget",
                                        "distance",
                                        "pose_index",
                                        "pose",
                                        "truth",
                                        "answer",
                                        "false_positive",
                                        "false_negative",
                                        "probability",
                                        "exact",
                                        "budget_exhausted",
                                        "time_us",
                                        "bv_tests",
                                        "triangle_tests",
                                        "probability_evaluations",
                                        "nodes_visited"};
  ASSERT_EQ(csv[0], header);
  // 4 series (exact, adb at 2 p_min, time_critical) x 3 distances x 24 poses.
  ASSERT_EQ(csv.size(), 1u + 4 * 3 * 24);
  ASSERT_EQ(out.rows.size(), 4u * 3);
  std::map<std::string, double> time_sum, bv_sum;
  std::map<std::string, std::size_t> count;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    const auto& r = csv[i];
    ASSERT_EQ(r.size(), header.size()) << "row " << i;
    const std::string key = r[column(header, "label")] + "@" + r[column(header, "distance")];
    EXPECT_EQ(std::stoul(r[column(header, "pose_index")]), count[key]) << key;  // poses in order
    ++count[key];
    time_sum[key] += std::stod(r[column(header, "time_us")]);
    bv_sum[key] += std::stod(r[column(header, "bv_tests")]);
    const bool truth = r[column(header, "truth")] == "1", answer = r[column(header, "answer")] == "1";
    EXPECT_EQ(r[column(header, "false_positive")], answer && !truth ? "1" : "0");
    EXPECT_EQ(r[column(header, "false_negative")], !answer && truth ? "1" : "0");
    if (r[column(header, "strategy")] == "exact") {
      EXPECT_EQ(answer, truth) << "row " << i;
      EXPECT_EQ(r[column(header, "exact")], "1");
    }
  }
  for (const ResultRow& row : out.rows) {
    char distance[32];
    std::snprintf(distance, sizeof distance, "%.6g", row.distance);
    const std::string key = row.label + "@" + distance;
    ASSERT_EQ(count[key], row.queries) << key;
    EXPECT_NEAR(time_sum[key] / double(row.queries), row.mean_time_us, 1e-4 * row.mean_time_us + 1e-3) << key;
    EXPECT_NEAR(bv_sum[key] / double(row.queries), row.bv_tests_per_query, 1e-9) << key;
  }
}

// `wrong`: exactly the answers that differ from the truth, as many as results.csv's FP and FN rates count.
TEST_F(PerPoseOutput, WrongHasExactlyTheFalseAnswersOfTheResults) {
  const RunOutput out = run(PerPose::wrong);
  write_results_csv(out, dir / "out" / "results.csv");
  write_poses_csv(out, dir / "out" / "poses.csv");
  const auto results = testing::read_csv(dir / "out" / "results.csv");
  long expected = 0;
  for (std::size_t i = 1; i < results.size(); ++i) {
    const double queries = std::stod(results[i][column(results[0], "queries")]);
    expected += std::lround(std::stod(results[i][column(results[0], "fp_rate")]) * queries) +
                std::lround(std::stod(results[i][column(results[0], "fn_rate")]) * queries);
  }
  ASSERT_GT(expected, 0) << "the scene should make ADB err somewhere, or this test proves nothing";
  const auto poses = testing::read_csv(dir / "out" / "poses.csv");
  ASSERT_EQ(long(poses.size()) - 1, expected);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    EXPECT_NE(poses[i][column(poses[0], "answer")], poses[i][column(poses[0], "truth")]) << "row " << i;
    EXPECT_NE(poses[i][column(poses[0], "strategy")], "exact");
  }
}

// The pose column reads back (with the reader --pose uses) into the pose the run queried, bit for bit, and a
// query of the library at it gives the row's answer, probability and counters; the exact one its truth.
TEST_F(PerPoseOutput, PoseColumnRoundTripsThroughAQuery) {
  const RunOutput out = run(PerPose::all);
  write_poses_csv(out, dir / "out" / "poses.csv");
  const auto csv = testing::read_csv(dir / "out" / "poses.csv");
  const auto& header = csv[0];
  const RunPlan plan = plan_run(scene);
  ASSERT_EQ(plan.hierarchies.size(), 1u);
  const PlannedHierarchy& planned = plan.hierarchies[0];
  std::map<std::string, const StrategyVariant*> variants;
  for (const StrategyVariant& v : planned.variants) variants[v.label()] = &v;
  const SceneObject& torus = scene.objects[0];
  std::size_t checked = 0;
  for (std::size_t i = 1; i < csv.size(); i += 5) {  // every fifth row: each series, each distance
    const auto& r = csv[i];
    std::vector<double> numbers;
    std::stringstream in(r[column(header, "pose")]);
    for (std::string item; std::getline(in, item, ',');) numbers.push_back(std::stod(item));
    const RigidTransform pose = pose_from_numbers(numbers);
    const PoseRecord& record = out.poses[i - 1];
    const RigidTransform& queried = scene.workload.groups[record.group].poses[record.index];
    ASSERT_EQ(pose.rotation, queried.rotation) << "row " << i;
    ASSERT_EQ(pose.translation, queried.translation) << "row " << i;

    QueryRequest request{*planned.hierarchy, planned.density, *variants.at(r[column(header, "label")])};
    const Result answer = run_query(torus, torus, request, pose, options).answers.at(0).result;
    request.strategy = StrategyVariant{};  // exact
    const Result truth = run_query(torus, torus, request, pose, options).answers.at(0).result;
    EXPECT_EQ(answer.collides, r[column(header, "answer")] == "1") << "row " << i;
    EXPECT_EQ(truth.collides, r[column(header, "truth")] == "1") << "row " << i;
    EXPECT_NEAR(answer.probability, std::stod(r[column(header, "probability")]), 1e-5) << "row " << i;
    EXPECT_EQ(answer.counters.bv_tests, std::stoull(r[column(header, "bv_tests")])) << "row " << i;
    EXPECT_EQ(answer.counters.probability_evaluations,
              std::stoull(r[column(header, "probability_evaluations")]))
        << "row " << i;
    ++checked;
  }
  EXPECT_GT(checked, 50u);
}

}  // namespace
}  // namespace bvhlab
