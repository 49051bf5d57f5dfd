// One budget for a whole frame of candidate object pairs (issue #14): the broad phase yields the pairs, and
// one scheduler spends one budget of BV tests and/or microseconds on all of them, expanding the BV pairs
// whose answer matters most first. Each candidate pair runs the ADB traversal of traversal/adb.hpp (AdbHooks,
// SplitBoth: the same estimate, decisions and best-effort answer) in the order FrameOptions::order names
// (best first, the paper's, or depth first into the most probable child, as adb_dfs), cut into steps
// (traversal/driver.hpp, "Resumable"); the scheduler decides which pair takes the next step.
//
//   std::vector<PairOutcome> out = schedule_frame<BV, D>(pairs, options);   // one outcome per pair, in order
//   schedule_frame<BV, D>(pairs, options, &memory);   // with frame-to-frame fronts (FrameMemory)
//
// The schedule, in order:
//   1. Options and pairs are checked (FrameOptions::validate; a null tree, a bad pose, or guided exact on
//      trees without polygons is refused with std::invalid_argument naming the pair). A deadline counts from
//      the call, set-up included.
//   2. Roots: every pair's root BV pair is tested, in the order given, before any pair is expanded further.
//      This is the guard against starvation: however the policy ranks them, every pair has its root test and
//      an estimate (a pair whose root boxes are apart is decided "no contact" exactly by it), unless the
//      budget ends during this round; the pairs it did not reach answer as in 4. With a FrameMemory, a pair
//      its root leaves open then tests the node pair the previous frame decided on (FrameMemory).
//   3. Steps: while the budget lasts and some pair is undecided, the policy picks the pair whose next step
//      ranks highest (ties: the pair given first), and that pair takes one step: its next BV pair (best
//      first: its most probable queued one; depth first: the most probable child of its last expansion,
//      else of the one before) is taken off its queue and expanded (up to four BV tests), or tested as a
//      leaf pair. Without a budget, both orders give each pair the answer query_adb gives in that order.
//      Then:
//        - a pair whose estimate exceeds p_min (one BV pair's, or its children's / leaf pairs' combined
//          evidence, as ADB's options say) is decided colliding: its remaining entries are dropped;
//        - a pair whose queue runs empty is decided not colliding: exactly when every BV pair was
//          disproved by its volumes (or, with exact leaves, by the triangle tests), otherwise from
//          estimates below p_min;
//        - with exact leaves, a leaf pair whose triangles intersect decides "collision" exactly.
//   4. Exhaustion: when the budget runs out (the cap of BV tests is reached, or the deadline passes), every
//      undecided pair answers from its best remaining estimate, as ADB's best effort does: the highest
//      estimate still queued (or its leaf pairs' combined evidence); "collision" iff that is at least
//      adb.best_effort_threshold (default 0.5), flagged budget_exhausted, never exact. A pair that had no
//      test at all answers probability 0, "no", flagged (with a FrameMemory: the estimate it remembers).
//
// The budget: max_bv_tests counts every BV test of every pair and is never exceeded in total. The deadline
// is checked before each step, reading the clock with BudgetLimit's adaptive stride (every 1 to 4 steps,
// the closer to the deadline the more often): the frame overruns it by at most the steps between two reads.
// Answers decided before the scheduler sees the deadline pass stand unflagged (query_adb flags an answer
// that came late; in a frame, only the pairs the deadline left undecided are flagged).
//
// Policies (frame_policy(name); each is one small struct and one registry line in frame_budget.cpp):
//   adb_probability       the BV pair with the highest ADB estimate among all pairs' queues first: the order
//                         of one global priority queue over every pair's BV pairs (kept as the maximum over
//                         the per-pair queues, which is the same order). Depth first: the pair whose next
//                         BV pair has the highest estimate.
//   uncertainty_per_cost  the pair whose best BV pair maximises p (1 - p) / cost: p its estimate, cost the
//                         expected BV tests to settle it: four per level down to the leaves along the deeper
//                         of its two nodes (SplitBoth descends both at once, up to four tests per level). A
//                         node's levels are estimated from its size: its triangles taken as the tree's times
//                         (box volume / root box volume)^(2/3) (a surface's area scales as volume^(2/3)), and
//                         log2 of that. Nearly settled pairs (p near 0 or 1) and pairs far above their
//                         leaves wait.
//   equal_split           every pair gets an equal share: max_bv_tests / n tests (the first
//                         max_bv_tests mod n pairs one more) and deadline_us / n microseconds from when its
//                         turn begins; the pairs run one after the other, in order, each as the single-pair
//                         time-critical ADB would under its share. A share left unspent is not passed on.
//   round_robin           one step per undecided pair in turn, in the order given.
#pragma once

