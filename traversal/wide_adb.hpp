// ADB on wide trees (bvh/wide_bvh.hpp): the ADB hooks of traversal/adb.hpp (estimate, admission, leaf
// pairs, confirmation, the best-effort answer) on a walk that tests a volume of one tree against the four
// children of a node of the other at once. Best first by estimate (or ordered depth first), splitting the
// larger of a pair's two volumes, as the wide exact walk does (traversal/wide_exact.hpp).
//
// The estimates read the binary tree's annotation: each lane holds a binary node (WideBvh::binary_node),
// whose counts and box the binary walk would read. The wide walk estimates fewer pairs (a step skips the
// binary levels its node absorbed), so its answers are not the binary walk's: it decides on the pairs it
// meets, which may be deeper or coarser. With exact leaves (guided exact) it is exact like the binary walk.
//
// Counters as in the wide exact walk: bv_tests four a step (occupied lanes or not), nodes_visited the pairs
// taken off the queue; probability_evaluations one per overlapping lane. A budget of BV tests is checked
// before each step, so a query may run up to three tests past it.
#pragma once

#include "adb.hpp"
#include "wide_exact.hpp"

#include <bit>
#include <vector>

namespace bvhlab {

namespace wide_detail {

/// A pair on the wide ADB walk's queue: lane a_lane of A's node a_node against lane b_lane of B's b_node
/// (placed in block `placed` where the layout keeps placed blocks), with the hooks' key and tag.
struct WideAdbPair {
  double key = 0;
  std::uint32_t a_node = 0, a_lane = 0, b_node = 0, b_lane = 0, placed = 0;
  std::uint8_t tag = 0;
};

/// The walk itself, filling `hooks`' result: see the header comment.
template <class Order, class Lanes, class Hooks>
void adb_walk(const WideBvh<Lanes>& wide_a, const WideBvh<Lanes>& wide_b,
              const typename Lanes::PairContext& lanes, Hooks& hooks, BudgetLimit& limit,
              Counters& counters) {
  using Tree = WideBvh<Lanes>;
  using HookPair = typename Hooks::Pair;
  constexpr bool keep = Lanes::kKeepsPlaced;
  std::vector<typename Lanes::Placed> placed;
  typename Order::Queue::template Queue<WideAdbPair> queue;
  const auto hook_pair = [&](const WideAdbPair& w) {
    return HookPair{
        w.key, wide_a.binary_node(w.a_node, w.a_lane), wide_b.binary_node(w.b_node, w.b_lane), {}, {}, w.tag};
  };
  // Files an estimated pair: queued with the hooks' key and tag, dropped, or deciding (true).
  const auto file = [&](WideAdbPair w, double estimate) {
    HookPair h = hook_pair(w);
    const Admission admission = hooks.admit(h, estimate);
    if (admission == Admission::Queue) {
      w.key = h.key;
      w.tag = h.tag;
      queue.push(w);
    }
    return admission == Admission::Decide;
  };

  if (!limit.allows_test(counters)) return hooks.finish(queue, Ended::BudgetExhausted);
  counters.bv_tests += 1;
  const typename Lanes::Placed root_b = Lanes::place(wide_b.node(0).boxes, lanes);
  if constexpr (keep) placed.push_back(root_b);
  const auto& root_a = tested_lanes(wide_a.node(0).boxes);
  if (Lanes::overlap_placed(root_a, root_b, lanes) & 1u) {
    const WideAdbPair root{};
    if (file(root, hooks.estimate_overlapping(hook_pair(root)))) return;
  }
  while (!queue.empty()) {
    if (!limit.allows_pop()) return hooks.finish(queue, Ended::BudgetExhausted);
    const WideAdbPair p = queue.pop();
    ++counters.nodes_visited;
    const OpenedPair<Tree> q = open_pair(wide_a, wide_b, p);
    if (q.leaf_a && q.leaf_b) {
      if (hooks.leaf_pair(hook_pair(p)) == Step::Decided) return;
      continue;
    }
    if (!limit.allows_test(counters)) {
      queue.push(p);  // unexpanded: it keeps its key for the best-effort answer
      return hooks.finish(queue, Ended::BudgetExhausted);
    }
    counters.bv_tests += 4;
    unsigned hits = 0;
    WideAdbPair base = p;
    const bool split_b = q.splits_b(p.a_lane, p.b_lane);
    if (split_b) {
      const typename Lanes::Placed children = Lanes::place(wide_b.node(q.child_b).boxes, lanes);
      hits = Lanes::overlap_placed(Lanes::broadcast(q.node_a.boxes, int(p.a_lane)), children, lanes);
      base.b_node = q.child_b;
      base.placed = static_cast<std::uint32_t>(placed.size());
      if constexpr (keep) placed.push_back(children);
    } else {
      const typename Lanes::Placed b_volume = [&] {
        if constexpr (keep)
          return Lanes::broadcast_placed(placed[p.placed], int(p.b_lane));
        else
          return Lanes::place(Lanes::broadcast(q.node_b.boxes, int(p.b_lane)), lanes);
      }();
      hits = Lanes::overlap_placed(tested_lanes(wide_a.node(q.child_a).boxes), b_volume, lanes);
      base.a_node = q.child_a;
    }
    // Every overlapping child estimated, then the parent's confirmation, then each child filed: the order
    // of the binary walk's staged expansion.
    WideAdbPair children[4];
    double estimates[4];
    int count = 0;
    for (; hits != 0; hits &= hits - 1) {
      WideAdbPair child = base;
      (split_b ? child.b_lane : child.a_lane) = static_cast<std::uint32_t>(std::countr_zero(hits));
      estimates[count] = hooks.estimate_overlapping(hook_pair(child));
      children[count++] = child;
    }
    if (hooks.children_evaluated(hook_pair(p), estimates, count) == Step::Decided) return;
    for (int c = 0; c < count; ++c)
      if (file(children[c], estimates[c])) return;
  }
  hooks.finish(queue, Ended::QueueEmpty);
}

}  // namespace wide_detail

/// ADB (p_min, a budget, or exact leaves: AdbOptions, as query_adb) on the wide trees of two annotated
/// trees. `Order` is AdbBestFirst (the default) or AdbDepthFirst: the queue; the descent splits the larger
/// volume, four children at once. Throws std::invalid_argument as query_adb does, and for wide trees not
/// built from these trees' hierarchies (or built before a refit). Const and thread-safe on shared trees.
/// Only volumes whose walkers carry no state: a lane's binary node alone then gives its box to the estimate.
template <class Order = AdbBestFirst, class Lanes, ProbabilityDensity D>
requires StatelessWalk<typename Lanes::Volume> Result query_adb_wide(const Tree<typename Lanes::Volume, D>& a,
                                                                     const WideBvh<Lanes>& wide_a,
                                                                     const Tree<typename Lanes::Volume, D>& b,
                                                                     const WideBvh<Lanes>& wide_b,
                                                                     const RigidTransform& b_to_a,
                                                                     const AdbOptions& options) {
  using BV = typename Lanes::Volume;
  BudgetLimit limit(options.budget);  // a deadline counts from here, set-up included
  options.validate();
  b_to_a.validate();
  const auto estimate = detail::pair_estimator(a, b, b_to_a);
  if (options.exact_leaves) TriangleLeaves::require(a.bvh, b.bvh, "wide adb: guided exact");
  Result result;
  if (a.bvh.empty() || b.bvh.empty()) return result;
  wide_detail::require_pair(a.bvh, wide_a, b.bvh, wide_b, "wide adb query");
  // The leaf test and the estimates read no volume context (the lanes have their own).
  const typename VolumeWalker<BV>::Context unused_context{};
  const TreePair<BV> trees(a.bvh, b.bvh, b_to_a, unused_context, result.counters);
  const auto node_estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                                 std::uint32_t j) { return estimate(i, box_a, j, box_b, overlap); };
  AdbHooks<BV, decltype(node_estimate), TriangleLeaves, estimates_in_node_frames<D, BV>> hooks(
      trees, result, options, node_estimate);
  const typename Lanes::PairContext lanes = Lanes::make_context(b_to_a, wide_a.origin(), wide_b.origin());
  wide_detail::adb_walk<Order>(wide_a, wide_b, lanes, hooks, limit, result.counters);
  if (!result.budget_exhausted && limit.deadline_passed()) result.budget_exhausted = true;
  return result;
}

}  // namespace bvhlab
