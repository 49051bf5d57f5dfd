// Trees over point clouds as the run-time layer builds them: the tree of a cloud and the densities it takes.
// Which strategies query them is in engine/typed_query.hpp. Internal to engine/.
#pragma once

#include "adb/point_density.hpp"
#include "engine/specs.hpp"
#include "engine/timing.hpp"
#include "traversal/surface_side.hpp"

#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>

namespace bvhlab {

/// The tree of `cloud` (options.max_leaf_points per leaf) with density D: NoDensity, or AdbDensity from
/// the points' areas (`density`: its grid and tau). `annotate_seconds` receives the annotation's time.
/// Throws std::invalid_argument for a cloud without areas under AdbDensity (annotate_adb_points).
template <TreeVolume BV, class D>
Tree<BV, D> cloud_tree(const PointCloud& cloud, const ParamValues& density, const BuildOptions& options,
                       double& annotate_seconds) {
  Bvh<BV> bvh = Bvh<BV>::build(cloud, options);
  annotate_seconds = 0;
  if constexpr (std::is_same_v<D, NoDensity>) {
    return Tree<BV, D>{std::move(bvh), {}};
  } else {
    static_assert(std::is_same_v<D, AdbDensity>, "trees over points carry no density or adb's");
    const AdbParams params = density_params<D>(density);
    const auto start = Clock::now();
    Tree<BV, D> tree = annotate_adb_points(std::move(bvh), cloud, params.grid, params.tau);
    annotate_seconds = seconds_since(start);
    return tree;
  }
}

/// Calls f.template operator()<D>() with the density a tree over points of BV takes under `density`:
/// NoDensity for "none", AdbDensity for "adb". Throws std::invalid_argument naming any other density, or
/// adb on a volume it cannot annotate (`bv` names the volume).
template <TreeVolume BV, class F>
void with_cloud_density(const std::string& density, const std::string& bv, F&& f) {
  check_cloud_density(density);
  if (density == NoDensity::name()) {
    f.template operator()<NoDensity>();
  } else if constexpr (DensityFor<AdbDensity, BV>) {
    f.template operator()<AdbDensity>();
  } else {
    throw std::invalid_argument("density adb cannot annotate " + bv + " trees");
  }
}

}  // namespace bvhlab
