// FCL's octree side of the point-cloud benchmark and its test: an octomap::OcTree filled with a cloud's
// points, wrapped as fcl::OcTree, and FCL's first-contact answer for two such trees at a pose. The one place
// the bench and the tests hand a cloud to FCL's octree. Include only where FCL is found (a target that links
// fcl); Debian's fcl is built with octomap.
#pragma once

#include "../../bvh/point_cloud.hpp"
#include "../../volumes/geometry.hpp"

#include <fcl/config.h>
#include <fcl/geometry/octree/octree.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

static_assert(FCL_HAVE_OCTOMAP, "bench/core/fcl_octree.hpp needs an FCL built with octomap");

namespace bvhlab {

/// FCL's occupancy thresholds for the trees below. Every point's voxel holds octomap's clamping maximum
/// (p = 0.971) and every inner node the maximum of its children (octomap's updateInnerOccupancy), so every
/// stored node is occupied at 0.5 (octomap's default) and none is free at 0.12 (octomap's clamping minimum).
/// Space without points has no node at all (unknown); FCL's collision without cost skips unknown space, so
/// only occupied-occupied leaf overlaps report a collision.
inline constexpr double kFclOctreeOccupied = 0.5;
inline constexpr double kFclOctreeFree = 0.12;

/// The cloud's points as occupied voxels of an octree of `resolution` (voxel side), pruned, in FCL's wrapper.
/// Only the points are inserted: no rays are cast, there is no free space (nothing in the benchmark needs
/// it: FCL's collision reads occupied nodes only). Throws std::invalid_argument for a resolution that is not
/// positive and finite, or a point outside the octree's range (about 32,768 voxels from the origin).
inline std::shared_ptr<fcl::OcTreed> make_fcl_octree(const PointCloud& cloud, double resolution) {
  if (!(resolution > 0) || !std::isfinite(resolution))
    throw std::invalid_argument("make_fcl_octree: resolution must be positive and finite, got " +
                                std::to_string(resolution));
  auto tree = std::make_shared<octomap::OcTree>(resolution);
  const float occupied = tree->getClampingThresMaxLog();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.positions[i];
    if (!tree->setNodeValue(p.x(), p.y(), p.z(), occupied, /*lazy_eval*/ true))
      throw std::invalid_argument("make_fcl_octree: point " + std::to_string(i) + " of " + cloud.name +
                                  " is outside the octree's range at resolution " +
                                  std::to_string(resolution));
  }
  tree->updateInnerOccupancy();  // inner nodes: the maximum of their children
  tree->prune();                 // eight occupied children become one occupied parent: the same space
  auto fcl_tree = std::make_shared<fcl::OcTreed>(std::shared_ptr<const octomap::OcTree>(std::move(tree)));
  fcl_tree->setOccupancyThres(kFclOctreeOccupied);
  fcl_tree->setFreeThres(kFclOctreeFree);
  return fcl_tree;
}

/// Two octrees as FCL collision objects, A fixed at the identity and B placed per query.
class FclOctreePair {
 public:
  FclOctreePair(std::shared_ptr<fcl::OcTreed> a, std::shared_ptr<fcl::OcTreed> b)
      : a_(checked(std::move(a), "A")), b_(checked(std::move(b), "B")) {}

  /// FCL's answer with B placed in A's frame by `b_to_a`: one contact requested, no contact points.
  bool collides(const RigidTransform& b_to_a) {
    fcl::Transform3d tf = fcl::Transform3d::Identity();
    tf.linear() = b_to_a.rotation;
    tf.translation() = b_to_a.translation;
    b_.setTransform(tf);
    const fcl::CollisionRequestd request(1, false);
    fcl::CollisionResultd result;
    fcl::collide(&a_, &b_, request, result);
    return result.isCollision();
  }

 private:
  static std::shared_ptr<fcl::OcTreed> checked(std::shared_ptr<fcl::OcTreed> tree, const char* which) {
    if (!tree) throw std::invalid_argument(std::string("FclOctreePair: octree ") + which + " is null");
    return tree;
  }

  fcl::CollisionObjectd a_, b_;
};

}  // namespace bvhlab