#include "adb.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bvhlab {

/// One candidate pair of a frame: two trees (not owned; they must outlive the call) and B's pose in A's
/// frame. Trees of different meshes may share a frame; one tree may appear in many pairs.
template <TreeVolume BV, ProbabilityDensity D>
struct FramePair {
  const Tree<BV, D>* a = nullptr;
  const Tree<BV, D>* b = nullptr;
  RigidTransform b_to_a;
  /// Names the pair across frames (e.g. its two instances), for a FrameMemory; unique within a frame. A
  /// pair without one is neither recalled nor remembered.
  std::optional<std::uint64_t> identity;
};

/// Frame-to-frame fronts (optional; schedule_frame's `memory`): what one frame leaves to the next. For each
/// pair a frame decided "collision" on one node pair's own estimate, that node pair and the estimate. In the
/// next frame, when the pair is a candidate again on the same trees and its root test leaves it open, that
/// node pair is tested next and decides "collision" at once if its estimate still exceeds p_min: one BV test
/// where the descent from the root took many, since contacts persist over the frames of a continuous
/// motion. Otherwise the pair goes on from its root, one test later. Under confirm_levels the node pair kept
/// is the last of the confirmed chain; recalled, it decides on its own estimate and is not asked to confirm
/// again (a new chain below it cost about as much as the descent it saves). A pair decided by combined leaf
/// evidence leaves nothing. A pair the budget leaves without a root test answers the remembered estimate as
/// its best effort (flagged), not 0. Such a decision applies ADB's rule to one node pair without its
/// ancestors: where a child's volume is not inside its parent's (OBBs), the descent from the root might
/// have proved the pair apart first; the errors are measured as any schedule's. Identities must be unique
/// within a frame: two remembered pairs with one identity are refused. Keep one object per motion and
/// schedule; a copy keeps a state to return to (a warm-up run).
class FrameMemory {
 public:
  struct Entry {
    std::uint64_t identity = 0;
    const void* tree_a = nullptr;  ///< the trees the node indices refer to
    const void* tree_b = nullptr;
    std::uint32_t node_a = 0, node_b = 0;
    double probability = 0;  ///< the estimate that decided
  };
  /// The previous frame's entry for a pair, when it was decided on the same trees; null otherwise.
  [[nodiscard]] const Entry* recall(std::uint64_t identity, const void* tree_a, const void* tree_b) const;
  /// Keeps an entry for the next frame.
  void remember(const Entry& entry) { next_.push_back(entry); }
  /// Ends a frame: what it remembered becomes what the next recalls. std::invalid_argument when two entries
  /// share an identity (the memory then stays as it was).
  void end_frame();
  /// Entries the next frame may recall.
  [[nodiscard]] std::size_t size() const { return previous_.size(); }

 private:
  std::vector<Entry> previous_;  ///< sorted by identity
  std::vector<Entry> next_;
};

/// The order of each pair's own traversal (header comment, 3.).
enum class FrameOrder {
  best_first,   ///< the most probable queued BV pair next (AdbBestFirst, the paper's)
  depth_first,  ///< the most probable child of the last expansion next (AdbDepthFirst, as adb_dfs)
};
/// Every order, in a fixed order.
std::span<const FrameOrder> frame_orders();
/// "best_first" or "depth_first".
std::string_view frame_order_name(FrameOrder order);
/// The order named `name`; std::invalid_argument listing the known names otherwise.
FrameOrder frame_order(std::string_view name);

struct FrameOptions {
  std::string policy = "adb_probability";     ///< a name of frame_policies()
  FrameOrder order = FrameOrder::best_first;  ///< each pair's traversal order (header comment, 3.)
  double p_min = 0.9;                         ///< a pair is decided colliding once its estimate exceeds this
  /// ADB's options for every pair (leaf evidence, confirmation, best_effort_threshold, exact leaves). Its
  /// p_min is not read (the frame's is), and its budget must be empty: the budget is the frame's.
  AdbOptions adb;
  Budget budget;  ///< for the whole frame; unlimited when empty

