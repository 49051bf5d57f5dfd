// The density-update policies (concept `DensityUpdate`, adb/concept.hpp): how a tree's ADB counts follow
// its mesh when the mesh deforms and the tree is refitted (Bvh<BV>::refit) instead of rebuilt. The
// query-time density stays `adb`; only how its counts are kept up to date differs.
//
//   stale          the rest shape's counts, kept (no cost)
//   recount_all    every node counted anew, exactly (= annotating the refitted tree from scratch)
//   recount_moved  exact recount of the nodes whose box moved by more than a fraction of a cell
//   samples        counts from fixed area-weighted surface samples that move with their triangles
//
// A new policy is one header (and its .cpp) plus one line in `DensityUpdates`. These are deliberately not
// densities of the bench's registry (engine/registry.hpp): every density there multiplies the runner's
// instantiations, while an update policy only changes the counts of an `adb` tree between frames.
//
//   auto state = RecountMovedUpdate::start(tree.bvh, tree.density, update_params<RecountMovedUpdate>());
//   tree.bvh.refit(deformed);
//   RecountMovedUpdate::update(tree.bvh, tree.density, state, {}, &stats);
#pragma once

#include "../volumes/aabb.hpp"
#include "../volumes/shipped.hpp"
#include "update_recount_all.hpp"
#include "update_recount_moved.hpp"
#include "update_samples.hpp"
#include "update_stale.hpp"

#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Every density-update policy, in the order tools list them.
using DensityUpdates = TypeList<StaleUpdate, RecountAllUpdate, RecountMovedUpdate, SampledUpdate>;

namespace density_update {

template <class... Us>
constexpr bool all_update_adb(TypeList<Us...>) {
  return (DensityUpdateFor<Us, AdbDensity, Aabb> && ...);
}
static_assert(all_update_adb(DensityUpdates{}));

}  // namespace density_update

/// `counts` against an exact recount of the same tree (AdbDensity::annotate), node by node. Throws
/// std::invalid_argument when they differ in node count.
CountError count_error(const AdbStorage& counts, const AdbStorage& exact);

/// The policies' names, in registration order.
inline std::vector<std::string> density_update_names() {
  return type_names(DensityUpdates{});
}

/// Calls f(std::type_identity<U>{}) for every policy, in registration order.
template <class F>
void with_each_density_update(F&& f) {
  for_each_type(std::forward<F>(f), DensityUpdates{});
}

/// Calls f(std::type_identity<U>{}) for the policy named `name` and returns what f returns; throws
/// std::invalid_argument naming the choices for an unknown name.
template <class F>
auto with_density_update(std::string_view name, F&& f) {
  return with_named_type("density update", name, std::forward<F>(f), DensityUpdates{});
}

}  // namespace bvhlab
