// ADB traversal (adb/README.md, section 3): best-first descent ordered by the estimated probability that
// a BV pair holds intersecting polygons. One configuration of the pair-traversal driver
// (traversal/driver.hpp: BestFirst on the estimate, SplitBoth, AdbHooks, BudgetLimit), parameterised by
// options, serves three strategies:
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
//   * Cells: each node's grid lies on its bounding box, so its cells are boxes of extent / g. Differently
//     sized BVs are mapped onto the coarser cells (the larger cell volume): s = Vol(A ∩ B) / c_coarse, and
//     the finer side's expected count is scaled by F_fine / F_coarse, the ratio of the cells' mean face
//     areas. Possible collision cells hold surface, and a surface crosses about area / F cells; for cubic
//     cells this is the square of the side ratio, and for equal sizes it is 1: the paper's case. The
//     same mean face area defines the annotation's threshold tau, and the ratio needs no roots.
//   * Rounding: s is rounded up (at least 1 when the volumes overlap, at most g^3); the fractional s_A, s_B
//     are interpolated bilinearly between the table's integer entries, so a query still does no
//     transcendental math and a small expected count is not rounded away to a probability of 0.
#pragma once

#include "adb/lb_table.hpp"
#include "adb/probability.hpp"
#include "adb/tree.hpp"
#include "traversal/driver.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace bvhlab {

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

/// The probability model for one (grid, tau): the lookup table over (s, s_A, s_B). Built once, shared
/// read-only by any number of queries and threads.
class AdbModel {
 public:
  AdbModel(int grid, double tau) : grid_(grid), tau_(tau), table_(grid * grid * grid, lb_for_tau(tau)) {}

  [[nodiscard]] int grid() const { return grid_; }
  [[nodiscard]] double tau() const { return tau_; }
  [[nodiscard]] const ProbabilityTable& table() const { return table_; }

  /// The estimate for a BV pair from the nodes' own-frame bounding boxes, the overlap volume and the pc
  /// counts. Only arithmetic and four table loads: no transcendental math on the query path.
  [[nodiscard]] double estimate(const Box& box_a, const Box& box_b, double overlap, int pc_a,
                                int pc_b) const {
    if (!(overlap > 0) || pc_a == 0 || pc_b == 0) return 0;
    const Vec3 ea = box_a.extent(), eb = box_b.extent();
    const double volume_a = ea.prod(), volume_b = eb.prod();
    // Mean face area of a cell, times 3 g^2 (the common factor cancels in the ratio).
    const double face_a = ea.x() * ea.y() + ea.y() * ea.z() + ea.z() * ea.x();
    const double face_b = eb.x() * eb.y() + eb.y() * eb.z() + eb.z() * eb.x();
    const int cells = grid_ * grid_ * grid_;
    const bool a_coarse = volume_a >= volume_b;
    const double coarse_cell = (a_coarse ? volume_a : volume_b) / cells;
    // Expected possible-collision cells in the overlap, in each node's own cells...
    double s_a = volume_a > 0 ? pc_a * std::min(1.0, overlap / volume_a) : pc_a;
    double s_b = volume_b > 0 ? pc_b * std::min(1.0, overlap / volume_b) : pc_b;
    // ...with the finer side mapped onto the coarser cells by the ratio of cell face areas.
    if (a_coarse && face_a > 0)
      s_b *= std::min(1.0, face_b / face_a);
    else if (!a_coarse && face_b > 0)
      s_a *= std::min(1.0, face_a / face_b);
    const double s_real = coarse_cell > 0 ? overlap / coarse_cell : cells;
    const int s =
        !(s_real < cells) ? cells : std::clamp(static_cast<int>(std::ceil(s_real - 1e-9)), 1, cells);
    s_a = std::min(s_a, double(s));
    s_b = std::min(s_b, double(s));
    return interpolate(s, s_a, s_b);
  }

 private:
  [[nodiscard]] double interpolate(int s, double s_a, double s_b) const {
    const int a0 = static_cast<int>(s_a), b0 = static_cast<int>(s_b);
    const int a1 = std::min(a0 + 1, s), b1 = std::min(b0 + 1, s);
    const double fa = s_a - a0, fb = s_b - b0;
    const double p00 = table_.lookup(s, a0, b0), p10 = table_.lookup(s, a1, b0);
    const double p01 = table_.lookup(s, a0, b1), p11 = table_.lookup(s, a1, b1);
    return (1 - fa) * ((1 - fb) * p00 + fb * p01) + fa * ((1 - fb) * p10 + fb * p11);
  }

  int grid_;
  double tau_;
  ProbabilityTable table_;
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

}  // namespace detail

/// The ADB strategies' hooks (best-first on the estimate, both sides split). `Estimator` is the probability
/// model: estimate(box_a, box_b, overlap volume, node of A, node of B) -> probability.
template <TreeVolume BV, class Estimator>
class AdbHooks {
 public:
  /// key: the pair's estimate; tag: the estimate exceeded p_min, awaiting confirmation by its children.
  using Pair = QueuedPair<BV, double, bool>;

