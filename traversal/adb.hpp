// ADB traversal (adb/README.md, section 3): best-first descent ordered by the estimated probability that
// a BV pair holds intersecting polygons. One loop, parameterised by options, serves three strategies:
//   - probability-guided with p_min: answer "collision" as soon as a pair's estimate exceeds p_min;
//   - time-critical: the same, under a budget of BV tests and/or a deadline; on exhaustion, a best effort;
//   - guided exact: the same order, but leaf pairs run exact triangle tests and nothing is pruned by
//     probability, so the answer is exact.
//
// Decisions (see README, "Method"):
//   * Vol(A ∩ B) is bounded from above by re-boxing: A's bounding box ∩ B's box re-boxed in A's frame
//     (centre R c + t, half-extents |R| h), and the same with the roles swapped; the smaller bound is used.
//     It still over-estimates the true overlap of a rotated pair, which errs toward "collision" (false
//     positives rather than false negatives).
//   * The estimate itself comes from the trees' density (adb/concept.hpp, ProbabilityDensity): for ADB,
//     adb/model.hpp.
#pragma once

#include "adb/tree.hpp"
#include "bvh/triangle_intersection.hpp"
#include "traversal/result.hpp"
#include "traversal/tree_access.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <queue>
#include <stdexcept>
#include <vector>

namespace bvhlab {

/// Limits for time-critical queries. Zero means "no limit".
struct Budget {
  std::uint64_t max_bv_tests = 0;  ///< hard cap on BV-pair tests (never exceeded)
  double deadline_us = 0;          ///< wall-clock limit, checked every few node pairs
  [[nodiscard]] bool unlimited() const { return max_bv_tests == 0 && deadline_us <= 0; }
};

struct AdbOptions {
  double p_min = 0.9;  ///< answer "collision" once a pair's estimate exceeds this
  Budget budget;
  /// On budget exhaustion: "collision" iff the highest probability still queued is at least this.
  double best_effort_threshold = 0.5;
  /// Guided exact: leaf pairs run exact triangle tests, no pruning by probability; the answer is exact.
  bool exact_leaves = false;
  /// Leaf pairs cannot be refined; each one left below p_min is still evidence. When set, the traversal
  /// tracks 1 - prod(1 - p_i) over those pairs (the probability that at least one of them collides, if
  /// independent) and answers "collision" once that exceeds p_min. When not set: the paper's literal
  /// rule, which drops each such pair. (A running product: no transcendental math.)
  bool combine_leaf_evidence = true;
  /// A pair whose estimate exceeds p_min decides "collision" only if its children confirm it: their
  /// combined estimate 1 - prod(1 - p_child) must exceed p_min too; otherwise the descent goes on. Coarse
  /// pairs of dense nodes (every cell full) otherwise decide on the first test whenever their boxes overlap
  /// widely. Costs at most four BV tests per decision. Leaf pairs have no children and decide directly.
  /// When not set: the paper's literal rule.
  bool confirm_with_children = false;

