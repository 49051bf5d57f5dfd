// Refit side by side with FCL: its update-and-refit (beginUpdateModel / updateSubModel / endUpdateModel)
// on the same frames and poses gives the same exact answers as bvhlab's refitted trees and CGAL.
#include "bench/core/fcl_model.hpp"
#include "bench/core/ground_truth.hpp"
#include "bvh/deform.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"
#include "volumes/dop24.hpp"
#include "volumes/obb.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>

namespace bvhlab {
namespace {

template <class BV, class FclBV>
void compare_over_frames(const Mesh& rest, const char* spec) {
  const Mesh b = testing::make_torus(0.45, 0.12, 12, 6);
  const Deformation d = parse_deformation(spec);
  auto tree = Bvh<BV>::build(rest);
  const auto tree_b = Bvh<BV>::build(b);
  auto model = make_fcl_model<FclBV>(rest);
  const auto model_b = make_fcl_model<FclBV>(b);
  std::mt19937_64 rng(17);
  int colliding = 0, queries = 0;
  for (int f = 1; f < 6; ++f) {
    const Mesh frame = deform(rest, d, frame_time(f, 6));
    tree.refit(frame);
    ASSERT_EQ(model->beginUpdateModel(), fcl::BVH_OK);
    ASSERT_EQ(model->updateSubModel(fcl_points(frame)), fcl::BVH_OK);
    ASSERT_EQ(model->endUpdateModel(true, true), fcl::BVH_OK);
    const CgalGroundTruth truth(frame, b);
    for (int k = 0; k < 20; ++k) {
      RigidTransform pose = testing::random_pose(rng, 0.9);
      pose.translation += rest.bounds().center();
      const bool expected = truth.collides(pose);
      ASSERT_EQ(query_exact(tree, tree_b, pose).collides, expected)
          << spec << " frame " << f << " pose " << k;
      ASSERT_EQ(fcl_collides(*model, *model_b, pose), expected) << spec << " frame " << f << " pose " << k;
      colliding += expected;
      ++queries;
    }
  }
  EXPECT_GT(colliding, queries / 10) << spec;
  EXPECT_LT(colliding, queries * 9 / 10) << spec;
}

template <class BV, class FclBV>
void compare_all() {
  for (const char* spec :
       {"twist:amplitude=3", "wave:amplitude=0.15,wavelength=0.3", "pulsate:amplitude=0.5"}) {
    compare_over_frames<BV, FclBV>(cloth_grid(12), spec);
    compare_over_frames<BV, FclBV>(testing::make_torus(0.7, 0.25, 18, 9), spec);
  }
}

TEST(RefitFcl, AabbAnswersEqualFclUpdateAndRefit) {
  compare_all<Aabb, fcl::AABBd>();
}
TEST(RefitFcl, ObbAnswersEqualFclUpdateAndRefit) {
  compare_all<Obb, fcl::OBBd>();
}
TEST(RefitFcl, Dop24AnswersEqualFclKdop24UpdateAndRefit) {
  compare_all<Dop24, fcl::KDOPd<24>>();
}

}  // namespace
}  // namespace bvhlab
