// World scenes: many instances over frames. The motion is deterministic and stays where it was told; every
// bad field (a missing pose, a pose that is no rotation, an option that does not apply) is refused by name.
#include "bench/core/ground_truth.hpp"
#include "bench/core/scene.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/world/motion.hpp"
#include "bench/world/world.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <map>
#include <set>

namespace bvhlab {
namespace {

using testing::TempDir;

class WorldTest : public testing::SceneParsing {
 protected:
  WorldTest() : SceneParsing("world.json") {}
  void SetUp() override {
    testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj");
    testing::write_obj(testing::make_torus(0.3, 0.1, 8, 6), dir / "ring.obj");
  }
};

const std::string kObjects = R"("objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}])";
const std::string kPlain =
    R"("hierarchies": [{"bv": "aabb"}, {"bv": "obb"}], "strategies": [{"type": "exact"}])";
// The frame budgets need a probability density on the hierarchies they run on.
const std::string kAnnotated =
    R"("hierarchies": [{"bv": "aabb", "annotation": {"type": "adb"}}, {"bv": "obb"}], "strategies": [{"type": "exact"}])";

std::string world_scene(const std::string& world, const std::string& extra = "",
                        const std::string& hierarchies = kPlain) {
  return "{" + kObjects + ", " + hierarchies + extra + R"(, "world": )" + world + "}";
}

const std::string kWalk =
    R"({"instances": [{"object": "torus", "count": 5}, {"object": "ring", "name": "lonely",
        "placement": {"translation": [1, 2, 3]}}],
        "region": {"min": [-10, -10, -10], "max": [10, 10, 10]},
        "motion": {"type": "random_walk", "frames": 40, "seed": 3, "step": 0.5, "turn_deg": 10}})";

TEST_F(WorldTest, RandomWalkStaysInItsRegionAndStepsNoFurtherThanAsked) {
  const Scene scene = parse(world_scene(kWalk));
  ASSERT_TRUE(scene.world);
  const WorldSpec& w = *scene.world;
  ASSERT_EQ(w.instances.size(), 6u);
  EXPECT_EQ(w.instances[0].name, "torus#0");
  EXPECT_EQ(w.instances[4].name, "torus#4");
  EXPECT_EQ(w.instances[5].name, "lonely");
  EXPECT_EQ(w.instances[5].object, "ring");
  ASSERT_EQ(w.poses.size(), 40u);
  EXPECT_EQ(w.poses[0][5].translation, Vec3(1, 2, 3));
  for (std::size_t f = 0; f < w.poses.size(); ++f) {
    ASSERT_EQ(w.poses[f].size(), 6u);
    for (std::size_t i = 0; i < 6; ++i) {
      const RigidTransform& p = w.poses[f][i];
      EXPECT_TRUE(w.region.contains(p.translation)) << f << " " << i;
      EXPECT_NEAR((p.rotation * p.rotation.transpose() - Mat3::Identity()).norm(), 0, 1e-12);
      EXPECT_NEAR(p.rotation.determinant(), 1, 1e-12);
      if (f == 0) continue;
      const RigidTransform& q = w.poses[f - 1][i];
      EXPECT_LE((p.translation - q.translation).cwiseAbs().maxCoeff(), 0.5 + 1e-12);
      EXPECT_GT((p.translation - q.translation).norm(), 0);
      // Three turns of at most 10 degrees each: at most 30 degrees in all.
      const double angle = Eigen::AngleAxisd(p.rotation * q.rotation.transpose()).angle();
      EXPECT_LE(angle, 30.0 * M_PI / 180 + 1e-9);
    }
  }
  EXPECT_EQ(w.broad_phases.size(), 3u);  // every registered one by default
}

TEST_F(WorldTest, TheSameSeedGivesTheSameFramesAndAnotherSeedOthers) {
  const auto a = parse(world_scene(kWalk)).world->poses;
  const auto b = parse(world_scene(kWalk)).world->poses;
  std::string other = kWalk;
  other.replace(other.find("\"seed\": 3"), 9, "\"seed\": 4");
  const auto c = parse(world_scene(other)).world->poses;
  EXPECT_EQ(a[39][2].translation, b[39][2].translation);
  EXPECT_EQ(a[39][2].rotation, b[39][2].rotation);
  EXPECT_NE(a[39][2].translation, c[39][2].translation);
}

