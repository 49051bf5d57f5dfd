// FCL's side of the benchmarks and tests: a BVHModel built from a bvhlab Mesh, a pose as an FCL transform,
// FCL's first-contact answer and distance, and FCL's broad-phase managers over the instances of a world
// scene. The one place the bench and the tests hand a mesh to the peer. Include only where FCL is found
// (BVHLAB_HAVE_FCL, or a target that links fcl).
#pragma once

#include "../../bvh/mesh.hpp"
#include "../../traversal/broad_phase/broad_phase.hpp"

#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

/// The mesh's vertices as FCL points (updateSubModel takes them in this form).
inline std::vector<fcl::Vector3d> fcl_points(const Mesh& mesh) {
  return {mesh.vertices.begin(), mesh.vertices.end()};
}

inline std::vector<fcl::Triangle> fcl_triangles(const Mesh& mesh) {
  std::vector<fcl::Triangle> out;
  out.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) out.emplace_back(t[0], t[1], t[2]);
  return out;
}

/// A built FCL model (FCL's default split rule for the BV), with its local AABB computed so that it can also
/// stand in a broad-phase manager. Throws std::runtime_error when FCL refuses the mesh.
template <class FclBV>
std::shared_ptr<fcl::BVHModel<FclBV>> make_fcl_model(const std::vector<fcl::Vector3d>& points,
                                                     const std::vector<fcl::Triangle>& triangles) {
  auto model = std::make_shared<fcl::BVHModel<FclBV>>();
  if (model->beginModel() != fcl::BVH_OK || model->addSubModel(points, triangles) != fcl::BVH_OK ||
      model->endModel() != fcl::BVH_OK)
    throw std::runtime_error("FCL refused to build a model of " + std::to_string(triangles.size()) +
                             " triangles");
  model->computeLocalAABB();
  return model;
}
template <class FclBV>
std::shared_ptr<fcl::BVHModel<FclBV>> make_fcl_model(const Mesh& mesh) {
  return make_fcl_model<FclBV>(fcl_points(mesh), fcl_triangles(mesh));
}

inline fcl::Transform3d fcl_transform(const RigidTransform& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.rotation;
  tf.translation() = pose.translation;
  return tf;
}

/// FCL's first-contact answer for B placed in A's frame by `b_to_a`.
template <class FclBV>
bool fcl_collides(const fcl::BVHModel<FclBV>& a, const fcl::BVHModel<FclBV>& b,
                  const RigidTransform& b_to_a) {
  const fcl::CollisionRequestd request(1, false);
  fcl::CollisionResultd result;
  fcl::collide(&a, fcl::Transform3d::Identity(), &b, fcl_transform(b_to_a), request, result);
  return result.isCollision();
}

/// FCL's distance between A and B placed in A's frame by `b_to_a`, with its nearest points (in A's frame, as
/// A sits at the identity); 0 when they intersect, as bvhlab answers (FCL says -1 then).
struct FclDistance {
  double distance;
  Vec3 on_a, on_b;
};
template <class FclBV>
FclDistance fcl_distance(const fcl::BVHModel<FclBV>& a, const fcl::BVHModel<FclBV>& b,
                         const RigidTransform& b_to_a) {
  const fcl::DistanceRequestd request(true);  // nearest points too, as bvhlab computes them
  fcl::DistanceResultd result;
  fcl::distance(&a, fcl::Transform3d::Identity(), &b, fcl_transform(b_to_a), request, result);
  return {std::max(result.min_distance, 0.0), result.nearest_points[0], result.nearest_points[1]};
}

/// FCL's broad phase over the instances of a world: one CollisionObject per instance (copies of a mesh share
/// its model), registered in FCL's DynamicAABBTreeCollisionManager and SaPCollisionManager. The objects are
/// shared by both managers, as bvhlab's broad phases share the world boxes: place() sets every pose and
/// world AABB once per frame, then each manager updates and finds its pairs. FCL's world AABB of a
/// rotated object is the box around its model's bounding sphere, so its candidates contain bvhlab's.
class FclWorld {
 public:
  static constexpr std::array<const char*, 2> kManagers{"fcl_dynamic_aabb_tree", "fcl_sap"};

  /// `models[i]`: instance i's model. Throws std::invalid_argument for a null model.
  explicit FclWorld(const std::vector<std::shared_ptr<fcl::CollisionGeometryd>>& models) {
    for (std::size_t i = 0; i < models.size(); ++i) {
      if (!models[i])
        throw std::invalid_argument("FclWorld: instance " + std::to_string(i) + " has no model");
      objects_.push_back(std::make_unique<fcl::CollisionObjectd>(models[i]));
      objects_.back()->setUserData(reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
      pointers_.push_back(objects_.back().get());
    }
    managers_[0] = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
    managers_[1] = std::make_unique<fcl::SaPCollisionManagerd>();
  }

  [[nodiscard]] std::size_t size() const { return objects_.size(); }

  /// Every instance's pose and world AABB (setTransform, computeAABB): what the managers read.
  void place(std::span<const RigidTransform> poses) {
    if (poses.size() != objects_.size())
      throw std::invalid_argument("FclWorld: " + std::to_string(poses.size()) + " poses for " +
                                  std::to_string(objects_.size()) + " instances");
    for (std::size_t i = 0; i < poses.size(); ++i) {
      objects_[i]->setTransform(fcl_transform(poses[i]));
      objects_[i]->computeAABB();
    }
  }

  /// Manager k (kManagers) after place(): registration and setup on its first call, update() on later ones,
  /// then its all-pairs collide with a callback that only collects the pair (unsorted: FCL's order).
  const std::vector<ObjectPair>& pairs(std::size_t k) {
    fcl::BroadPhaseCollisionManagerd& manager = *managers_.at(k);
    if (!registered_[k]) {
      manager.registerObjects(pointers_);
      manager.setup();
      registered_[k] = true;
    } else {
      manager.update();
    }
    pairs_.clear();
    manager.collide(&pairs_, collect);
    return pairs_;
  }

  /// FCL's narrow phase on one pair of instances at their placed poses: first contact on the models.
  [[nodiscard]] bool collides(ObjectPair p) const {
    const fcl::CollisionRequestd request(1, false);
    fcl::CollisionResultd result;
    fcl::collide(objects_.at(p.a).get(), objects_.at(p.b).get(), request, result);
    return result.isCollision();
  }

 private:
  static std::uint32_t index_of(const fcl::CollisionObjectd* o) {
    return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o->getUserData()));
  }
  static bool collect(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
    static_cast<std::vector<ObjectPair>*>(data)->push_back(
        broad_phase_detail::ordered_pair(index_of(a), index_of(b)));
    return false;  // all pairs, not the first
  }

  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_;
  std::vector<fcl::CollisionObjectd*> pointers_;
  std::array<std::unique_ptr<fcl::BroadPhaseCollisionManagerd>, 2> managers_;
  std::array<bool, 2> registered_{false, false};
  std::vector<ObjectPair> pairs_;
};

}  // namespace bvhlab
