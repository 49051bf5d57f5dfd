// Trees over point clouds as the run-time layer builds and queries them: the tree of a cloud, and which
// strategies take the clouds' surface test at the leaves (traversal/point_leaves.hpp). Internal to engine/.
#pragma once

#include "adb/point_density.hpp"
#include "engine/specs.hpp"
#include "engine/timing.hpp"
#include "traversal/point_leaves.hpp"

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

/// Strategy S, given two trees of type TreeT (a Tree<BV, D>, or what else it reads a tree as), runs on point
/// clouds: it takes the leaf test as a last argument (S::query(a, b, pose, options, leaves)).
template <class S, class BV, class TreeT>
inline constexpr bool takes_leaf_test_on = requires(const TreeT& tree, const RigidTransform& pose,
                                                    const typename S::Options& options,
                                                    const SurfaceLeaves<BV>& leaves) {
  S::query(tree, tree, pose, options, leaves);
};
/// Strategy S runs on point clouds of BV and D.
template <class S, class BV, class D>
inline constexpr bool takes_leaf_test = takes_leaf_test_on<S, BV, Tree<BV, D>>;

/// Why strategy S, configured with `options`, cannot query point clouds on trees of BV and D; empty when it
/// can: it takes a leaf test (takes_leaf_test) and answers something other than triangle pairs
/// (all_contacts).
template <class S, TreeVolume BV, class D>
std::string cloud_query_refusal(const typename S::Options& options, std::string_view name) {
  if constexpr (std::is_same_v<typename S::Options, ContactMode>)
    if (options == ContactMode::All)
      return "strategy " + std::string(name) +
             " lists intersecting triangle pairs, and a point cloud has none";
  if constexpr (!takes_leaf_test<S, BV, D>)
    return "strategy " + std::string(name) + " takes no leaf test, so it cannot query point clouds";
  return {};
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