TEST_F(WorldTest, InstancesOfAMissingOptionalObjectLeaveTheWorldWithANote) {
  const Scene scene = parse(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "gone.obj", "optional": true}],
      "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
      "world": {"instances": [{"object": "gone", "count": 2}, {"object": "torus", "count": 3}],
                "region": {"min": [0, 0, 0], "max": [5, 5, 5]}, "motion": {"type": "random_walk", "frames": 4}}})");
  ASSERT_EQ(scene.world->instances.size(), 3u);
  EXPECT_EQ(scene.world->instances[0].name, "torus#0");
  for (const auto& frame : scene.world->poses) EXPECT_EQ(frame.size(), 3u);
  ASSERT_EQ(scene.notes.size(), 1u);
  EXPECT_NE(scene.notes[0].find("instances of gone skipped"), std::string::npos);
  EXPECT_NE(error_of(R"({"objects": [{"mesh": "gone.obj", "optional": true}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "world": {"instances": [{"object": "gone"}],
      "region": {"min": [0, 0, 0], "max": [5, 5, 5]}, "motion": {"type": "random_walk", "frames": 4}}})")
                .find("/world/instances: no instance is left"),
            std::string::npos);
}

TEST(WorldMotion, ReflectionFoldsBackIntoTheRegion) {
  EXPECT_DOUBLE_EQ(reflect_into(0.5, 0, 1), 0.5);
  EXPECT_DOUBLE_EQ(reflect_into(1.25, 0, 1), 0.75);
  EXPECT_DOUBLE_EQ(reflect_into(-0.25, 0, 1), 0.25);
  EXPECT_DOUBLE_EQ(reflect_into(2.5, 0, 1), 0.5);
  EXPECT_DOUBLE_EQ(reflect_into(-3, -2, 2), -1);
}

TEST_F(WorldTest, AFrameFileGivesEveryInstanceItsPose) {
  testing::write_text(dir / "frames.json", R"({"frames": [
      {"a": {"translation": [0, 0, 0]}, "b": {"translation": [1, 0, 0], "axis_angle_deg": [0, 0, 1, 90]}},
      {"a": {"translation": [0, 1, 0]}, "b": {"translation": [2, 0, 0]}}]})");
  const Scene scene = parse(world_scene(R"({"instances": [{"object": "torus", "name": "a"},
      {"object": "ring", "name": "b"}], "motion": {"type": "frame_file", "file": "frames.json"}})"));
  ASSERT_EQ(scene.world->poses.size(), 2u);
  EXPECT_EQ(scene.world->poses[1][0].translation, Vec3(0, 1, 0));
  EXPECT_NEAR(scene.world->poses[0][1].rotation(1, 0), 1, 1e-12);
}

TEST_F(WorldTest, AFrameFileWithAMissingOrUnknownInstanceOrABadPoseIsRefused) {
  const std::string world =
      R"({"instances": [{"object": "torus", "name": "a"}, {"object": "ring", "name": "b"}],
      "motion": {"type": "frame_file", "file": "frames.json"}})";
  testing::write_text(dir / "frames.json", R"({"frames": [{"a": {}, "b": {}}, {"a": {}}]})");
  EXPECT_NE(error_of(world_scene(world)).find("/frames/1: no pose for instance \"b\""), std::string::npos);
  testing::write_text(dir / "frames.json", R"({"frames": [{"a": {}, "b": {}, "c": {}}]})");
  EXPECT_NE(error_of(world_scene(world)).find("/frames/0/c: no instance named \"c\""), std::string::npos);
  testing::write_text(dir / "frames.json",
                      R"({"frames": [{"a": {"rotation": [[2, 0, 0], [0, 1, 0], [0, 0, 1]]}, "b": {}}]})");
  EXPECT_NE(error_of(world_scene(world)).find("/frames/0/a/rotation: not a rotation"), std::string::npos);
  testing::write_text(dir / "frames.json", R"({"frames": [{"a": {"translation": [0, 0]}, "b": {}}]})");
  EXPECT_NE(error_of(world_scene(world)).find("/frames/0/a/translation: expected an array of 3 numbers"),
            std::string::npos);
  std::filesystem::remove(dir / "frames.json");
  EXPECT_NE(error_of(world_scene(world)).find("cannot read the frame file"), std::string::npos);
}