  AdbHooks(const TreePair<BV>& trees, Result& result, const AdbOptions& options, const Estimator& estimate)
      : trees_(trees),
        result_(result),
        options_(options),
        estimate_(estimate),
        abs_rotation_(trees.b_to_a.rotation.cwiseAbs()) {}

  /// Estimated probability of a pair; negative when the volumes do not overlap (provably no contact).
  [[gnu::always_inline]] double evaluate(const Pair& p) {
    if (!trees_.overlap(p)) return -1;
    ++trees_.counters.probability_evaluations;
    const Box box_a = trees_.box_a(p), box_b = trees_.box_b(p);
    const double overlap = detail::overlap_volume(box_a, box_b, trees_.b_to_a, abs_rotation_);
    return estimate_(box_a, box_b, overlap, p.a, p.b);
  }

  /// Decide, queue (possibly as a candidate), or drop.
  [[gnu::always_inline]] Admission admit(Pair& p, double probability) {
    if (probability < 0) return Admission::Drop;  // volumes apart: provably no contact below
    if (!options_.exact_leaves) {
      if (probability > options_.p_min) {
        if (!options_.confirm_with_children || trees_.is_leaf_pair(p)) return decide(probability);
        p.tag = true;
      } else if (probability <= 0) {
        dropped_possible_contact_ = true;
        return Admission::Drop;
      }
    }
    p.key = probability;
    return Admission::Queue;
  }

  [[gnu::always_inline]] Step leaf_pair(const Pair& p) {
    if (options_.exact_leaves) {
      const bool hit = trees_.intersecting_triangles(p.a, p.b, [&](const TrianglePair& pair) {
        result_.witness = pair;
        return true;
      });
      if (!hit) return Step::Continue;
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
  [[gnu::always_inline]] Step children_evaluated(const Pair& parent, const double* estimates, int count) {
    if (!parent.tag) return Step::Continue;
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
      result_.probability = queue.empty() ? best_dropped_ : std::max(queue.top().key, best_dropped_);
      result_.collides = result_.probability >= options_.best_effort_threshold;
      return;
    }
    // Queue empty: every pair was disproved by its volumes (exact "no"), or some were left below p_min.
    result_.collides = false;
    result_.exact = options_.exact_leaves || !dropped_possible_contact_;
    result_.probability = options_.exact_leaves ? 0 : best_dropped_;
  }

 private:
  Admission decide(double probability) {
    result_.collides = true;
    result_.exact = false;
    result_.probability = probability;
    return Admission::Decide;
  }

  const TreePair<BV>& trees_;
  Result& result_;
  const AdbOptions& options_;
  const Estimator& estimate_;
  const Mat3 abs_rotation_;
  bool dropped_possible_contact_ = false;  // a pair whose volumes overlap was left unexamined
  double best_dropped_ = 0;
  double no_contact_in_leaves_ = 1;  // prod(1 - p) over leaf pairs left below p_min
};

/// ADB query on two annotated trees. `b_to_a` maps B's frame into A's.
/// Const and thread-safe: the model is read-only and all traversal state is local.
template <TreeVolume BV, int G>
Result query_adb(const Tree<BV, AdbDensity<G>>& a, const Tree<BV, AdbDensity<G>>& b,
                 const RigidTransform& b_to_a, const AdbModel& model, const AdbOptions& options) {
  options.validate();
  b_to_a.validate();
  if (model.grid() != G) throw std::invalid_argument("adb: the model's grid differs from the trees'");
  if (a.density.tau != model.tau() || b.density.tau != model.tau())
    throw std::invalid_argument("adb: the trees were annotated with another tau than the model's");
  if (options.exact_leaves && (!a.bvh.has_polygons() || !b.bvh.has_polygons()))
    throw std::invalid_argument("adb: guided exact needs trees with polygons");

  Result result;
  if (a.bvh.empty() || b.bvh.empty()) return result;
  BudgetLimit limit(options.budget);
  const auto context = VolumeWalker<BV>::make_context(b_to_a);
  const TreePair<BV> trees(a.bvh, b.bvh, b_to_a, context, result.counters);
  // The probability model: the only place the traversal reads it.
  const auto& pc_a = a.density.possible_collision_cells;
  const auto& pc_b = b.density.possible_collision_cells;
  const auto estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                            std::uint32_t j) {
    return model.estimate(box_a, box_b, overlap, pc_a[i], pc_b[j]);
  };
  AdbHooks<BV, decltype(estimate)> hooks(trees, result, options, estimate);
  traverse<BestFirst, SplitBoth>(trees, hooks, limit);
  return result;
}

/// Strategy object: ADB with p_min, optionally under a budget, or guided exact. Holds the shared model.
template <int G>
struct AdbStrategy {
  std::shared_ptr<const AdbModel> model;
  AdbOptions options;

  template <TreeVolume BV>
  Result query(const Tree<BV, AdbDensity<G>>& a, const Tree<BV, AdbDensity<G>>& b,
               const RigidTransform& b_to_a) const {
    return query_adb(a, b, b_to_a, *model, options);
  }
};

}  // namespace bvhlab