  /// Throws std::invalid_argument naming the first bad value (p_min outside (0, 1], a negative or NaN
  /// deadline, a budget in adb, an unknown policy or order, bad ADB options).
  void validate() const;
  /// The ADB options each pair runs with: adb, with the frame's p_min and no budget of its own.
  [[nodiscard]] AdbOptions pair_options() const;
};

/// A pair's answer.
struct PairOutcome {
  bool collides = false;
  double probability = 0;         ///< the estimate decided on; 1 or 0 when exact
  bool budget_exhausted = false;  ///< undecided when the budget ran out: a best-effort answer
  bool exact = false;             ///< decided exactly (volumes apart everywhere, or triangles tested)
  Counters counters;              ///< the work spent on this pair
};

/// What a policy sees of an undecided pair with BV pairs queued.
struct PairStatus {
  std::size_t index = 0;   ///< position in the frame
  double probability = 0;  ///< the estimate of the BV pair it expands next (best first: its queue's highest)
  double cost = 0;         ///< expected BV tests to settle it (header comment); 0 unless the policy uses it
  std::uint64_t expansions = 0;  ///< steps taken so far (BV pairs taken off its queue)
};

/// A scheduling policy (header comment).
struct FramePolicy {
  std::string_view name;
  std::string_view description;
  /// Rank of a pair's next step: the highest goes first.
  double (*priority)(const PairStatus&) = nullptr;
  bool uses_cost = false;     ///< priority reads PairStatus::cost (computing it costs two logarithms)
  bool equal_shares = false;  ///< each pair runs alone under budget / n (see equal_split)
};

/// Every registered policy, in a fixed order.
std::span<const FramePolicy> frame_policies();
/// The policy named `name`; std::invalid_argument listing the known names otherwise.
const FramePolicy& frame_policy(std::string_view name);

namespace frame_detail {

/// The density's estimator for a pair, in the form for its rotation when it has one (as query_adb).
template <TreeVolume BV, ProbabilityDensity D>
auto density_estimator(const Tree<BV, D>& a, const Tree<BV, D>& b, const RigidTransform& b_to_a) {
  if constexpr (requires { D::estimator(a.density, b.density, b_to_a.rotation); })
    return D::estimator(a.density, b.density, b_to_a.rotation);
  else
    return D::estimator(a.density, b.density);
}

/// The estimator in AdbHooks' argument order.
template <class Model>
struct NodeEstimate {
  Model model;
  [[gnu::always_inline]] double operator()(const Box& box_a, const Box& box_b, double overlap,
                                           std::uint32_t i, std::uint32_t j) const {
    return model(i, box_a, j, box_b, overlap);
  }
};

/// The limit of one step: BV tests up to an absolute count of the pair's counters. The scheduler checks
/// the clock itself, between steps.
struct TestCap {
  static constexpr bool never_stops = false;
  std::uint64_t cap;
  [[gnu::always_inline]] [[nodiscard]] bool allows_test(const Counters& c) const { return c.bv_tests < cap; }
  static constexpr bool allows_pop() { return true; }
};

/// Levels below a node down to the leaves, estimated from its box volume (header comment).
template <TreeVolume BV>
double levels_below(const Bvh<BV>& tree, std::uint32_t node) {
  const double root = tree.size(0), own = tree.size(node);
  const double triangles = static_cast<double>(tree.triangle_ids().size());
  if (!(root > 0)) return std::log2(std::max(triangles, 1.0));  // a flat mesh: no size to go by
  if (!(own > 0)) return 0;
  return std::max(0.0, std::log2(std::max(triangles, 1.0)) + (2.0 / 3.0) * std::log2(own / root));
}

/// One candidate pair's ADB traversal, resumable: the state query_adb keeps on its stack, kept between
/// steps, in the order of `Queue` (BestFirst or OrderedDepthFirst). Not movable (the traversal's parts refer
/// to each other): built in place in a std::optional.
template <TreeVolume BV, ProbabilityDensity D, class Queue>
class PairRun {
 public:
  using Estimate = NodeEstimate<decltype(density_estimator(std::declval<const Tree<BV, D>&>(),
                                                           std::declval<const Tree<BV, D>&>(),
                                                           std::declval<const RigidTransform&>()))>;
  using Hooks = AdbHooks<BV, Estimate, TriangleLeaves, estimates_in_node_frames<D, BV>>;
  using Steps = Traversal<Queue, SplitBoth, BV, Hooks, TestCap>;