// The largest world the parser takes: its instances are numbered and checked for duplicates in one pass
// (a search of the instances read so far for each new one took minutes here), and a motion beyond a million
// poses is refused before any is drawn.
TEST_F(WorldTest, AHundredThousandInstancesAreReadInOnePass) {
  auto world = [](const std::string& instances, int frames) {
    return R"({"instances": )" + instances + R"(, "region": {"min": [0, 0, 0], "max": [100, 100, 100]},
        "motion": {"type": "random_walk", "frames": )" +
           std::to_string(frames) + "}}";
  };
  const std::string many = R"([{"object": "ring", "name": "first"}, {"object": "torus", "count": 99998},
      {"object": "ring"}])";
  const Scene scene = parse(world_scene(world(many, 1)));
  ASSERT_EQ(scene.world->instances.size(), 100000u);
  EXPECT_EQ(scene.world->instances[99998].name, "torus#99997");
  EXPECT_EQ(scene.world->instances[99999].name, "ring#1");
  EXPECT_NE(error_of(world_scene(world(many, 11))).find("/world/motion/frames: frames x instances is above"),
            std::string::npos);
  // The torus numbered 1 meets the ring named so first.
  const std::string clash = R"([{"object": "ring", "name": "torus#1"}, {"object": "torus", "count": 3}])";
  EXPECT_NE(
      error_of(world_scene(world(clash, 2))).find("/world/instances/1: duplicate instance name \"torus#1\""),
      std::string::npos);
  const std::string too_many = R"([{"object": "ring"}, {"object": "torus", "count": 100000}])";
  EXPECT_NE(error_of(world_scene(world(too_many, 2))).find("/world/instances/1: more than 100000 instances"),
            std::string::npos);
}

TEST_F(WorldTest, OptionsThatDoNotApplyAreRefusedByName) {
  auto expect = [&](const std::string& text, const std::string& message) {
    const std::string error = error_of(text);
    EXPECT_NE(error.find(message), std::string::npos) << error;
  };
  expect(world_scene(kWalk, R"(, "pairs": [["torus", "ring"]])"), "/pairs: does not apply to a world scene");
  expect(world_scene(kWalk, R"(, "workload": {"type": "protocol"})"), "/workload: does not apply");
  expect(world_scene(kWalk, "", kAnnotated), "/hierarchies/0/annotation: a density is set but no strategy");
  expect(world_scene(R"({"instances": [{"object": "teapot"}], "region": {"min": [0,0,0], "max": [1,1,1]},
      "motion": {"type": "random_walk", "frames": 2}})"),
         "/world/instances/0/object: no object named \"teapot\"; expected one of torus, ring");
  expect(world_scene(R"({"instances": [{"object": "torus", "count": 2, "name": "x"}],
      "region": {"min": [0,0,0], "max": [1,1,1]}, "motion": {"type": "random_walk", "frames": 2}})"),
         "/world/instances/0/count: \"name\" and \"placement\" describe one instance");
  expect(
      world_scene(R"({"instances": [{"object": "torus"}], "motion": {"type": "random_walk", "frames": 2}})"),
      "/world/region: missing");
  expect(world_scene(R"({"instances": [{"object": "torus"}], "region": {"min": [0,0,0], "max": [1,0,1]},
      "motion": {"type": "random_walk", "frames": 2}})"),
         "/world/region: expected \"min\" below \"max\" on every axis");
  expect(world_scene(R"({"instances": [{"object": "torus"}], "region": {"min": [0,0,0], "max": [1,1,1]},
      "motion": {"type": "frame_file", "file": "f.json"}})"),
         "/world/region: does not apply to a frame file");
  expect(world_scene(R"({"instances": [{"object": "torus"}], "region": {"min": [0,0,0], "max": [1,1,1]},
      "motion": {"type": "random_walk", "frames": 2}, "broad_phases": ["octree"]})"),
         "/world/broad_phases/0: expected one of brute_force, sweep_and_prune, dynamic_aabb_tree");
  // A world with one frame_budgets entry (equal_split at 100 BV tests) and `fields` added to it.
  const auto budget_entry = [](const std::string& fields, const std::string& hierarchies) {
    return world_scene(R"({"instances": [{"object": "torus"}], "region": {"min": [0,0,0], "max": [1,1,1]},
      "motion": {"type": "random_walk", "frames": 2},
      "frame_budgets": [{"schedules": ["equal_split"], "budgets": [{"bv_tests": 100}])" +
                           fields + "}]}",
                       "", hierarchies);
  };
  expect(budget_entry("", kPlain), "/world/frame_budgets/0: no hierarchy carries a probability density");
  expect(budget_entry(R"(, "hierarchies": ["obb"])", kAnnotated),
         "/world/frame_budgets/0/hierarchies/0: hierarchy \"obb\" carries no probability density");
  expect(world_scene(R"({"instances": [{"object": "torus"}], "region": {"min": [0,0,0], "max": [1,1,1]},
      "motion": {"type": "random_walk", "frames": 2},
      "frame_budgets": [{"schedules": ["greedy"], "budgets": [{"bv_tests": 100}], "hierarchies": ["aabb"]}]})",
                     "", kAnnotated),
         "/world/frame_budgets/0/schedules/0: expected one of adb_probability");
  expect(budget_entry(R"(, "confirm_levels": 256)", kAnnotated), "/world/frame_budgets/0/confirm_levels: ");
  expect(budget_entry(R"(, "confirm_levels": 1.5)", kAnnotated),
         "/world/frame_budgets/0/confirm_levels: expected an integer");
  expect(budget_entry(R"(, "memory": "yes")", kAnnotated),
         "/world/frame_budgets/0/memory: expected true or false");
  expect(budget_entry(R"(, "order": "sideways")", kAnnotated),
         "/world/frame_budgets/0/order: expected one of best_first, depth_first");
}

