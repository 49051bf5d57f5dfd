// FCL's side of the benchmarks and tests: a BVHModel built from a bvhlab Mesh, a pose as an FCL transform,
// and FCL's first-contact answer. The one place the bench and the tests hand a mesh to the peer. Include
// only where FCL is found (BVHLAB_HAVE_FCL, or a target that links fcl).
#pragma once

#include "../../bvh/mesh.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/narrowphase/collision.h>

#include <memory>
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

}  // namespace bvhlab
