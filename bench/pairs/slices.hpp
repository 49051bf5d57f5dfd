// The aggregate stage's unit: a slice of the workload's poses filed under one value of the report's
// "distance" column. A protocol distance or a pose file's group is one slice; a separation axis cuts a random
// or pose-file workload into bins of the two objects' separation, per mesh pair. Internal to the runner.
#pragma once

#include "bench/core/scene.hpp"
#include "bvh/mesh.hpp"

#include <cstddef>
#include <utility>
#include <vector>

namespace bvhlab {

/// Poses (group, index into the group) filed under `distance`.
struct PoseSlice {
  double distance = 0;
  std::vector<std::pair<std::size_t, std::size_t>> poses;
};

/// Bins of the separation axis: this wide from 0, with every separation from kSeparationOpenFrom on in one
/// last bin (filed under kSeparationOpenFrom + half a bin): bounding spheres apart, every pose
/// collision-free.
inline constexpr double kSeparationBin = 0.1, kSeparationOpenFrom = 1.5;

/// The sphere about the centre of the mesh's bounding box that holds every vertex.
struct BoundingSphere {
  Vec3 centre = Vec3::Zero();
  double radius = 0;
};
BoundingSphere bounding_sphere(const Mesh& mesh);

/// B's separation from A at `pose`: the distance of their bounding spheres' centres (B's moved by the pose)
/// over the sum of their radii. Below 1 the spheres overlap.
double separation(const BoundingSphere& a, const BoundingSphere& b, const RigidTransform& pose);

/// Group g of the workload as one slice.
PoseSlice group_slice(const WorkloadSpec& workload, std::size_t g);
/// Every pose of the workload in bins of its separation between `a` and `b` (empty bins left out), in order.
std::vector<PoseSlice> separation_slices(const WorkloadSpec& workload, const Mesh& a, const Mesh& b);

}  // namespace bvhlab