TEST_F(WorldTest, FrameBudgetsOnAHierarchyWithAProbabilityDensityAreKept) {
  const Scene scene = parse(world_scene(R"({"instances": [{"object": "torus", "count": 3}],
      "region": {"min": [0,0,0], "max": [4,4,4]}, "motion": {"type": "random_walk", "frames": 3},
      "broad_phases": ["sweep_and_prune"],
      "frame_budgets": [{"schedules": ["adb_probability", "equal_split"], "budgets": [{"bv_tests": 100},
                         {"deadline_us": 50}], "p_min": 0.8, "hierarchies": ["aabb"]}]})",
                                        "", kAnnotated));
  ASSERT_EQ(scene.world->frame_budgets.size(), 1u);
  const FrameBudgetSpec& fb = scene.world->frame_budgets[0];
  EXPECT_EQ(fb.schedules, (std::vector<std::string>{"adb_probability", "equal_split"}));
  ASSERT_EQ(fb.budgets.size(), 2u);
  EXPECT_EQ(fb.budgets[0].max_bv_tests, 100u);
  EXPECT_DOUBLE_EQ(fb.budgets[1].deadline_us, 50);
  EXPECT_DOUBLE_EQ(fb.p_min, 0.8);
  EXPECT_EQ(scene.world->broad_phases, std::vector<std::string>{"sweep_and_prune"});
  // Without a step, nothing moves; the frames still exist.
  EXPECT_EQ(scene.world->poses[2][1].translation, scene.world->poses[0][1].translation);
}

}  // namespace
}  // namespace bvhlab

namespace bvhlab {
namespace {

// A small world: two tori in a box where they keep bumping into each other.
std::string crowded_world(const std::string& hierarchies, const std::string& strategies,
                          const std::string& frame_budgets = "") {
  return R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}], "hierarchies": )" + hierarchies +
         R"(, "strategies": )" + strategies + R"(, "world": {"instances": [{"object": "torus", "count": 8},
         {"object": "ring", "count": 6}], "region": {"min": [-2, -2, -2], "max": [2, 2, 2]},
         "motion": {"type": "random_walk", "frames": 6, "seed": 11, "step": 0.3, "turn_deg": 20})" +
         frame_budgets + "}}";
}

/// Not one of FCL's rows (those a build with FCL adds to every world run).
template <class Row>
bool is_bvhlab_row(const Row& row) {
  return row.hierarchy != kFclWorldHierarchy;
}

RunOptions quiet_options() {
  RunOptions options;
  options.log = [](const std::string&) {};
  options.threads = 1;
  options.warmup_queries = 0;
  return options;
}

