// Coherent ADB queries: the ADB strategies (best first, depth first, larger first, time-critical, guided
// exact) started from the node pair that decided the previous query on the same two trees, kept in a
// CoherentState (traversal/coherent_state.hpp). The frame budget's memory, for one pair of trees.
#pragma once

#include "adb.hpp"
#include "coherent_binding.hpp"
#include "coherent_state.hpp"

namespace bvhlab {

/// query_adb<Order>, trying first the node pair that decided the last query with `state`. The remembered
/// pair decides again as the traversal would on reaching it: its estimate still exceeds p_min (no
/// confirming generations are asked of it again, as in the frame budget), or, under exact leaves (guided
/// exact), its triangles still intersect: then guided exact stays exact. A traversal that finds no deciding
/// pair runs as query_adb does. Volumes whose walkers carry state from the root (rbox) never start below
/// it: for them this is query_adb. Throws as query_adb does, and as query_exact_coherent does for the state.
template <class Order = AdbBestFirst, TreeVolume BV, ProbabilityDensity D, class Leaves = TriangleLeaves>
Result query_adb_coherent(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a,
                          const AdbOptions& options, CoherentState& state,
                          const Leaves& leaves = kTriangleLeaves) {
  const CoherentState::InUse in_use(state);
  coherent_detail::attach(state, a.bvh, b.bvh);
  state.serve(options.exact_leaves ? CoherentState::Use::Guided : CoherentState::Use::Adb);
  detail::AdbRecall recall{state.witness};
  Result result = detail::adb_query<Order>(a, b, b_to_a, options, leaves, &recall);
  state.witness = recall.pair;
  if (recall.hit) state.count_witness_hit();
  return result;
}

}  // namespace bvhlab