  PairRun(const FramePair<BV, D>& pair, const AdbOptions& options)
      : context_(VolumeWalker<BV>::make_context(pair.b_to_a)),
        trees_(pair.a->bvh, pair.b->bvh, pair.b_to_a, context_, result_.counters),
        estimate_{density_estimator(*pair.a, *pair.b, pair.b_to_a)},
        hooks_(trees_, result_, options, estimate_),
        state_(pair.a->bvh.empty() || pair.b->bvh.empty() ? TraversalState::Done : TraversalState::Stopped) {}
  PairRun(const PairRun&) = delete;
  PairRun& operator=(const PairRun&) = delete;

  /// The root test, with at most `allowance` BV tests; then, when the root leaves the pair open and the
  /// allowance a test, the node pair the previous frame decided on (FrameMemory). After the root: a root
  /// that decides or disproves the pair (most pairs) costs no recall.
  TraversalState begin(std::uint64_t allowance, const FrameMemory::Entry* remembered = nullptr) {
    if (state_ == TraversalState::Done) return state_;  // an empty tree: no contact (query_adb's answer)
    TestCap cap = cap_after(allowance);
    state_ = steps(cap).begin();
    if (state_ == TraversalState::Running && remembered && cap.allows_test(result_.counters) &&
        decides_again(remembered->node_a, remembered->node_b))
      state_ = TraversalState::Done;
    return state_;
  }
  /// The node pair the traversal decided "collision" on, by its own estimate (AdbHooks::decided_at).
  [[nodiscard]] std::optional<std::pair<std::uint32_t, std::uint32_t>> decided_at() const {
    return hooks_.decided_at();
  }
  /// One step, with at most `allowance` BV tests. Only while running (or stopped, to resume).
  TraversalState step(std::uint64_t allowance) {
    TestCap cap = cap_after(allowance);
    return state_ = steps(cap).step();
  }
  /// The best-effort answer of a pair still undecided; a decided pair keeps its answer.
  void end() {
    if (state_ == TraversalState::Done) return;
    TestCap none{0};
    steps(none).stop();
    state_ = TraversalState::Done;
  }

  [[nodiscard]] std::uint64_t bv_tests() const { return result_.counters.bv_tests; }
  /// Only while running (some BV pair queued).
  [[nodiscard]] PairStatus status(std::size_t index, bool with_cost) const {
    const auto& top = queue_.top();
    const double cost =
        with_cost ? 4 * (1 + std::max(levels_below(trees_.a, top.a), levels_below(trees_.b, top.b))) : 0;
    return {index, top.key, cost, result_.counters.nodes_visited};
  }
  [[nodiscard]] PairOutcome outcome() const {
    return {result_.collides, result_.probability, result_.budget_exhausted, result_.exact, result_.counters};
  }

 private:
  /// A cap `allowance` tests on from here (saturating: an unlimited allowance is the largest count).
  [[nodiscard]] TestCap cap_after(std::uint64_t allowance) const {
    const std::uint64_t spent = result_.counters.bv_tests;
    return {allowance > std::numeric_limits<std::uint64_t>::max() - spent
                ? std::numeric_limits<std::uint64_t>::max()
                : spent + allowance};
  }
  Steps steps(TestCap& cap) { return Steps(trees_, hooks_, cap, queue_, staged_); }

  /// Node pair (i, j) decides "collision" on its own estimate (one BV test): what the traversal would
  /// decide on reaching it. Volumes whose walkers carry state down from the root cannot start below it.
  bool decides_again(std::uint32_t i, std::uint32_t j) {
    if constexpr (!std::is_empty_v<typename VolumeWalker<BV>::Working>) {
      return false;
    } else {
      if (i >= trees_.a.nodes().size() || j >= trees_.b.nodes().size()) return false;
      typename Hooks::Pair pair{{}, i, j, {}, {}, {}};
      return hooks_.decides_again(pair);
    }
  }