TEST_F(WorldTest, TheExactAnswerPerFrameAgreesWithCgalOnEveryPairOfInstances) {
  const Scene scene =
      parse(crowded_world(R"([{"bv": "aabb"}, {"bv": "obb"}, {"bv": "dop24"}])", R"([{"type": "exact"}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  const WorldSpec& w = *scene.world;
  std::map<std::string, Mesh> meshes;
  for (const auto& o : scene.objects) meshes[o.name] = load_scene_object(o);
  std::size_t checked_colliding = 0;
  for (int f = 0; f < w.frames; ++f) {
    std::size_t colliding = 0;  // CGAL over every pair of instances, candidates or not
    for (std::size_t i = 0; i < w.instances.size(); ++i)
      for (std::size_t j = i + 1; j < w.instances.size(); ++j) {
        const CgalGroundTruth truth(meshes[w.instances[i].object], meshes[w.instances[j].object]);
        const auto& poses = w.poses[static_cast<std::size_t>(f)];
        colliding += truth.collides(poses[i].inverse() * poses[j]);
      }
    checked_colliding += colliding;
    for (const WorldSeriesRow& row : out.series) {
      if (row.frame != f) continue;
      EXPECT_EQ(row.colliding, colliding) << row.hierarchy << " frame " << f;
      EXPECT_EQ(row.missed + row.false_pairs, 0u) << row.hierarchy << " frame " << f;
      EXPECT_EQ(row.answered, colliding);
    }
  }
  EXPECT_GT(checked_colliding, 0u);  // the world is crowded enough to test something
  // Three hierarchies over six frames, and FCL's narrow phase per frame where FCL is built.
  EXPECT_EQ(std::count_if(out.series.begin(), out.series.end(), is_bvhlab_row<WorldSeriesRow>), 3 * 6);
}

// A coherent strategy keeps each instance pair's state from frame to frame: the cold answers, with fewer BV
// tests where the objects move a little. The warm-up queries run on a copy of the state
// (PreparedQuery::time): with or without them, the timed queries do the same work.
TEST_F(WorldTest, CoherentQueriesCarryEachPairsStateAcrossFrames) {
  const Scene scene = parse(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}],
      "hierarchies": [{"bv": "aabb"}, {"bv": "obb"}],
      "strategies": [{"type": "exact"}, {"type": "exact", "coherent": true}],
      "world": {"instances": [{"object": "torus", "count": 8}, {"object": "ring", "count": 6}],
        "region": {"min": [-1.5, -1.5, -1.5], "max": [1.5, 1.5, 1.5]},
        "motion": {"type": "random_walk", "frames": 30, "seed": 5, "step": 0.01, "turn_deg": 0.5}}})");
  RunOptions options = quiet_options();
  options.per_pose = PerPose::all;
  const WorldOutput out = run_world(scene, options);
  options.warmup_queries = 1;
  std::map<std::string, std::uint64_t> tests, warmed_up;
  for (const WorldSeriesRow& row : run_world(scene, options).series)
    if (is_bvhlab_row(row)) warmed_up[row.hierarchy + " " + row.series] += row.bv_tests;

  std::size_t candidates = 0;
  for (const WorldSeriesRow& row : out.series) {
    if (!is_bvhlab_row(row)) continue;
    EXPECT_EQ(row.missed + row.false_pairs, 0u) << row.series << " frame " << row.frame;
    tests[row.hierarchy + " " + row.series] += row.bv_tests;
    candidates += row.candidates;
  }
  ASSERT_GT(candidates, 200u);  // enough persisting pairs to carry a state
  EXPECT_EQ(warmed_up, tests);
  for (const char* bv : {"aabb", "obb"}) {
    const std::uint64_t cold = tests[std::string(bv) + " exact"];
    const std::uint64_t coherent = tests[std::string(bv) + " exact coherent"];
    EXPECT_GT(coherent, 0u) << bv;
    EXPECT_LT(2 * coherent, cold) << bv;
  }
  // Pair by pair, the coherent answer is the cold one.
  std::map<std::tuple<int, std::string, std::string, std::string>, bool> cold;
  for (const WorldPairRow& r : out.pairs)
    if (r.series == "exact") cold[{r.frame, r.hierarchy, r.a, r.b}] = r.collides;
  std::size_t compared = 0;
  for (const WorldPairRow& r : out.pairs)
    if (r.series == "exact coherent") {
      EXPECT_EQ(r.collides, cold.at({r.frame, r.hierarchy, r.a, r.b}));
      ++compared;
    }
  EXPECT_EQ(compared, cold.size());
}

