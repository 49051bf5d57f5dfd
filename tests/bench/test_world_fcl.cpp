// FCL's side of a world run: on a crowded world of bundled meshes, FCL's managers and narrow phase find
// exactly the colliding pairs bvhlab's exact traversal finds, and CGAL finds, pair by pair in every frame;
// the runner's FCL rows count them so. And FCL's octrees of point clouds (bench/core/fcl_octree.hpp, what
// bench_points times): occupied voxels that overlap collide, clouds apart do not.
#include "bench/core/fcl_model.hpp"
#include "bench/core/fcl_octree.hpp"
#include "bench/core/ground_truth.hpp"
#include "bench/world/world.hpp"
#include "scene_fixtures.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace bvhlab {
namespace {

class WorldFclTest : public testing::SceneParsing {
 protected:
  WorldFclTest() : SceneParsing("world_fcl.json") {}
};

// A dozen instances of the bundled meshes (normalised to [-1, 1]^3) in a box where they keep touching.
const std::string kCrowd = R"({"objects": [{"mesh": "jeep1.ms3d", "name": "jeep", "normalize": true},
    {"mesh": "pinion.off", "name": "gear", "normalize": true},
    {"mesh": "teapot.obj", "name": "teapot", "normalize": true}],
  "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
  "world": {"instances": [{"object": "jeep", "count": 4}, {"object": "gear", "count": 4},
                          {"object": "teapot", "count": 4}],
            "region": {"min": [-2.5, -2.5, -2.5], "max": [2.5, 2.5, 2.5]},
            "motion": {"type": "random_walk", "frames": 4, "seed": 5, "step": 0.3, "turn_deg": 20},
            "scaling": [36]}})";

using PairSet = std::set<ObjectPair>;

TEST_F(WorldFclTest, FclsCollidingPairsAreBvhlabsAndCgalsInEveryFrame) {
  const Scene scene = parse(kCrowd);
  RunOptions options;
  options.log = [](const std::string&) {};
  options.warmup_queries = 0;
  const WorldOutput out = run_world(scene, options);  // throws when FCL and bvhlab disagree
  const WorldSpec& w = *scene.world;
  const std::size_t n = w.instances.size();

  std::map<std::string, Mesh> meshes;
  std::map<std::string, Bvh<Aabb>> trees;
  std::map<std::string, std::shared_ptr<fcl::CollisionGeometryd>> models;
  for (const auto& o : scene.objects) {
    meshes[o.name] = load_scene_object(o);
    trees.emplace(o.name, Bvh<Aabb>::build(meshes[o.name]));
    models[o.name] = make_fcl_model<fcl::OBBRSSd>(meshes[o.name]);
  }
  std::map<std::pair<std::string, std::string>, CgalGroundTruth> cgal;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> instance_models;
  for (const auto& instance : w.instances) instance_models.push_back(models[instance.object]);
  FclWorld fcl(instance_models);

  std::size_t colliding_seen = 0;
  for (int f = 0; f < w.frames; ++f) {
    const auto& poses = w.poses[static_cast<std::size_t>(f)];
    PairSet truth, ours;  // CGAL's and bvhlab's exact answer, over every pair of instances
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j) {
        const std::string &a = w.instances[i].object, &b = w.instances[j].object;
        auto it = cgal.find({a, b});
        if (it == cgal.end()) it = cgal.emplace(std::pair{a, b}, CgalGroundTruth(meshes[a], meshes[b])).first;
        const RigidTransform b_to_a = poses[i].inverse() * poses[j];
        if (it->second.collides(b_to_a)) truth.insert({i, j});
        if (query_exact(trees.at(a), trees.at(b), b_to_a).collides) ours.insert({i, j});
      }
    EXPECT_EQ(ours, truth) << "frame " << f;
    fcl.place(poses);
    for (std::size_t k = 0; k < FclWorld::kManagers.size(); ++k) {
      PairSet theirs;
      for (const ObjectPair& p : fcl.pairs(k))
        if (fcl.collides(p)) theirs.insert(p);
      EXPECT_EQ(theirs, truth) << FclWorld::kManagers[k] << ", frame " << f;
    }
    colliding_seen += truth.size();

    // The runner's rows of this frame: FCL's narrow phase counted against bvhlab's truth, and FCL's
    // candidates (boxes around each model's bounding sphere) never fewer than bvhlab's.
    std::size_t fcl_rows = 0, bvhlab_candidates = 0;
    for (const BroadPhaseRow& r : out.broad)
      if (r.frame == f && r.hierarchy != kFclWorldHierarchy) bvhlab_candidates = r.candidates;
    for (const BroadPhaseRow& r : out.broad) {
      if (r.frame != f || r.hierarchy != kFclWorldHierarchy) continue;
      ++fcl_rows;
      EXPECT_GE(r.candidates, bvhlab_candidates) << r.broad_phase << ", frame " << f;
      EXPECT_EQ(r.objects, n);
    }
    EXPECT_EQ(fcl_rows, FclWorld::kManagers.size()) << "frame " << f;
    for (const WorldSeriesRow& r : out.series) {
      if (r.frame != f) continue;
      EXPECT_EQ(r.colliding, truth.size()) << r.hierarchy << ", frame " << f;
      EXPECT_EQ(r.answered, truth.size()) << r.hierarchy << ", frame " << f;
      EXPECT_EQ(r.missed + r.false_pairs, 0u) << r.hierarchy << ", frame " << f;
    }
  }
  EXPECT_GT(colliding_seen, 2 * std::size_t(w.frames));  // crowded enough to compare something

  // The scaling rows: FCL's two managers beside bvhlab's broad phases on the same 36 copies and walk; both
  // managers see FCL's boxes, so they find the same number of candidates, never fewer than bvhlab's.
  std::map<std::string, std::size_t> fcl_candidates;
  std::size_t bvhlab_scaled = 0;
  for (const ScalingRow& r : out.scaling) {
    EXPECT_EQ(r.objects, 36u) << r.hierarchy << " " << r.broad_phase;
    if (r.hierarchy == kFclWorldHierarchy)
      fcl_candidates[r.broad_phase] = r.candidates;
    else
      bvhlab_scaled = r.candidates;
  }
  ASSERT_EQ(fcl_candidates.size(), FclWorld::kManagers.size());
  EXPECT_EQ(fcl_candidates.begin()->second, fcl_candidates.rbegin()->second);
  EXPECT_GE(fcl_candidates.begin()->second, bvhlab_scaled);
  EXPECT_GT(bvhlab_scaled, 0u);
  EXPECT_LT(colliding_seen, std::size_t(w.frames) * n * (n - 1) / 2);
}

