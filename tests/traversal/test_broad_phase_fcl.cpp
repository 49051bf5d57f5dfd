// bvhlab's colliding pairs among many objects (broad phase + exact narrow phase) equal FCL's (its dynamic
// AABB tree manager's collide with fcl::collide on every candidate), on FCL's broad-phase environment.
#include "bench/core/broad_phase_env.hpp"
#include "bench/core/fcl_model.hpp"
#include "traversal/broad_phase/registry.hpp"
#include "traversal/broad_phase/world_box.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision.h>
#include <gtest/gtest.h>

#include <set>

namespace bvhlab {
namespace {

struct FclCollect {
  std::set<ObjectPair> colliding;
  std::size_t candidates = 0;
};

bool fcl_exact(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  auto* out = static_cast<FclCollect*>(data);
  ++out->candidates;
  fcl::CollisionResultd result;
  fcl::collide(a, b, fcl::CollisionRequestd(1, false), result);
  if (result.isCollision()) {
    const auto ia = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(a->getUserData()));
    const auto ib = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(b->getUserData()));
    out->colliding.insert(ia < ib ? ObjectPair{ia, ib} : ObjectPair{ib, ia});
  }
  return false;
}

// Runs `frames` frames of FCL's motion; returns how many colliding pairs were seen in all.
std::size_t expect_same_collisions(std::size_t count, double extent, std::size_t frames) {
  const auto env = broad_phase_env::make_environment(count, extent, 7);
  const auto poses = broad_phase_env::make_frames(env, frames);
  std::vector<Bvh<Aabb>> trees;
  std::vector<BoundingBall> balls;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> models;
  for (const Mesh& mesh : env.shapes) {
    trees.push_back(Bvh<Aabb>::build(mesh));
    balls.push_back(bounding_ball(trees.back()));
    models.push_back(make_fcl_model<fcl::OBBRSSd>(mesh));
  }
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> pointers;
  for (std::size_t i = 0; i < env.poses.size(); ++i) {
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(models[env.shape_of[i]]));
    objects.back()->setUserData(reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
    pointers.push_back(objects.back().get());
  }
  fcl::DynamicAABBTreeCollisionManagerd manager;
  std::vector<std::unique_ptr<AnyBroadPhase>> phases;
  for (const auto& name : broad_phase_names()) phases.push_back(make_broad_phase(name));
  std::size_t total = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    const auto& frame = poses[f];
    std::vector<Box> boxes;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      boxes.push_back(world_box(trees[env.shape_of[i]], frame[i], balls[env.shape_of[i]]));
      fcl::Transform3d tf = fcl::Transform3d::Identity();
      tf.linear() = frame[i].rotation;
      tf.translation() = frame[i].translation;
      objects[i]->setTransform(tf);
      objects[i]->computeAABB();
    }
    if (f == 0) {
      manager.registerObjects(pointers);
      manager.setup();
    } else {
      manager.update();
    }
    FclCollect fcl_result;
    manager.collide(&fcl_result, fcl_exact);
    for (auto& phase : phases) {
      phase->update(boxes);
      std::set<ObjectPair> ours;
      for (const ObjectPair& p : phase->pairs()) {
        const RigidTransform b_to_a = frame[p.a].inverse() * frame[p.b];
        if (query_exact(trees[env.shape_of[p.a]], trees[env.shape_of[p.b]], b_to_a).collides) ours.insert(p);
      }
      EXPECT_EQ(ours, fcl_result.colliding) << phase->name() << ", frame " << f;
      // FCL's boxes (around each mesh's bounding sphere) are never tighter than bvhlab's.
      EXPECT_LE(phase->pairs().size(), fcl_result.candidates) << phase->name() << ", frame " << f;
    }
    total += fcl_result.colliding.size();
  }
  return total;
}

TEST(BroadPhaseFcl, CollidingPairsEqualFclOnItsEnvironment) {
  // FCL's n = 100 environment: 300 objects in [-2000, 2000]^3, few of them in contact.
  expect_same_collisions(300, 2000, 20);
}

TEST(BroadPhaseFcl, CollidingPairsEqualFclInACrowd) {
  // The same objects in a box 8 times narrower: many contacts, so the comparison has something to compare.
  EXPECT_GT(expect_same_collisions(300, 250, 10), 20u);
}

}  // namespace
}  // namespace bvhlab