TEST_F(WorldTest, EveryBroadPhaseFindsTheSameCandidatesInEveryFrame) {
  const Scene scene = parse(crowded_world(R"([{"bv": "aabb"}, {"bv": "sphere"}])", R"([{"type": "exact"}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  // frames x hierarchies x broad phases (FCL's managers find FCL's own candidates: test_world_fcl.cpp)
  ASSERT_EQ(std::count_if(out.broad.begin(), out.broad.end(), is_bvhlab_row<BroadPhaseRow>), 6 * 2 * 3);
  std::map<std::pair<int, std::string>, std::set<std::size_t>> counts;
  for (const BroadPhaseRow& r : out.broad) {
    EXPECT_EQ(r.objects, 14u);
    if (!is_bvhlab_row(r)) continue;
    counts[{r.frame, r.hierarchy}].insert(r.candidates);
  }
  for (const auto& [key, values] : counts)
    EXPECT_EQ(values.size(), 1u) << key.second << " frame " << key.first;
}

TEST_F(WorldTest, AFrameBudgetOfOneTestFlagsItsPairsAndAGenerousOneDecidesThemAll) {
  const Scene scene =
      parse(crowded_world(R"([{"bv": "aabb", "annotation": {"type": "adb"}}])", R"([{"type": "exact"}])",
                          R"(, "frame_budgets": [{"schedules": ["adb_probability", "equal_split"],
          "budgets": [{"bv_tests": 1}, {"bv_tests": 10000000}]}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  std::size_t starved = 0, candidates = 0;
  for (const WorldSeriesRow& row : out.series) {
    if (row.schedule.empty()) continue;
    candidates += row.candidates;
    if (row.budget == "bv_tests=1") {
      EXPECT_LE(row.bv_tests, 1u);
      starved += row.flagged;
    } else {
      EXPECT_EQ(row.flagged, 0u) << row.series;
    }
  }
  EXPECT_GT(candidates, 0u);
  EXPECT_GT(starved, 0u);
}

// "The right tool": a budget below one test per candidate pair leaves pairs untested, and the run says which
// series, how many pairs, the budget that covers the round and the run's series that did; a budget that
// covers it gives no advice.
TEST_F(WorldTest, ABudgetBelowTheRootRoundIsNamedWithItsUntestedPairs) {
  const Scene scene =
      parse(crowded_world(R"([{"bv": "aabb", "annotation": {"type": "adb"}}])", R"([{"type": "exact"}])",
                          R"(, "frame_budgets": [{"schedules": ["adb_probability"],
          "budgets": [{"bv_tests": 1}, {"bv_tests": 10000000}]}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  std::size_t untested = 0, most = 0, untested_colliding = 0, candidates = 0;
  for (const WorldSeriesRow& row : out.series) {
    if (row.budget != "bv_tests=1") {
      EXPECT_EQ(row.untested, 0u) << row.series;
      continue;
    }
    EXPECT_EQ(row.untested, row.candidates - std::min<std::size_t>(row.candidates, 1)) << row.frame;
    untested += row.untested;
    candidates += row.candidates;
    untested_colliding += row.untested_colliding;
    most = std::max(most, row.candidates);
  }
  ASSERT_GT(most, 1u) << "the crowded world needs frames with two candidate pairs or more";
  ASSERT_EQ(out.advice.size(), 1u);
  const std::string& advice = out.advice.front();
  EXPECT_NE(advice.find("bv_tests=1 "), std::string::npos) << advice;
  EXPECT_NE(advice.find(fmt::format("{} of {} candidate pairs had no test", untested, candidates)),
            std::string::npos)
      << advice;
  EXPECT_NE(advice.find(fmt::format("({} of them collide in truth)", untested_colliding)), std::string::npos)
      << advice;
  EXPECT_NE(advice.find(fmt::format("at least {} BV tests", most)), std::string::npos) << advice;
  EXPECT_NE(
      advice.find("`frame adb_probability bv_tests=10000000 p_min=0.9`, which covered every root round"),
      std::string::npos)
      << advice;
  EXPECT_NE(world_readme(out).find("The right tool"), std::string::npos);
  EXPECT_EQ(world_document(out)["advice"].size(), 1u);
}

// A frame budget that never runs out answers every pair as ADB does on its own, with the same confirming
// generations: the scene's confirm_levels reaches every pair of the frame.
TEST_F(WorldTest, AGenerousFrameBudgetWithConfirmLevelsAnswersAsAdbWithThem) {
  const Scene scene = parse(crowded_world(
      R"([{"bv": "aabb", "annotation": {"type": "adb"}}])",
      R"([{"type": "adb", "p_min": 0.5, "confirm_levels": [0, 2]}])",
      R"(, "frame_budgets": [{"schedules": ["adb_probability", "round_robin"], "budgets": [{"bv_tests": 10000000}],
          "p_min": 0.5, "confirm_levels": 2}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  std::map<std::pair<int, std::string>, const WorldSeriesRow*> rows;
  for (const WorldSeriesRow& row : out.series) rows[{row.frame, row.series}] = &row;
  std::size_t compared = 0, changed = 0;
  for (const WorldSeriesRow& row : out.series) {
    if (row.schedule.empty()) continue;
    EXPECT_NE(row.schedule.find("confirm_levels=2"), std::string::npos) << row.schedule;
    const WorldSeriesRow& adb = *rows.at({row.frame, "adb p_min=0.5 confirm_levels=2"});
    const WorldSeriesRow& plain = *rows.at({row.frame, "adb p_min=0.5"});
    EXPECT_EQ(row.answered, adb.answered) << row.series << " frame " << row.frame;
    EXPECT_EQ(row.missed, adb.missed) << row.series << " frame " << row.frame;
    EXPECT_EQ(row.false_pairs, adb.false_pairs) << row.series << " frame " << row.frame;
    compared += row.candidates;
    changed += row.answered != plain.answered;
  }
  EXPECT_GT(compared, 0u);
  EXPECT_GT(changed,
            0u);  // the confirming generations change some answers here, so the match means something
}

// A depth-first schedule (the entry's "order") names itself so, and with a budget that never runs out each
// pair runs as adb_dfs with the same options, test for test; the best-first schedule spends other tests.
TEST_F(WorldTest, ADepthFirstScheduleAnswersAsAdbDfsTestForTest) {
  const Scene scene = parse(crowded_world(
      R"([{"bv": "aabb", "annotation": {"type": "adb"}}])",
      R"([{"type": "adb_dfs", "p_min": 0.9, "confirm_levels": 2}])",
      R"(, "frame_budgets": [{"schedules": ["adb_probability", "round_robin"], "budgets": [{"bv_tests": 10000000}],
          "p_min": 0.9, "confirm_levels": 2, "order": "depth_first"},
          {"schedules": ["adb_probability"], "budgets": [{"bv_tests": 10000000}], "p_min": 0.9, "confirm_levels": 2}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  std::map<std::pair<int, std::string>, const WorldSeriesRow*> rows;
  for (const WorldSeriesRow& row : out.series) rows[{row.frame, row.series}] = &row;
  std::size_t compared = 0;
  std::uint64_t depth_first_tests = 0, best_first_tests = 0;
  for (const WorldSeriesRow& row : out.series) {
    if (row.schedule.empty()) continue;
    if (row.schedule.find("depth_first") == std::string::npos) {
      best_first_tests += row.bv_tests;
      continue;
    }
    EXPECT_TRUE(row.schedule == "adb_probability depth_first confirm_levels=2" ||
                row.schedule == "round_robin depth_first confirm_levels=2")
        << row.schedule;
    const WorldSeriesRow& dfs = *rows.at({row.frame, "adb_dfs p_min=0.9 confirm_levels=2"});
    EXPECT_EQ(row.answered, dfs.answered) << row.series << " frame " << row.frame;
    EXPECT_EQ(row.false_pairs, dfs.false_pairs) << row.series << " frame " << row.frame;
    EXPECT_EQ(row.bv_tests, dfs.bv_tests) << row.series << " frame " << row.frame;
    if (row.schedule.starts_with("adb_probability")) depth_first_tests += row.bv_tests;
    compared += row.candidates;
  }
  EXPECT_GT(compared, 0u);
  EXPECT_NE(depth_first_tests, best_first_tests);
}

// A schedule with frame-to-frame fronts is a series of its own; its memory carries one frame to the next and
// saves tests on a slow walk (also under confirm_levels), and the warm-up run does not feed it (the timed run
// would recall the very frame it answers, and spend fewer tests with a warm-up than without).
TEST_F(WorldTest, AFrameMemoryCarriesFramesOnAndTheWarmUpDoesNotFeedIt) {
  const Scene scene = parse(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}],
      "hierarchies": [{"bv": "aabb", "annotation": {"type": "adb"}}], "strategies": [{"type": "exact"}],
      "world": {"instances": [{"object": "torus", "count": 8}, {"object": "ring", "count": 6}],
        "region": {"min": [-2, -2, -2], "max": [2, 2, 2]},
        "motion": {"type": "random_walk", "frames": 8, "seed": 11, "step": 0.02, "turn_deg": 1},
        "frame_budgets": [{"schedules": ["adb_probability"], "budgets": [{"bv_tests": 10000000}], "p_min": 0.99},
                          {"schedules": ["adb_probability"], "budgets": [{"bv_tests": 10000000}], "p_min": 0.99,
                           "memory": true},
                          {"schedules": ["adb_probability"], "budgets": [{"bv_tests": 10000000}], "p_min": 0.9,
                           "confirm_levels": 2, "order": "depth_first"},
                          {"schedules": ["adb_probability"], "budgets": [{"bv_tests": 10000000}], "p_min": 0.9,
                           "confirm_levels": 2, "order": "depth_first", "memory": true}]}})");
  RunOptions warm = quiet_options();
  warm.warmup_queries = 1;
  const WorldOutput cold = run_world(scene, quiet_options()), warmed = run_world(scene, warm);
  std::map<std::string, std::uint64_t> tests;
  for (const WorldSeriesRow& row : cold.series)
    if (!row.schedule.empty()) tests[row.schedule] += row.bv_tests;
  ASSERT_EQ(tests.size(), 4u);
  EXPECT_LT(tests.at("adb_probability memory"), tests.at("adb_probability"));
  EXPECT_LT(tests.at("adb_probability depth_first confirm_levels=2 memory"),
            tests.at("adb_probability depth_first confirm_levels=2"));
  for (std::size_t k = 0; k < cold.series.size(); ++k) {
    if (cold.series[k].schedule.empty()) continue;
    EXPECT_EQ(warmed.series[k].bv_tests, cold.series[k].bv_tests)
        << cold.series[k].series << " frame " << cold.series[k].frame;
  }
}

TEST_F(WorldTest, AnObjectWithoutTrianglesIsRefusedByName) {
  testing::write_text(dir / "flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  const Scene scene = parse(R"({"objects": [{"mesh": "flat.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "world": {"instances": [{"object": "flat", "count": 2}],
      "region": {"min": [0, 0, 0], "max": [1, 1, 1]}, "motion": {"type": "random_walk", "frames": 2}}})");
  try {
    run_world(scene, quiet_options());
    ADD_FAILURE() << "an object without triangles ran";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("flat.obj"), std::string::npos) << e.what();
  }
}

TEST_F(WorldTest, AWorldRunWritesItsTablesAndRefusesAPairScene) {
  const Scene scene = parse(crowded_world(R"([{"bv": "aabb"}])", R"([{"type": "exact"}])"));
  const WorldOutput out = run_world(scene, quiet_options());
  write_world_csv(out, dir / "out");
  const std::string frames = testing::read_text(dir / "out" / "world_frames.csv");
  EXPECT_EQ(std::count(frames.begin(), frames.end(), '\n'), 1 + std::ptrdiff_t(out.series.size()));
  EXPECT_EQ(std::count_if(out.series.begin(), out.series.end(), is_bvhlab_row<WorldSeriesRow>), 6);
  EXPECT_NE(world_readme(out).find("| aabb | exact |"), std::string::npos);
  Scene pairs = scene;
  pairs.world.reset();
  EXPECT_THROW(run_world(pairs, quiet_options()), std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab
