// ADB traversal (adb/README.md, section 3): a descent ordered by the estimated probability that a BV pair
// holds intersecting polygons. One configuration of the pair-traversal driver (traversal/driver.hpp:
// AdbHooks, BudgetLimit, and an order: a queue and a descent policy), parameterised by options, serves
// three strategies:
//   - probability-guided with p_min: answer "collision" as soon as a pair's estimate exceeds p_min;
//   - time-critical: the same, under a budget of BV tests and/or a deadline; on exhaustion, a best effort;
//   - guided exact: the same order, but leaf pairs run exact triangle tests and nothing is pruned by
//     probability, so the answer is exact.
// The order is a template parameter of query_adb (each order compiles to a loop of its own):
//   AdbBestFirst   the paper's rule: the most probable pair anywhere in the queue next (BestFirst,
//   SplitBoth); AdbDepthFirst  dive: the most probable child of the pair just expanded next, down to a leaf
//   pair, then
//                  back to the most probable pair left by the last expansion (OrderedDepthFirst, SplitBoth).
// Without a budget both orders give the same answers: decisions are made as pairs are filed, and the pairs
// filed before the queue runs empty are the same in any order; only the work until a decision differs.
//
// Decisions (see adb/README.md, "In brief" and section 2):
//   * Vol(A ∩ B) is bounded from above by re-boxing: A's bounding box ∩ B's box re-boxed in A's frame
//     (centre R c + t, half-extents |R| h), and the same with the roles swapped; the smaller bound is used.
//     It still over-estimates the true overlap of a rotated pair, which errs toward "collision" (false
//     positives rather than false negatives).
//   * Flat boxes: a node of polygons in one axis-aligned plane has a box of thickness 0, hence volume 0 and
//     an overlap of 0 with anything: its estimate would be 0 while the volumes overlap. Each box is thickened
//     to at least kMinRelativeThickness of its longest side before the overlap and the estimate see it; the
//     overlap's share of the box, all the estimate uses of it, then stays that of the plane. Boxes that only
//     touch intersect in a face, an edge or a corner; that intersection is thickened the same way.
//   * Which boxes: the nodes' bounding boxes in the trees' frames, or, for a density that counts its cells
//     in the nodes' own frames on a volume that has one (the OBB under "adb"), the nodes' own boxes and
//     their overlap in those frames (adb/pair_geometry.hpp). The density decides; the loop is the same.
//   * The estimate itself comes from the trees' density (adb/concept.hpp, ProbabilityDensity): for ADB,
//     adb/model.hpp.
#pragma once

#include "../adb/pair_geometry.hpp"
#include "../adb/tree.hpp"
#include "adb_options.hpp"
#include "driver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

namespace bvhlab {

/// The paper's order: best first by estimated probability.
struct AdbBestFirst {
  using Queue = BestFirst;
  using Descent = SplitBoth;
};
/// Probability-ordered depth first: the children of an expanded pair are taken most probable first, before
/// anything queued earlier.
struct AdbDepthFirst {
  using Queue = OrderedDepthFirst;
  using Descent = SplitBoth;
};
/// Best first, splitting only the larger node of a pair (the exact traversal's descent): a small object is
/// not opened level by level against a large one's every level.
struct AdbLargerFirst {
  using Queue = BestFirst;
  using Descent = SplitLarger;
};

namespace detail {

/// The highest estimate still queued (0 when none): a priority queue's top, or a scan of a stack, whose top
/// is only the most probable of the latest children. Read once, on an exhausted budget.
template <class Queue>
double highest_queued(const Queue& queue) {
  if constexpr (requires { queue.highest_key(); }) {  // a queue that knows (the frame's run-time order)
    return queue.highest_key();
  } else if constexpr (requires { queue.items(); }) {
    double best = 0;
    for (const auto& pair : queue.items()) best = std::max(best, pair.key);
    return best;
  } else {
    return queue.empty() ? 0 : queue.top().key;
  }
}

// The estimate's geometry lives with the density (adb/pair_geometry.hpp); the old names stay for callers.
using bvhlab::kMinRelativeThickness;
using bvhlab::overlap_volume;
using bvhlab::reboxed_overlap;
using bvhlab::with_min_thickness;

}  // namespace detail

/// The ADB strategies' hooks (queued by the estimate, in either order). `Estimator` is the probability
/// model: estimate(box_a, box_b, overlap volume, node of A, node of B) -> probability. `Leaves` is the
/// trees' leaf test (driver.hpp): triangles run only under exact_leaves (guided exact); a leaf test with
/// kTestedByEstimates (point surfaces) runs on every leaf pair reached, the points' only evidence there.
/// `kNodeFrames`: the boxes and the overlap are taken in the nodes' own frames, for a density that counts
/// its cells there (estimates_in_node_frames, adb/pair_geometry.hpp); otherwise in the trees' frames.
template <TreeVolume BV, class Estimator, class Leaves = TriangleLeaves, bool kNodeFrames = false>
class AdbHooks {
 public:
  /// key: the pair's estimate; tag: the estimate exceeded p_min and awaits confirmation, by its children's
  /// combined estimate (confirm_with_children: 1) or by this many more generations (confirm_levels).
  using Pair = QueuedPair<BV, double, std::uint8_t>;

  AdbHooks(const TreePair<BV, Leaves>& trees, Result& result, const AdbOptions& options,
           const Estimator& estimate)
      : trees_(trees), result_(result), options_(options), estimate_(estimate) {}

  /// Estimated probability of a pair; negative when the volumes do not overlap (provably no contact).
  [[gnu::always_inline]] double evaluate(const Pair& p) {
    if constexpr (kNodeFrames && FramePlacingVolume<BV>) {
      // The test places the two boxes in A's box frame; the estimate reads that, not a second placement.
      PlacedBoxes placed;
      if (!trees_.overlap(p, placed)) return -1;
      ++trees_.counters.probability_evaluations;
      const PairGeometry g = node_frame_geometry(placed);
      return estimate_(g.a, g.b, g.overlap, p.a, p.b);
    } else {
      if (!trees_.overlap(p)) return -1;
      return estimate_overlapping(p);
    }
  }

  /// The estimate of a pair whose volumes are known to overlap: evaluate's after its test, and a wide walk's
  /// (traversal/wide_adb.hpp), which tests four at once and estimates the pairs it found overlapping.
  [[gnu::always_inline]] double estimate_overlapping(const Pair& p) {
    ++trees_.counters.probability_evaluations;
    const PairGeometry g = geometry(p);
    return estimate_(g.a, g.b, g.overlap, p.a, p.b);
  }

  /// Decide, queue (possibly as a candidate), or drop.
  [[gnu::always_inline]] Admission admit(Pair& p, double probability) {
    if (probability < 0) return Admission::Drop;  // volumes apart: provably no contact below
    if (!options_.exact_leaves) {
      if (probability > options_.p_min) {
        if (trees_.is_leaf_pair(p)) return decide(probability, p);
        if (options_.confirm_levels > 0) {
          // A candidate's child carries its count down; any other pair starts a chain.
          p.tag = parent_levels_ > 0 ? parent_levels_ - 1 : options_.confirm_levels;
          if (p.tag == 0) return decide(probability, p);
        } else {
          if (!options_.confirm_with_children) return decide(probability, p);
          p.tag = 1;
        }
      } else if (probability <= 0) {
        dropped_possible_contact_ = true;
        return Admission::Drop;
      }
    }
    p.key = probability;
    return Admission::Queue;
  }

  [[gnu::always_inline]] Step leaf_pair(const Pair& p) {
    if (Leaves::kTestedByEstimates || options_.exact_leaves) {
      const bool hit = trees_.leaf_contact(p.a, p.b, [&](const std::optional<TrianglePair>& pair) {
        result_.witness = pair;
        return true;
      });
      if (!hit) return Step::Continue;
      decided_at_.emplace(p.a, p.b);
      result_.collides = true;
      result_.exact = true;
      result_.probability = 1;
      return Step::Decided;
    }
    dropped_possible_contact_ = true;  // nothing left to refine: the pair's estimate stays below p_min
    best_dropped_ = std::max(best_dropped_, p.key);
    if (options_.combine_leaf_evidence) {
      no_contact_in_leaves_ *= 1 - p.key;
      const double combined = 1 - no_contact_in_leaves_;
      best_dropped_ = std::max(best_dropped_, combined);
      if (combined > options_.p_min) {
        decide(combined);
        return Step::Decided;
      }
    }
    return Step::Continue;
  }

  /// A candidate is confirmed by its children's combined estimate, or demoted to a plain descent.
  /// Under confirm_levels, it only notes the parent's count for the children's admission, which follows.
  [[gnu::always_inline]] Step children_evaluated(const Pair& parent, const double* estimates, int count) {
    parent_levels_ = parent.tag;
    if (!parent.tag || options_.confirm_levels > 0) return Step::Continue;
    double no_contact_in_children = 1;
    for (int c = 0; c < count; ++c) no_contact_in_children *= 1 - std::max(0.0, estimates[c]);
    if (!(1 - no_contact_in_children > options_.p_min)) return Step::Continue;
    decide(1 - no_contact_in_children);
    return Step::Decided;
  }

  /// Shapes the answer once the loop ends without a decisive pair: exhausted budget or empty queue.
  template <class Queue>
  void finish(const Queue& queue, Ended why) {
    // best_dropped: the strongest evidence left unexamined (a single pair's or the combined leaf estimate).
    if (why == Ended::BudgetExhausted) {
      result_.budget_exhausted = true;
      result_.exact = false;
      result_.probability = std::max(detail::highest_queued(queue), best_dropped_);
      result_.collides = result_.probability >= options_.best_effort_threshold;
      return;
    }
    // Queue empty: every pair was disproved by its volumes (exact "no"), or some were left below p_min.
    result_.collides = false;
    result_.exact = options_.exact_leaves || !dropped_possible_contact_;
    result_.probability = options_.exact_leaves ? 0 : best_dropped_;
  }

  /// The node pair whose own estimate decided "collision" (A's node, B's node); none when no single pair
  /// did (undecided, or decided by combined leaf or children evidence). What a frame remembers.
  [[nodiscard]] std::optional<std::pair<std::uint32_t, std::uint32_t>> decided_at() const {
    return decided_at_;
  }

  /// A node pair remembered from the previous frame's decision (FrameMemory) decides "collision" again iff
  /// its estimate still exceeds p_min. Under confirm_levels it was the last pair of a confirmed chain, so
  /// it is not asked to confirm again.
  bool decides_again(const Pair& p) {
    const double probability = evaluate(p);
    if (!(probability > options_.p_min)) return false;
    decide(probability, p);
    return true;
  }

  /// A node pair a coherent query remembered (query_adb_coherent) decides again as reaching it would: under
  /// exact leaves, a leaf pair whose triangles intersect (an exact answer); else decides_again.
  bool recall(const Pair& p) {
    if (!options_.exact_leaves) return decides_again(p);
    return trees_.is_leaf_pair(p) && trees_.overlap(p) && leaf_pair(p) == Step::Decided;
  }

 private:
  [[gnu::always_inline]] PairGeometry geometry(const Pair& p) const {
    if constexpr (kNodeFrames)
      return node_frame_geometry(trees_.a.volume(p.a).oriented_box(), trees_.b.volume(p.b).oriented_box(),
                                 trees_.b_to_a);
    else
      return tree_frame_geometry(trees_.box_a(p), trees_.box_b(p), rebox());
  }

  /// Made at the first estimate: a query whose root volumes are apart needs none.
  const ReboxPose& rebox() const {
    if (!rebox_) rebox_.emplace(trees_.b_to_a);
    return *rebox_;
  }

  Admission decide(double probability, const Pair& p) {
    decided_at_.emplace(p.a, p.b);
    return decide(probability);
  }
  Admission decide(double probability) {
    result_.collides = true;
    result_.exact = false;
    result_.probability = probability;
    return Admission::Decide;
  }

  const TreePair<BV, Leaves>& trees_;
  Result& result_;
  const AdbOptions& options_;
  const Estimator& estimate_;
  mutable std::optional<ReboxPose> rebox_;  ///< the pose as the overlap bound reads it, both ways
  bool dropped_possible_contact_ = false;   // a pair whose volumes overlap was left unexamined
  double best_dropped_ = 0;
  double no_contact_in_leaves_ = 1;  // prod(1 - p) over leaf pairs left below p_min
  std::uint8_t parent_levels_ = 0;   // the tag of the pair whose children are being admitted
  std::optional<std::pair<std::uint32_t, std::uint32_t>> decided_at_;
};

namespace detail {

/// A coherent query's remembered node pair: tried before the traversal (in), the pair that decided (out).
struct AdbRecall {
  std::optional<std::pair<std::uint32_t, std::uint32_t>> pair;
  bool hit = false;  ///< the remembered pair decided this query
};

/// Whether the remembered pair decides now. Only volumes whose walkers carry nothing down from the root can
/// start below it (as the frame budget's memory).
template <TreeVolume BV, class Leaves, class Hooks>
bool recalled(const TreePair<BV, Leaves>& trees, Hooks& hooks, AdbRecall& recall) {
  if constexpr (!StatelessWalk<BV>) {
    return false;
  } else {
    if (!recall.pair) return false;
    const auto [i, j] = *recall.pair;
    if (i >= trees.a.nodes().size() || j >= trees.b.nodes().size()) return false;
    return recall.hit = hooks.recall(typename Hooks::Pair{{}, i, j, {}, {}, {}});
  }
}

/// The trees' probability model for this pose. A density whose estimate depends on the pair's relative
/// rotation takes it; throws for incompatible annotations.
template <TreeVolume BV, ProbabilityDensity D>
auto pair_estimator(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a) {
  if constexpr (requires { D::estimator(a.density, b.density, b_to_a.rotation); })
    return D::estimator(a.density, b.density, b_to_a.rotation);
  else
    return D::estimator(a.density, b.density);
}

/// query_adb, with a remembered pair tried first when `recall` is given (one instantiation for both).
template <class Order, TreeVolume BV, ProbabilityDensity D, class Leaves>
Result adb_query(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a,
                 const AdbOptions& options, const Leaves& leaves, AdbRecall* recall) {
  BudgetLimit limit(options.budget);  // a deadline counts from here, set-up included
  options.validate();
  b_to_a.validate();
  const auto estimate = pair_estimator(a, b, b_to_a);
  if constexpr (Leaves::kTriangles)
    if (options.exact_leaves) TriangleLeaves::require(a.bvh, b.bvh, "adb: guided exact");

  Result result;
  if (!a.bvh.empty() && !b.bvh.empty()) {
    const auto context = VolumeWalker<BV>::make_context(b_to_a);
    const TreePair<BV, Leaves> trees(a.bvh, b.bvh, b_to_a, context, result.counters, leaves);
    // The probability model: the only place the traversal reads it.
    const auto node_estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                                   std::uint32_t j) { return estimate(i, box_a, j, box_b, overlap); };
    AdbHooks<BV, decltype(node_estimate), Leaves, estimates_in_node_frames<D, BV>> hooks(
        trees, result, options, node_estimate);
    if (!(recall && recalled(trees, hooks, *recall)))
      traverse<typename Order::Queue, typename Order::Descent>(trees, hooks,
                                                               limit);  // frees its queue before it returns
    if (recall) recall->pair = hooks.decided_at();
  } else if (recall) {
    recall->pair.reset();
  }
  // The loop reads the clock before each pop, so it misses a deadline that passed during the last step
  // (a decision, the last pair). Such an answer stands but came late: it is flagged too.
  if (!result.budget_exhausted && limit.deadline_passed()) result.budget_exhausted = true;
  return result;
}

}  // namespace detail

/// ADB query on two trees annotated with a ProbabilityDensity (adb/concept.hpp). `b_to_a` maps B's frame
/// into A's. The probability model comes from the trees' own annotation. `leaves` is the leaf test (the
/// default: triangles; traversal/point_leaves.hpp passes point surfaces: query_adb_points).
/// `Order` is AdbBestFirst (the paper's) or AdbDepthFirst. Const and thread-safe: the model is read-only and
/// all traversal state is local.
template <class Order = AdbBestFirst, TreeVolume BV, ProbabilityDensity D, class Leaves = TriangleLeaves>
Result query_adb(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a,
                 const AdbOptions& options, const Leaves& leaves = kTriangleLeaves) {
  return detail::adb_query<Order>(a, b, b_to_a, options, leaves, nullptr);
}

}  // namespace bvhlab