  typename VolumeWalker<BV>::Context context_;
  Result result_;
  TreePair<BV> trees_;
  Estimate estimate_;
  Hooks hooks_;
  typename Steps::Queue queue_;
  typename Steps::Staged staged_;
  TraversalState state_;  ///< Stopped until begun; Done at once for an empty tree
};

/// Checks one pair (header comment, 1.); `index` names it.
template <TreeVolume BV, ProbabilityDensity D>
void validate_pair(const FramePair<BV, D>& pair, std::size_t index, const AdbOptions& options) {
  // The name only on failure: built for every pair, it cost as much as the pair's root test.
  const auto name = [index] { return "frame: pair " + std::to_string(index); };
  if (pair.a == nullptr || pair.b == nullptr) throw std::invalid_argument(name() + " has a null tree");
  try {
    pair.b_to_a.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name() + ": " + e.what());
  }
  if (options.exact_leaves && (!pair.a->bvh.has_polygons() || !pair.b->bvh.has_polygons()))
    throw std::invalid_argument(name() + ": guided exact needs trees with polygons");
}

/// The answer of a pair whose root the budget did not reach, without setting it up after the deadline: what
/// a traversal stopped before its first test answers (AdbHooks::finish on an empty queue: no estimate,
/// probability 0, flagged), or no contact for an empty tree (query_adb's answer).
/// With a memory, a pair the previous frame decided "collision" carries that decision's estimate instead.
template <TreeVolume BV, ProbabilityDensity D>
PairOutcome never_begun(const FramePair<BV, D>& pair, const AdbOptions& options,
                        const FrameMemory::Entry* remembered = nullptr) {
  if (pair.a->bvh.empty() || pair.b->bvh.empty()) return {false, 0, false, true, {}};
  const double probability = remembered ? remembered->probability : 0;
  return {probability >= options.best_effort_threshold, probability, true, false, {}};
}

/// The next pairs to step, ranked by the policy: (priority, index), highest priority first, then the lower
/// index.
struct Ranked {
  double priority;
  std::size_t index;
  friend bool operator<(const Ranked& x, const Ranked& y) {
    return x.priority < y.priority || (x.priority == y.priority && x.index > y.index);
  }
};

/// The frame's BV tests: what is left for the whole frame, and under equal shares for one pair.
class TestBudget {
 public:
  TestBudget(std::uint64_t total, std::size_t pairs, bool equal_shares)
      : total_(total), pairs_(pairs), equal_shares_(equal_shares) {}
  /// BV tests pair `index` may still spend, having spent `spent`.
  [[nodiscard]] std::uint64_t allowance(std::size_t index, std::uint64_t spent) const {
    if (total_ == 0) return std::numeric_limits<std::uint64_t>::max();
    const std::uint64_t frame_left = total_ - used_;
    if (!equal_shares_) return frame_left;
    const std::uint64_t share = total_ / pairs_ + (index < total_ % pairs_ ? 1 : 0);
    return std::min(frame_left, share > spent ? share - spent : 0);
  }
  void spend(std::uint64_t tests) { used_ += tests; }

 private:
  std::uint64_t total_, used_ = 0;
  std::size_t pairs_;
  bool equal_shares_;
};

/// A memory recalls decisions made by one node pair's estimate (FrameMemory).
inline void validate_memory(const AdbOptions& options) {
  if (options.confirm_with_children || options.exact_leaves)
    throw std::invalid_argument(
        "frame memory: recalls decisions made by one node pair's estimate; not with confirm_with_children "
        "or exact leaves");
}

/// The previous frame's decision for pair k, if any (FrameMemory::recall).
template <TreeVolume BV, ProbabilityDensity D>
const FrameMemory::Entry* recalled(const FrameMemory* memory, const FramePair<BV, D>& pair) {
  return memory && pair.identity ? memory->recall(*pair.identity, pair.a, pair.b) : nullptr;
}

