// The deform scene: its section is parsed with every refusal named, and its runner's answers hold against
// CGAL on the deformed meshes; exact strategies stay exact on refitted trees of every volume, and the
// exact recount of the density matches, while stale counts drift.
#include "adb/update.hpp"
#include "bench/core/ground_truth.hpp"
#include "bench/deform/deform.hpp"
#include "bvh/deform.hpp"
#include "bvh/mesh_io.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <map>

namespace bvhlab {
namespace {

class DeformSceneTest : public testing::SceneParsing {
 protected:
  DeformSceneTest() : SceneParsing("deform.json") {}
  void SetUp() override {
    testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj");
    testing::write_obj(testing::make_torus(0.3, 0.1, 8, 6), dir / "ring.obj");
  }
};

const std::string kHead = R"("objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}],
  "hierarchies": [{"bv": "aabb"}, {"bv": "obb"}, {"bv": "rbox"}, {"bv": "dop24"}],
  "annotation": {"type": "adb"},
  "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.9, "hierarchies": ["aabb"]}])";
const std::string kPoses = R"("poses": {"distances": [1.2, 1.8], "steps": 8})";

std::string deform_scene(const std::string& deform, const std::string& head = kHead) {
  return "{" + head + R"(, "deform": )" + deform + "}";
}

std::string twist(const std::string& extra = "") {
  return R"({"object": "torus", "deformation": "twist:amplitude=2", "frames": 3, )" + kPoses + extra + "}";
}

TEST_F(DeformSceneTest, TheSectionIsReadWithItsDefaults) {
  const Scene scene = parse(deform_scene(twist()));
  ASSERT_TRUE(scene.deform);
  EXPECT_EQ(scene.deform->object, "torus");
  EXPECT_EQ(scene.deform->other, "torus");
  EXPECT_EQ(scene.deform->frames, 3);
  EXPECT_EQ(scene.deform->poses.size(), 2u);
  EXPECT_FALSE(scene.deform->refit_by_fit);
  std::vector<std::string> updates;
  for (const auto& u : scene.deform->density_updates) updates.push_back(u.name);
  EXPECT_EQ(updates, density_update_names());
}

TEST_F(DeformSceneTest, RefusalsNameTheField) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {deform_scene(R"({"object": "cube", "deformation": "twist", "frames": 2, )" + kPoses + "}"),
       "/deform/object"},
      {deform_scene(R"({"object": "torus", "deformation": "twirl", "frames": 2, )" + kPoses + "}"),
       "/deform/deformation"},
      {deform_scene(R"({"object": "torus", "frames": 2, )" + kPoses + "}"), "either \"deformation\""},
      {deform_scene(R"({"object": "torus", "frame_files": ["nowhere.obj"], )" + kPoses + "}"),
       "no such file"},
      {deform_scene(twist(R"(, "density_updates": [{"type": "recount_moved", "fraction": -1}])")),
       "/deform/density_updates/0"},
      {deform_scene(twist(R"(, "density_updates": [{"type": "guess"}])")), "/deform/density_updates/0/type"},
      {deform_scene(twist(R"(, "refit": "sometimes")")), "/deform/refit"},
      {deform_scene(
           R"({"object": "torus", "deformation": "twist", "frames": 2,)"
           R"( "poses": {"distances": [1, 1.5, 2, 2.5, 3, 3.5, 4, 4.5, 5, 5.5, 6], "steps": 100000}})"),
       "/deform/poses: 11 distances of 100000 steps make 1100000 poses; a scene generates at most 1000000"},
      {"{" + kHead + R"(, "pairs": [["torus", "torus"]], "deform": )" + twist() + "}", "/pairs"},
      {deform_scene(twist(), R"("objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
          "annotation": {"type": "adb_paper"}, "strategies": [{"type": "adb"}])"),
       "updates the density \"adb\" only"},
  };
  for (const auto& [text, expected] : cases)
    EXPECT_NE(error_of(text).find(expected), std::string::npos) << text;
}

