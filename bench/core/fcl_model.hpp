// FCL's triangle model of a bvhlab Mesh: the one place the bench and the tests hand a mesh to the peer.
// Include only where FCL is found (BVHLAB_HAVE_FCL, or a target that links fcl).
#pragma once

#include "../../bvh/mesh.hpp"

#include <fcl/geometry/bvh/BVH_model.h>

#include <memory>
#include <vector>

namespace bvhlab {

/// The mesh's vertices and triangles in FCL's types.
inline std::vector<fcl::Vector3d> fcl_points(const Mesh& mesh) {
  return {mesh.vertices.begin(), mesh.vertices.end()};
}

/// A BVHModel over the mesh (FCL builds its tree in endModel), with its local AABB computed, so it can
/// also stand in a broad-phase manager.
template <class FclBV>
std::shared_ptr<fcl::BVHModel<FclBV>> make_fcl_model(const Mesh& mesh) {
  auto model = std::make_shared<fcl::BVHModel<FclBV>>();
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  model->beginModel();
  model->addSubModel(fcl_points(mesh), triangles);
  model->endModel();
  model->computeLocalAABB();
  return model;
}

}  // namespace bvhlab