/// schedule_frame with each pair's traversal in the order of `Queue`; `clock` runs from the call.
template <class Queue, TreeVolume BV, ProbabilityDensity D>
std::vector<PairOutcome> schedule_in_order(std::span<const FramePair<BV, D>> pairs,
                                           const FrameOptions& options, FrameMemory* memory,
                                           BudgetLimit& clock) {
  using Run = PairRun<BV, D, Queue>;
  const FramePolicy& policy = frame_policy(options.policy);
  const AdbOptions adb = options.pair_options();
  for (std::size_t k = 0; k < pairs.size(); ++k) validate_pair(pairs[k], k, adb);
  if (memory) validate_memory(adb);

  // Each pair's traversal is set up when its root is tested, in one block allocated up front: a deadline
  // that ends the root round leaves the pairs after it unbuilt (never_begun gives their answers).
  std::vector<std::optional<Run>> runs(pairs.size());
  TestBudget tests(options.budget.max_bv_tests, pairs.size(), policy.equal_shares);
  std::priority_queue<Ranked> next;
  std::vector<Ranked> open;  // the root round's pairs left running, ranked once the round is over
  const auto ranked = [&](std::size_t k) {
    return Ranked{policy.priority(runs[k]->status(k, policy.uses_cost)), k};
  };
  // Runs pair k's root or next step; true when the frame's budget of BV tests has run out.
  const auto advance = [&](std::size_t k, bool root) {
    Run& run = root ? runs[k].emplace(pairs[k], adb) : *runs[k];
    const std::uint64_t before = run.bv_tests();
    const TraversalState progress = root ? run.begin(tests.allowance(k, before), recalled(memory, pairs[k]))
                                         : run.step(tests.allowance(k, before));
    tests.spend(run.bv_tests() - before);
    if (progress == TraversalState::Running) {
      if (root)
        open.push_back({0, k});
      else
        next.push(ranked(k));
    }
    return progress == TraversalState::Stopped && !policy.equal_shares;
  };

  bool exhausted = false;
  // 2. every pair's root first; under a tight deadline the ranking (for uncertainty_per_cost, two
  // logarithms a pair) would take the time of root tests, so it follows the round
  open.reserve(runs.size());
  for (std::size_t k = 0; k < runs.size() && !exhausted; ++k)
    exhausted = !clock.allows_pop() || advance(k, true);
  if (!exhausted && clock.allows_pop()) {
    for (Ranked& r : open) r = ranked(r.index);
    next = std::priority_queue<Ranked>(std::less<Ranked>{}, std::move(open));
  }
  const bool shared_deadline = policy.equal_shares && options.budget.deadline_us > 0;
  const double share_us =
      options.budget.deadline_us / static_cast<double>(std::max<std::size_t>(runs.size(), 1));
  std::size_t turn = runs.size();  // equal shares: the pair whose turn it is, and its own clock
  BudgetLimit turn_clock(Budget{});
  while (!exhausted && !next.empty()) {  // 3.
    if (!clock.allows_pop()) break;
    const std::size_t k = next.top().index;
    next.pop();
    if (shared_deadline) {
      if (k != turn) turn = k, turn_clock = BudgetLimit(Budget{0, share_us});
      if (!turn_clock.allows_pop()) continue;  // its share of time is spent: it answers at the end
    }
    exhausted = advance(k, false);
  }
  std::vector<PairOutcome> outcomes;  // 4. the undecided answer their best effort
  outcomes.reserve(runs.size());
  for (std::size_t k = 0; k < runs.size(); ++k) {
    if (!runs[k]) {
      outcomes.push_back(never_begun(pairs[k], adb, recalled(memory, pairs[k])));
      continue;
    }
    runs[k]->end();
    outcomes.push_back(runs[k]->outcome());
    const auto at = runs[k]->decided_at();
    if (memory && pairs[k].identity && at && !outcomes.back().budget_exhausted)
      memory->remember(
          {*pairs[k].identity, pairs[k].a, pairs[k].b, at->first, at->second, outcomes.back().probability});
  }
  if (memory) memory->end_frame();
  return outcomes;
}

}  // namespace frame_detail

/// Schedules one frame (header comment). Const and thread-safe on shared trees: all state is local, but
/// for `memory` (FrameMemory: frame-to-frame fronts), which it reads and then updates for the next frame.
template <TreeVolume BV, ProbabilityDensity D>
std::vector<PairOutcome> schedule_frame(std::span<const FramePair<BV, D>> pairs, const FrameOptions& options,
                                        FrameMemory* memory = nullptr) {
  BudgetLimit clock(Budget{0, options.budget.deadline_us});  // the deadline counts from here
  options.validate();
  if (options.order == FrameOrder::depth_first)
    return frame_detail::schedule_in_order<OrderedDepthFirst>(pairs, options, memory, clock);
  return frame_detail::schedule_in_order<BestFirst>(pairs, options, memory, clock);
}

}  // namespace bvhlab