// The runner's truth per frame is the exact traversal on the deformed mesh: checked here against CGAL.
TEST_F(DeformSceneTest, AnswersHoldAgainstCgalOnTheDeformedMeshes) {
  const Scene scene = parse(deform_scene(twist()));
  const DeformOutput out = run_deform(scene, RunOptions{});
  ASSERT_EQ(out.frames, 3);
  const Mesh rest = load_mesh(dir / "torus.obj").mesh;
  const Deformation d = parse_deformation(scene.deform->deformation);
  std::vector<RigidTransform> poses;
  for (const auto& g : scene.deform->poses) poses.insert(poses.end(), g.poses.begin(), g.poses.end());
  std::vector<std::size_t> colliding(4, 0);
  for (int f = 1; f <= 3; ++f) {
    const CgalGroundTruth truth(deform(rest, d, frame_time(f, 4)), rest);
    for (const auto& pose : poses) colliding[f] += truth.collides(pose);
  }
  std::set<std::string> seen;
  for (const DeformRow& r : out.rows) {
    EXPECT_EQ(r.colliding, colliding[r.frame]) << r.hierarchy << " " << r.update << " frame " << r.frame;
    EXPECT_EQ(r.queries, poses.size());
    if (r.exact_strategy) {
      EXPECT_EQ(r.missed + r.false_pairs, 0u) << r.hierarchy << " " << r.update << " frame " << r.frame;
      seen.insert(r.hierarchy + " " + r.update);
    }
  }
  EXPECT_EQ(seen.size(), 8u);  // four volumes, refitted and rebuilt
  EXPECT_GT(colliding[1] + colliding[2] + colliding[3], 0u);
  EXPECT_LT(colliding[1] + colliding[2] + colliding[3], 3 * poses.size());
}

TEST_F(DeformSceneTest, TheExactRecountMatchesAndStaleCountsDrift) {
  const DeformOutput out = run_deform(parse(deform_scene(twist())), RunOptions{});
  double stale_error = 0;
  for (const DeformRow& r : out.rows) {
    if (r.update == "refit + recount_all") {
      EXPECT_EQ(r.count_error, 0) << "frame " << r.frame;
    }
    if (r.update == "refit + stale") stale_error += r.count_error;
  }
  EXPECT_GT(stale_error, 0);
}

TEST_F(DeformSceneTest, FrameFilesOfAnotherTopologyAreRefusedByName) {
  const Mesh torus = testing::make_torus(0.7, 0.25, 12, 8);
  testing::write_obj(torus, dir / "f0.obj");
  testing::write_obj(deform(torus, parse_deformation("bend"), 0.25), dir / "f1.obj");
  testing::write_obj(testing::make_torus(0.7, 0.25, 10, 8), dir / "f2.obj");
  const std::string files =
      R"({"object": "torus", "frame_files": ["f0.obj", "f1.obj", "f2.obj"], )" + kPoses + "}";
  const Scene scene = parse(deform_scene(files));
  EXPECT_EQ(scene.deform->frames, 3);
  try {
    (void)run_deform(scene, RunOptions{});
    FAIL() << "a frame of another topology was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("f2.obj"), std::string::npos) << e.what();
  }
}

// A coherent series keeps each pose's state across the refitted frames: the exact answers, with fewer BV
// tests than the cold series from the second frame on; on the trees built anew, the exact answers too.
TEST_F(DeformSceneTest, CoherentSeriesFollowEachPoseAcrossFrames) {
  const std::string head = R"("objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}],
    "hierarchies": [{"bv": "aabb"}, {"bv": "obb"}],
    "strategies": [{"type": "exact"}, {"type": "exact", "coherent": true}])";
  const std::string slow_twist = R"({"object": "torus", "other": "ring", "deformation": "twist:amplitude=0.3",
    "frames": 12, "poses": {"distances": [1.2, 1.4], "steps": 16}})";
  const DeformOutput out = run_deform(parse(deform_scene(slow_twist, head)), RunOptions{});
  std::map<std::string, std::uint64_t> tests;  // hierarchy, update, series: BV tests after the first frame
  std::size_t colliding = 0;
  for (const DeformRow& r : out.rows) {
    EXPECT_EQ(r.missed + r.false_pairs, 0u) << r.hierarchy << " " << r.update << " " << r.series;
    if (r.frame > 1) tests[r.hierarchy + " " + r.update + " " + r.series] += r.bv_tests;
    colliding += r.colliding;
  }
  EXPECT_GT(colliding, 0u);
  EXPECT_LT(colliding, out.rows.size() * out.poses) << "some poses apart";
  for (const std::string bv : {"aabb", "obb"})
    EXPECT_LT(tests[bv + " refit exact coherent"], tests[bv + " refit exact"]) << bv;
}

}  // namespace
}  // namespace bvhlab
