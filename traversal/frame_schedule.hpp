// The frame scheduler of traversal/frame_budget.hpp (its header comment says what it does): the steps of
// each pair's ADB traversal (traversal/adb.hpp) and the loop that hands them out. Included by the code that
// schedules frames; frame_budget.hpp alone declares the types and schedule_frame.
#pragma once

#include "adb.hpp"
#include "frame_budget.hpp"

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
#include <utility>
#include <vector>

namespace bvhlab {

namespace frame_detail {

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

/// The queue policy of a pair's traversal in the frame's order (FrameOptions::order), chosen at run time: a
/// best-first queue or an ordered depth-first stack behind one type, so that a volume and density compile
/// one pair run and one scheduling loop instead of one per order (0.9 of the 2.2 s a density query file
/// spent compiling the frame budget).
/// The price is a branch per push and pop that goes the same way all frame.
struct FrameOrderQueue {
  template <class Pair>
  class Queue {
   public:
    void order_by(FrameOrder order) { depth_first_ = order == FrameOrder::depth_first; }
    [[nodiscard]] bool empty() const { return depth_first_ ? stack_.empty() : heap_.empty(); }
    [[nodiscard]] const Pair& top() const { return depth_first_ ? stack_.top() : heap_.top(); }
    [[gnu::always_inline]] void push(const Pair& p) {
      if (depth_first_)
        stack_.push(p);
      else
        heap_.push(p);
    }
    [[gnu::always_inline]] Pair pop() { return depth_first_ ? stack_.pop() : heap_.pop(); }
    /// The highest key queued (0 when none): AdbHooks' best-effort answer (detail::highest_queued).
    [[nodiscard]] double highest_key() const {
      return depth_first_ ? detail::highest_queued(stack_) : detail::highest_queued(heap_);
    }

   private:
    BestFirst::Queue<Pair> heap_;
    OrderedDepthFirst::Queue<Pair> stack_;
    bool depth_first_ = false;
  };
};

/// One candidate pair's ADB traversal, resumable: the state query_adb keeps on its stack, kept between
/// steps, in the frame's order (FrameOrderQueue). Not movable (the traversal's parts refer to each other):
/// built in place in a std::optional.
template <TreeVolume BV, ProbabilityDensity D>
class PairRun {
 public:
  using Estimate = NodeEstimate<decltype(detail::pair_estimator(std::declval<const Tree<BV, D>&>(),
                                                                std::declval<const Tree<BV, D>&>(),
                                                                std::declval<const RigidTransform&>()))>;
  using Hooks = AdbHooks<BV, Estimate, TriangleLeaves, estimates_in_node_frames<D, BV>>;
  using Steps = Traversal<FrameOrderQueue, SplitBoth, BV, Hooks, TestCap>;

  PairRun(const FramePair<BV, D>& pair, const AdbOptions& options, FrameOrder order)
      : context_(VolumeWalker<BV>::make_context(pair.b_to_a)),
        trees_(pair.a->bvh, pair.b->bvh, pair.b_to_a, context_, result_.counters),
        estimate_{detail::pair_estimator(*pair.a, *pair.b, pair.b_to_a)},
        hooks_(trees_, result_, options, estimate_),
        state_(pair.a->bvh.empty() || pair.b->bvh.empty() ? TraversalState::Done : TraversalState::Stopped) {
    queue_.order_by(order);
  }
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
    if constexpr (!StatelessWalk<BV>) {
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

/// schedule_frame; `clock` runs from the call.
template <TreeVolume BV, ProbabilityDensity D>
std::vector<PairOutcome> schedule_pairs(std::span<const FramePair<BV, D>> pairs, const FrameOptions& options,
                                        FrameMemory* memory, BudgetLimit& clock) {
  using Run = PairRun<BV, D>;
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
    Run& run = root ? runs[k].emplace(pairs[k], adb, options.order) : *runs[k];
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
                                        FrameMemory* memory) {
  BudgetLimit clock(Budget{0, options.budget.deadline_us});  // the deadline counts from here
  options.validate();
  return frame_detail::schedule_pairs(pairs, options, memory, clock);
}

}  // namespace bvhlab
