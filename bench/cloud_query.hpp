// Queries with a point cloud on one side or both (`bvhlab query --cloud`): the two trees through the
// run-time layer (engine/any_tree.hpp), and a run over poses with the clouds' surface test at the leaves,
// timed as run_query times meshes.
#pragma once

#include "bench/run.hpp"

#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace bvhlab {

/// One side of a query: a mesh file, or a point-cloud file (PLY: its vertices; XYZ).
struct QueryObject {
  std::filesystem::path file;
  bool cloud = false;
};

/// A query with a point cloud on one side or both, in the files' own units: trees of `bv` (a bvhlab volume)
/// with `density` "none" or "adb" (a cloud from a file gets k-NN areas, k = 10: files carry none), clouds
/// with leaves of 16 points, meshes of one triangle; `strategy` runs with the surface test at the leaves.
/// Throws std::invalid_argument for no pose, no cloud, another density, a volume or strategy that cannot
/// run (all_contacts lists triangle pairs), PointCloudError and MeshError for files they refuse.
QueryOutcome run_cloud_query(const QueryObject& a, const QueryObject& b, const std::string& bv,
                             const DensitySpec& density, const StrategyVariant& strategy,
                             std::span<const RigidTransform> poses, int repeat = 0);

}  // namespace bvhlab