  /// Throws std::invalid_argument for nonsense values (NaN, outside [0, 1], negative deadline).
  void validate() const {
    if (!(p_min >= 0 && p_min <= 1)) throw std::invalid_argument("adb: p_min must lie in [0, 1]");
    if (!(best_effort_threshold >= 0 && best_effort_threshold <= 1))
      throw std::invalid_argument("adb: best_effort_threshold must lie in [0, 1]");
    if (!(budget.deadline_us >= 0)) throw std::invalid_argument("adb: deadline must be >= 0 microseconds");
  }
};

namespace detail {

/// Volume of `box` ∩ (`other` re-boxed through rotation/translation): an upper bound of the overlap.
inline double reboxed_overlap(const Box& box, const Box& other, const Mat3& rotation,
                              const Mat3& abs_rotation, const Vec3& translation) {
  const Vec3 center = rotation * other.center() + translation;
  const Vec3 half = abs_rotation * (other.extent() * 0.5);
  const Vec3 lo = box.min.cwiseMax(center - half), hi = box.max.cwiseMin(center + half);
  return (hi - lo).cwiseMax(0.0).prod();
}

/// An upper bound of Vol(A ∩ B) for a rotated pair: re-boxing either box in the other's frame bounds the
/// overlap from above, so the smaller of the two bounds is the tighter one.
inline double overlap_volume(const Box& a, const Box& b, const RigidTransform& b_to_a,
                             const Mat3& abs_rotation) {
  if (a.empty() || b.empty()) return 0;
  const double in_a = reboxed_overlap(a, b, b_to_a.rotation, abs_rotation, b_to_a.translation);
  if (!(in_a > 0)) return 0;
  const Mat3 r_t = b_to_a.rotation.transpose();
  const double in_b = reboxed_overlap(b, a, r_t, abs_rotation.transpose(), -(r_t * b_to_a.translation));
  return std::min(in_a, in_b);
}

template <class Working>
struct QueuedPair {
  double probability;
  std::uint32_t a, b;
  [[no_unique_address]] Working wa;
  [[no_unique_address]] Working wb;
  bool candidate = false;  ///< its estimate exceeded p_min; awaiting confirmation by its children
  bool operator<(const QueuedPair& o) const { return probability < o.probability; }
};

}  // namespace detail

/// Shapes the answer once the loop ends without a decisive pair: exhausted budget or empty queue.
template <class Queue>
Result& finish_adb(Result& result, const Queue& queue, const AdbOptions& options, bool budget_hit,
                   bool dropped_possible_contact, double best_dropped) {
  // best_dropped: the strongest evidence left unexamined (a single pair's or the combined leaf estimate).
  if (result.collides) return result;
  if (budget_hit) {
    result.budget_exhausted = true;
    result.exact = false;
    result.probability = queue.empty() ? best_dropped : std::max(queue.top().probability, best_dropped);
    result.collides = result.probability >= options.best_effort_threshold;
    return result;
  }
  // Queue empty: every pair was disproved by its volumes (exact "no"), or some were left below p_min.
  result.collides = false;
  result.exact = options.exact_leaves || !dropped_possible_contact;
  result.probability = options.exact_leaves ? 0 : best_dropped;
  return result;
}

/// ADB query on two trees annotated with a ProbabilityDensity (adb/concept.hpp). `b_to_a` maps B's frame
/// into A's. The probability model comes from the trees' own annotation.
/// Const and thread-safe: the model is read-only and all traversal state is local.
template <TreeVolume BV, ProbabilityDensity D>
Result query_adb(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a,
                 const AdbOptions& options) {
  options.validate();
  b_to_a.validate();
  const auto estimate = D::estimator(a.density, b.density);  // throws for incompatible annotations
  if (options.exact_leaves && (!a.bvh.has_polygons() || !b.bvh.has_polygons()))
    throw std::invalid_argument("adb: guided exact needs trees with polygons");

  Result result;
  if (a.bvh.empty() || b.bvh.empty()) return result;
  Counters& counters = result.counters;
  const auto start = std::chrono::steady_clock::now();
  using Walker = VolumeWalker<BV>;
  using Pair = detail::QueuedPair<typename Walker::Working>;
  const typename Walker::Context context = Walker::make_context(b_to_a);
  const Mat3 abs_rotation = b_to_a.rotation.cwiseAbs();
  const Budget& budget = options.budget;

  bool budget_hit = false;
  auto may_test = [&] {
    if (budget.max_bv_tests && counters.bv_tests >= budget.max_bv_tests) return budget_hit = true, false;
    return true;
  };
  // Estimated probability of a pair; negative when the volumes do not overlap (provably no contact).
  auto probability = [&](const Pair& e) -> double {
    ++counters.bv_tests;
    if (!Walker::overlap(a.bvh, e.a, e.wa, b.bvh, e.b, e.wb, context)) return -1;
    ++counters.probability_evaluations;
    const Box box_a = Walker::box(a.bvh, e.a, e.wa), box_b = Walker::box(b.bvh, e.b, e.wb);
    const double overlap = detail::overlap_volume(box_a, box_b, b_to_a, abs_rotation);
    return estimate(e.a, box_a, e.b, box_b, overlap);
  };

  std::priority_queue<Pair> queue;
  bool dropped_possible_contact = false;  // a pair whose volumes overlap was left unexamined
  double best_dropped = 0;
  double no_contact_in_leaves = 1;  // prod(1 - p) over leaf pairs left below p_min

  auto is_leaf_pair = [&](const Pair& e) { return a.bvh.node(e.a).is_leaf() && b.bvh.node(e.b).is_leaf(); };
  auto decide = [&](double p) {
    result.collides = true;
    result.exact = false;
    result.probability = p;
    return true;
  };
  // Files an evaluated pair: decide, queue (possibly as a candidate), or drop. True when decided.
  auto admit = [&](Pair e, double p) -> bool {
    if (p < 0) return false;  // volumes apart: provably no contact below
    if (!options.exact_leaves) {
      if (p > options.p_min) {
        if (!options.confirm_with_children || is_leaf_pair(e)) return decide(p);
        e.candidate = true;
      } else if (p <= 0) {
        dropped_possible_contact = true;
        return false;
      }
    }
    e.probability = p;
    queue.push(e);
    return false;
  };

  auto leaf_pair_hits = [&](std::uint32_t i, std::uint32_t j) {
    const TreeNode& na = a.bvh.node(i);
    const TreeNode& nb = b.bvh.node(j);
    const auto& tri_a = a.bvh.triangles();
    const auto& tri_b = b.bvh.triangles();
    for (std::uint32_t tb = nb.first; tb < nb.first + nb.count; ++tb) {
      const TrianglePoints moved = {b_to_a.apply(tri_b[tb][0]), b_to_a.apply(tri_b[tb][1]),
                                    b_to_a.apply(tri_b[tb][2])};
      for (std::uint32_t ta = na.first; ta < na.first + na.count; ++ta) {
        ++counters.triangle_tests;
        if (triangles_intersect(tri_a[ta], moved)) {
          result.witness = TrianglePair{a.bvh.triangle_ids()[ta], b.bvh.triangle_ids()[tb]};
          return true;
        }
      }
    }
    return false;
  };

  if (!may_test()) return finish_adb(result, queue, options, budget_hit, false, 0);
  if (const Pair root{0, 0, 0, Walker::root_a(a.bvh, context), Walker::root_b(b.bvh, context)};
      admit(root, probability(root)))
    return result;
  std::uint64_t pops = 0;
  while (!queue.empty()) {
    if (budget.deadline_us > 0 && (++pops & 15) == 0 &&
        std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count() >
            budget.deadline_us) {
      budget_hit = true;
      break;
    }
    const Pair top = queue.top();
    queue.pop();
    ++counters.nodes_visited;
    const TreeNode& na = a.bvh.node(top.a);
    const TreeNode& nb = b.bvh.node(top.b);
    if (na.is_leaf() && nb.is_leaf()) {
      if (options.exact_leaves) {
        if (leaf_pair_hits(top.a, top.b)) {
          result.collides = true;
          result.exact = true;
          result.probability = 1;
          return result;
        }
      } else {
        dropped_possible_contact = true;  // nothing left to refine: the pair's estimate stays below p_min
        best_dropped = std::max(best_dropped, top.probability);
        if (options.combine_leaf_evidence) {
          no_contact_in_leaves *= 1 - top.probability;
          const double combined = 1 - no_contact_in_leaves;
          best_dropped = std::max(best_dropped, combined);
          if (combined > options.p_min) return decide(combined), result;
        }
      }
      continue;
    }
    // A leaf stands for itself; an inner node for its two children.
    using Working = typename Walker::Working;
    std::pair<std::uint32_t, Working> a_children[2] = {{top.a, top.wa}, {top.a, top.wa}};
    std::pair<std::uint32_t, Working> b_children[2] = {{top.b, top.wb}, {top.b, top.wb}};
    const int a_count = na.is_leaf() ? 1 : 2, b_count = nb.is_leaf() ? 1 : 2;
    if (!na.is_leaf())
      for (int x = 0; x < 2; ++x) {
        const std::uint32_t c = x ? na.right() : na.left();
        a_children[x] = {c, Walker::child_a(a.bvh, top.wa, c, context)};
      }
    if (!nb.is_leaf())
      for (int y = 0; y < 2; ++y) {
        const std::uint32_t c = y ? nb.right() : nb.left();
        b_children[y] = {c, Walker::child_b(b.bvh, top.wb, c, context)};
      }
    Pair children[4];
    double estimates[4];
    int count = 0;
    double no_contact_in_children = 1;
    for (int x = 0; x < a_count; ++x)
      for (int y = 0; y < b_count; ++y) {
        if (!may_test()) {
          queue.push(top);  // the unexpanded pair keeps its estimate for the best-effort answer
          return finish_adb(result, queue, options, true, dropped_possible_contact, best_dropped);
        }
        children[count] = {0, a_children[x].first, b_children[y].first, a_children[x].second,
                           b_children[y].second};
        estimates[count] = probability(children[count]);
        no_contact_in_children *= 1 - std::max(0.0, estimates[count]);
        ++count;
      }
    // A candidate is confirmed by its children's combined estimate, or demoted to a plain descent.
    if (top.candidate && 1 - no_contact_in_children > options.p_min)
      return decide(1 - no_contact_in_children), result;
    for (int c = 0; c < count; ++c)
      if (admit(children[c], estimates[c])) return result;
  }
  return finish_adb(result, queue, options, budget_hit, dropped_possible_contact, best_dropped);
}

}  // namespace bvhlab
