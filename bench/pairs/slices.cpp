#include "bench/pairs/slices.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace bvhlab {

BoundingSphere bounding_sphere(const Mesh& mesh) {
  BoundingSphere s;
  if (mesh.vertices.empty()) return s;
  s.centre = mesh.bounds().center();
  for (const Vec3& v : mesh.vertices) s.radius = std::max(s.radius, double((v - s.centre).norm()));
  return s;
}

double separation(const BoundingSphere& a, const BoundingSphere& b, const RigidTransform& pose) {
  const double apart = (pose.rotation * b.centre + pose.translation - a.centre).norm();
  const double reach = a.radius + b.radius;
  return reach > 0 ? apart / reach : 0;
}

PoseSlice group_slice(const WorkloadSpec& workload, std::size_t g) {
  PoseSlice slice{workload.groups[g].distance, {}};
  for (std::size_t k = 0; k < workload.groups[g].poses.size(); ++k) slice.poses.emplace_back(g, k);
  return slice;
}

std::vector<PoseSlice> separation_slices(const WorkloadSpec& workload, const Mesh& a, const Mesh& b) {
  const BoundingSphere sa = bounding_sphere(a), sb = bounding_sphere(b);
  const long open_bin = std::lround(kSeparationOpenFrom / kSeparationBin);
  std::map<long, PoseSlice> bins;
  for (std::size_t g = 0; g < workload.groups.size(); ++g)
    for (std::size_t k = 0; k < workload.groups[g].poses.size(); ++k) {
      const double s = separation(sa, sb, workload.groups[g].poses[k]);
      const long bin = std::min(open_bin, static_cast<long>(std::floor(s / kSeparationBin)));
      PoseSlice& slice = bins[bin];
      // (2 bin + 1) / 20, not (bin + 0.5) * 0.1: 0.15 rather than 0.15000000000000002 in results.csv
      slice.distance = static_cast<double>(2 * bin + 1) / (2 / kSeparationBin);
      slice.poses.emplace_back(g, k);
    }
  std::vector<PoseSlice> out;
  for (auto& [bin, slice] : bins) out.push_back(std::move(slice));
  return out;
}

}  // namespace bvhlab