TEST(FclWorld, PosesOfAnotherCountAndMissingModelsAreRefused) {
  EXPECT_THROW(FclWorld({nullptr}), std::invalid_argument);
  FclWorld empty({});
  const std::vector<RigidTransform> one(1);
  EXPECT_THROW(empty.place(one), std::invalid_argument);
}

// A square plate of (n + 1)^2 points in the plane z = 0, side 1, corner at the origin.
PointCloud plate(int n) {
  PointCloud cloud;
  cloud.name = "plate";
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) cloud.positions.emplace_back(double(i) / n, double(j) / n, 0.0);
  return cloud;
}

RigidTransform moved(const Vec3& translation, const Mat3& rotation = Mat3::Identity()) {
  RigidTransform t;
  t.rotation = rotation;
  t.translation = translation;
  return t;
}

TEST(FclOctree, OverlappingOccupiedVoxelsCollideAndCloudsApartDoNot) {
  const double res = 0.05;  // the plate's point spacing
  const auto octree = make_fcl_octree(plate(20), res);
  FclOctreePair pair(octree, octree);
  const Mat3 upright =
      Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix();  // the plate in y = 0
  EXPECT_TRUE(pair.collides(moved({0, 0, 0})));
  EXPECT_TRUE(pair.collides(moved({0.3, 0.5, 0}, upright)));  // crossing A along y = 0.5
  EXPECT_FALSE(pair.collides(moved({5, 0, 0})));
  EXPECT_FALSE(pair.collides(moved({0, 0, 2.5 * res})));  // parallel, one empty voxel between: unknown space
  EXPECT_FALSE(pair.collides(moved({1.5, 0.5, 0}, upright)));
}

TEST(FclOctree, OnlyNodesAtTheOccupancyThresholdCount) {
  const auto octree = make_fcl_octree(plate(20), 0.05);
  EXPECT_LT(octree->getOccupancyThres(), 0.97);  // the voxels' value, octomap's clamping maximum
  EXPECT_LT(octree->getFreeThres(), octree->getOccupancyThres());
  FclOctreePair pair(octree, octree);
  octree->setOccupancyThres(0.99);  // above every voxel: nothing is occupied, nothing collides
  EXPECT_FALSE(pair.collides(moved({0, 0, 0})));
}

TEST(FclOctree, BadResolutionsPointsOutOfRangeAndNullTreesAreRefused) {
  EXPECT_THROW(make_fcl_octree(plate(2), 0), std::invalid_argument);
  EXPECT_THROW(make_fcl_octree(plate(2), std::nan("")), std::invalid_argument);
  PointCloud far = plate(2);
  far.positions.emplace_back(1e9, 0, 0);
  EXPECT_THROW(make_fcl_octree(far, 0.01), std::invalid_argument);
  EXPECT_THROW(FclOctreePair(nullptr, make_fcl_octree(plate(2), 0.5)), std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab
