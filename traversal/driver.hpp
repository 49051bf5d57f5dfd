// The pair-traversal driver: the one loop behind every strategy (exact first contact, all contacts, ADB with
// p_min, time-critical, guided exact). A strategy is a configuration of it: a queue policy, a descent
// policy, a limit and a hooks object, all resolved at compile time. No virtual calls, no copies of trees:
// the hooks and policies inline into one loop, which costs what a hand-written loop would.
//
//   traverse<QueuePolicy, Descent>(trees, hooks, limit);   // trees: TreePair<BV, Leaves>
//
// The loop, in order:
//   1. If the limit forbids a first BV test: finish(queue, Ended::BudgetExhausted).
//   2. The root pair is evaluated and admitted (see the hooks below).
//   3. While the queue is not empty:
//      - the limit may end the loop before a pop (limit.allows_pop(), e.g. a deadline): finish, as in 1;
//      - the next pair is taken off the queue (nodes_visited += 1);
//      - a pair of two leaves goes to leaf_pair(pair);
//      - any other pair is expanded by the descent policy into its child pairs, which are evaluated in the
//        descent's order. Staged (when the hooks have children_evaluated or the limit can stop the
//        loop): all children are evaluated, then children_evaluated(parent, scores, count) is called,
//        then each child is admitted; if the limit forbids a child's test, the unexpanded parent goes
//        back onto the queue (it keeps its key for a best-effort answer) and the loop ends with finish.
//        Otherwise each child is admitted right after its own evaluation (same tests, same queue).
//   4. finish(queue, Ended::QueueEmpty).
//   Whenever a hook answers "decided" (admit: Admission::Decide; leaf_pair, children_evaluated:
//   Step::Decided), traverse returns at once: the hook has shaped the Result, and finish is not called.
//
// Queue policies (the order in which admitted pairs are taken):
//   DepthFirst          a stack: the last admitted pair first. With SplitLarger's order [right, left], the
//                       left child is visited first.
//   BestFirst           a priority queue on Pair::key: the highest key first (a four-ary heap,
//                       traversal/four_ary_heap.hpp, ties in its order), with the highest pair pushed since
//                       the last pop held beside the heap: taken next when nothing queued beats it (ties to
//                       it), without a push or pop.
//   OrderedDepthFirst   a stack on which the pairs admitted since the last pop are ordered by key: depth
//                       first, into the most promising child (e.g. the most probable) first.
//
// Descent policies (the child pairs of a pair that is not two leaves):
//   SplitLarger  splits one side: the larger node (by Bvh::size; a leaf cannot be split), children in the
//                order [right, left]. Two child pairs.
//   SplitBoth    splits both sides (a leaf stands for itself): [(l, l), (l, r), (r, l), (r, r)]; two or four
//                child pairs.
//
// Limits (checked by the driver, never by hooks):
//   Unlimited    compiles away.
//   BudgetLimit  a cap on BV tests (checked before every test) and/or a wall-clock deadline (read before
//                the first pop, then every 1 to 4 pops: the closer the deadline, the more often). The loop
//                cannot see a deadline pass during its last step, so a strategy with a deadline asks
//                limit.deadline_passed() once more after traverse returns, and flags a late answer
//                (traversal/adb.hpp).
//
// Resumable (traversal/frame_budget.hpp interleaves many queries under one budget): the same loop, cut into
// steps, with the queue and the staged children kept by the caller between them.
//   begin()  1. and 2. above, as one call;
//   step()   one pass of 3. (a pop, then a leaf pair or an expansion), without limit.allows_pop(): the
//            caller decides when to step;
//   each answers TraversalState::Running (pairs left), Done (a hook decided, or the queue ran empty and
//   finish was called with QueueEmpty) or Stopped (the limit refused a BV test; as in 3., an unexpanded
//   parent goes back onto the queue). A stopped traversal may be stepped again under a new limit, or ended by
//   stop(), which calls finish with Ended::BudgetExhausted.
//
// Hooks: an object with, for Pair = QueuedPair<BV, Key, Tag> (Key: the queue key, or NoKey for a stack;
// Tag: data the strategy keeps with a queued pair, or NoTag):
//   using Pair = ...;
//   Score evaluate(const Pair&)            every BV-pair test, root and children: trees.overlap(pair)
//                                          (counts the test), plus e.g. an estimate.
//   Admission admit(Pair&, Score)          files an evaluated pair: Queue (after setting pair.key and
//                                          pair.tag as needed), Drop, or Decide.
//   Step leaf_pair(const Pair&)            a pair of two leaves taken off the queue. Exact strategies run
//                                          trees.leaf_contact: the one triangle-pair loop, or the trees'
//                                          other leaf test (TreePair's Leaves: point surfaces).
//   Step taken(const Pair&)                optional: a pair just taken off the queue, before its leaf test
//                                          or expansion; Decided ends the loop (distance: the nearest pair
//                                          left is no nearer than the best found).
//   Step children_evaluated(const Pair& parent, const Score* scores, int count)   optional: after all of a
//                                          parent's children were evaluated, before any is admitted (ADB's
//                                          "confirm with children").
//   void finish(queue, Ended)              shapes the Result when the loop ends without a decision; the
//                                          queue holds what was left unexamined.
// The hooks object holds the Result and any per-query state; it lives on the query's stack.
//
// A strategy is a hooks struct plus a choice of policies: exact (traversal/exact.hpp) is ExactHooks with
// DepthFirst, SplitLarger, Unlimited; ADB (traversal/adb.hpp) is AdbHooks with BestFirst, SplitBoth,
// BudgetLimit. A probability-ordered depth-first descent is AdbHooks with OrderedDepthFirst
// (tests/traversal/test_driver.cpp runs it); a frame-budget schedule (traversal/frame_budget.hpp) is
// AdbHooks with SplitBoth, stepped, its queue best first or ordered depth first as the frame asks.
//
// The hot path's members are [[gnu::always_inline]]: the loop must compile to one function whatever the
// including unit's inlining budget (large units otherwise leave pieces of it out of line). The volumes' own
// overlap tests are left to the compiler, as before.
#pragma once

#include "four_ary_heap.hpp"
#include "inline_stack.hpp"
#include "result.hpp"
#include "tree_pair.hpp"

#include <algorithm>
#include <chrono>
#include <concepts>
#include <cstdint>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace bvhlab {

// ---- Queue policies -------------------------------------------------------------------------------------

struct DepthFirst {
  template <class Pair>
  class Queue {
   public:
    [[nodiscard]] bool empty() const { return items_.empty(); }
    [[nodiscard]] const Pair& top() const { return items_.back(); }  ///< the next pair to be taken
    [[gnu::always_inline]] void push(const Pair& p) { items_.push_back(p); }
    [[gnu::always_inline]] Pair pop() {
      const Pair p = items_.back();
      items_.pop_back();
      return p;
    }

   private:
    // In the walk's own frame, up to 2 KiB: 64 pairs of most volumes, 12 of the restricted boxtree's.
    InlineStack<Pair, std::clamp<std::size_t>(2048 / sizeof(Pair), 8, 64)> items_;
  };
};

struct BestFirst {
  template <class Pair>
  class Queue {
   public:
    [[nodiscard]] bool empty() const { return !holding_ && items_.empty(); }
    /// The highest key.
    [[nodiscard]] const Pair& top() const { return takes_held() ? held_ : items_.top(); }
    // Best first mostly takes next a child of the pair it has just taken: holding the best of them outside
    // the heap spares a push and a pop for each such child (on the pinion's wide OBB distance query, half).
    [[gnu::always_inline]] void push(const Pair& p) {
      if (!holding_) {
        held_ = p;
        holding_ = true;
      } else if (held_.key < p.key) {
        push_to_heap(held_);
        held_ = p;
      } else {
        push_to_heap(p);
      }
    }
    [[gnu::always_inline]] Pair pop() {
      if (takes_held()) {
        holding_ = false;
        return held_;
      }
      const Pair p = items_.top();
      items_.pop();
      return p;
    }

   private:
    [[nodiscard]] bool takes_held() const {
      return holding_ && (items_.empty() || !(held_.key < items_.top().key));
    }
    [[gnu::always_inline]] void push_to_heap(const Pair& p) { items_.push(p); }
    // The first pairs in place, up to 2 KiB as the depth-first stack keeps them: a short query (most ADB
    // queries) then allocates nothing, where a 16 KiB block reserved at its first push cost an ADB query on
    // jeep1 4% of its instructions. Past them the room doubles (a 16 KiB front copies 14 KiB on its way).
    static constexpr std::size_t kInlinePairs = std::clamp<std::size_t>(2048 / sizeof(Pair), 8, 64);
    FourAryHeap<Pair, InlineStack<Pair, kInlinePairs>> items_;
    Pair held_{};
    bool holding_ = false;
  };
};

struct OrderedDepthFirst {
  template <class Pair>
  class Queue {
   public:
    [[nodiscard]] bool empty() const { return items_.empty(); }
    [[nodiscard]] const Pair& top() const { return items_.back(); }  ///< the next pair to be taken
    /// Keeps the pairs admitted since the last pop in ascending key order (ties: the later one above),
    /// so the highest is taken next.
    [[gnu::always_inline]] void push(const Pair& p) {
      // Room reserved at the first push, not at construction: a query decided by its root pair (common for
      // ADB on deep overlaps) then allocates nothing.
      if (items_.capacity() == 0) items_.reserve(64);
      items_.push_back(p);
      for (std::size_t i = items_.size() - 1; i > fresh_ && items_[i].key < items_[i - 1].key; --i)
        std::swap(items_[i], items_[i - 1]);
    }
    [[gnu::always_inline]] Pair pop() {
      const Pair p = items_.back();
      items_.pop_back();
      fresh_ = items_.size();
      return p;
    }
    /// Every queued pair, bottom of the stack first (the top is not the highest key: a best-effort answer
    /// looks at them all).
    [[nodiscard]] const std::vector<Pair>& items() const { return items_; }

   private:
    std::vector<Pair> items_;
    std::size_t fresh_ = 0;  ///< where the pairs admitted since the last pop begin
  };
};

// ---- Descent policies -----------------------------------------------------------------------------------

struct SplitLarger {
  /// Calls sink.child(Pair&&) on each child pair of `p` (not two leaves), in order; stops, returning false,
  /// as soon as that returns false.
  template <TreeVolume BV, class Leaves, class Pair, class Sink>
  [[gnu::always_inline]] static bool expand(const TreePair<BV, Leaves>& t, const Pair& p, Sink& sink) {
    const TreeNode& na = t.a.node(p.a);
    const TreeNode& nb = t.b.node(p.b);
    // The two children written out rather than a loop over {right, left}: GCC leaves such a loop rolled,
    // over an array in memory, which costs the cheapest volume (AABB) several percent of a query.
    if (nb.is_leaf() || (!na.is_leaf() && t.a.size(p.a) >= t.b.size(p.b)))
      return split_a(t, p, na.right(), sink) && split_a(t, p, na.left(), sink);
    return split_b(t, p, nb.right(), sink) && split_b(t, p, nb.left(), sink);
  }

 private:
  template <TreeVolume BV, class Leaves, class Pair, class Sink>
  [[gnu::always_inline]] static bool split_a(const TreePair<BV, Leaves>& t, const Pair& p,
                                             std::uint32_t child, Sink& sink) {
    return sink.child(Pair{{}, child, p.b, VolumeWalker<BV>::child_a(t.a, p.wa, child, t.context), p.wb, {}});
  }
  template <TreeVolume BV, class Leaves, class Pair, class Sink>
  [[gnu::always_inline]] static bool split_b(const TreePair<BV, Leaves>& t, const Pair& p,
                                             std::uint32_t child, Sink& sink) {
    return sink.child(Pair{{}, p.a, child, p.wa, VolumeWalker<BV>::child_b(t.b, p.wb, child, t.context), {}});
  }
};

struct SplitBoth {
  template <TreeVolume BV, class Leaves, class Pair, class Sink>
  [[gnu::always_inline]] static bool expand(const TreePair<BV, Leaves>& t, const Pair& p, Sink& sink) {
    using Walker = VolumeWalker<BV>;
    using Working = typename Walker::Working;
    const TreeNode& na = t.a.node(p.a);
    const TreeNode& nb = t.b.node(p.b);
    // A leaf stands for itself; an inner node for its two children.
    std::uint32_t a_nodes[2] = {p.a, p.a}, b_nodes[2] = {p.b, p.b};
    Working a_work[2] = {p.wa, p.wa}, b_work[2] = {p.wb, p.wb};
    const int a_count = na.is_leaf() ? 1 : 2, b_count = nb.is_leaf() ? 1 : 2;
    if (!na.is_leaf())
      for (int x = 0; x < 2; ++x) {
        a_nodes[x] = x ? na.right() : na.left();
        a_work[x] = Walker::child_a(t.a, p.wa, a_nodes[x], t.context);
      }
    if (!nb.is_leaf())
      for (int y = 0; y < 2; ++y) {
        b_nodes[y] = y ? nb.right() : nb.left();
        b_work[y] = Walker::child_b(t.b, p.wb, b_nodes[y], t.context);
      }
    for (int x = 0; x < a_count; ++x)
      for (int y = 0; y < b_count; ++y)
        if (!sink.child(Pair{{}, a_nodes[x], b_nodes[y], a_work[x], b_work[y], {}})) return false;
    return true;
  }
};

// ---- Limits ---------------------------------------------------------------------------------------------

struct Unlimited {
  static constexpr bool never_stops = true;
  static constexpr bool allows_test(const Counters&) { return true; }
  static constexpr bool allows_pop() { return true; }
};

/// A cap on BV tests and/or a wall-clock deadline. The clock starts when the limit is made, which a query
/// does first, before any set-up, and is read before the first pop. A read of steady_clock costs about
/// 25 ns; a pop (up to four BV tests and estimates) 0.25 us to 0.45 us on average on injector_pipes (AABB
/// to OBB), up to 0.9 us near the roots, where the estimates cost most, and twice that when the other
/// hardware thread of the core is busy. Reading before every pop would cost up to a tenth of the query, so
/// each read sets how many pops run before the next: a quarter of the time left at the mean cost of the
/// pops so far (set-up included), at most one more than the pops so far (the first pops may be the
/// dearest) and at most kMaxStride. Far from the deadline the clock is read every 4 pops; within four
/// pops' time of it, before every pop. Unless a stretch of pops costs four times the mean so far, the loop
/// stops within one pop after the deadline. Without a deadline the clock is never read.
class BudgetLimit {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr bool never_stops = false;
  static constexpr std::uint64_t kMaxStride = 4;

  explicit BudgetLimit(const Budget& budget) : max_bv_tests_(budget.max_bv_tests) {
    if (!(budget.deadline_us > 0)) return;  // also NaN: the query's own validation refuses it
    has_deadline_ = true;
    start_ = Clock::now();
    // At most 1e15 us (31 years), which keeps the conversion to the clock's integer ticks in range.
    end_ = start_ + std::chrono::duration_cast<Clock::duration>(
                        std::chrono::duration<double, std::micro>(std::min(budget.deadline_us, 1e15)));
    countdown_ = 1;
  }
  [[gnu::always_inline]] [[nodiscard]] bool allows_test(const Counters& c) const {
    return !(max_bv_tests_ && c.bv_tests >= max_bv_tests_);
  }
  /// Without a deadline the countdown starts at 2^64 - 1 and never reaches zero.
  [[gnu::always_inline]] bool allows_pop() { return --countdown_ != 0 || read_clock(); }
  /// True when a deadline is set and the clock has reached it.
  [[nodiscard]] bool deadline_passed() const { return has_deadline_ && Clock::now() >= end_; }
  /// The BV tests still allowed; the largest count when the budget has no cap.
  [[nodiscard]] std::uint64_t tests_left(const Counters& c) const {
    if (!max_bv_tests_) return ~std::uint64_t{0};
    return c.bv_tests >= max_bv_tests_ ? 0 : max_bv_tests_ - c.bv_tests;
  }

 private:
  /// False once the deadline is reached; otherwise sets the pops until the next read.
  bool read_clock() {
    if (!has_deadline_) return (countdown_ = ~std::uint64_t{0}), true;  // after 2^64 - 1 pops: start over
    const auto now = Clock::now();
    if (now >= end_) return (countdown_ = 1), false;
    const double remaining = static_cast<double>((end_ - now).count());
    const double elapsed = static_cast<double>((now - start_).count());
    const double affordable = pops_ == 0 ? 1 : remaining * static_cast<double>(pops_) / (4 * elapsed);
    const std::uint64_t most = std::min(pops_ + 1, kMaxStride);
    countdown_ = affordable >= static_cast<double>(most) ? most : std::max<std::uint64_t>(affordable, 1);
    pops_ += countdown_;
    return true;
  }

  std::uint64_t max_bv_tests_;
  bool has_deadline_ = false;
  std::uint64_t countdown_ = ~std::uint64_t{0};  ///< pops until the next read of the clock
  std::uint64_t pops_ = 0;                       ///< pops allowed so far
  Clock::time_point start_{}, end_{};
};

// ---- The loop -------------------------------------------------------------------------------------------

namespace driver_detail {
template <class Hooks, class Pair>
concept HasTakenHook = requires(Hooks& h, const Pair& p) {
  { h.taken(p) } -> std::same_as<Step>;
};
template <class Hooks, class Pair, class Score>
concept HasChildrenHook = requires(Hooks& h, const Pair& p, const Score* s) {
  { h.children_evaluated(p, s, 1) } -> std::same_as<Step>;
};
}  // namespace driver_detail

/// The (up to four) evaluated child pairs of a staged expansion. The pairs are left unconstructed: a
/// hierarchical volume's state is large, and a slot is written only when a child is stored.
template <class Pair, class Score>
struct StagedChildren {
  union Slots {
    Slots() {}
    Pair at[4];
  } pairs;
  Score scores[4];
  int count = 0;
};

/// One traversal: the loop of the header comment. Descent policies hand it each child pair through child().
/// It holds only references: the queue, the staged children, the trees and the hooks live on the caller's
/// stack as separate objects, so the queue's out-of-line growth does not force the compiler to reload the
/// trees' and hooks' references after every BV test.
template <class QueuePolicy, class Descent, TreeVolume BV, class Hooks, class Limit,
          class Leaves = TriangleLeaves>
class Traversal {
 public:
  using Pair = typename Hooks::Pair;
  using Score = decltype(std::declval<Hooks&>().evaluate(std::declval<const Pair&>()));
  using Queue = typename QueuePolicy::template Queue<Pair>;
  using Staged = StagedChildren<Pair, Score>;

  Traversal(const TreePair<BV, Leaves>& trees, Hooks& hooks, Limit& limit, Queue& queue, Staged& staged)
      : trees_(trees), hooks_(hooks), limit_(limit), queue_(queue), staged_(staged) {}

  [[gnu::always_inline]] void run() {
    if (!limit_.allows_test(trees_.counters)) return hooks_.finish(queue_, Ended::BudgetExhausted);
    if (Pair root = trees_.template root<Pair>(); file(root, hooks_.evaluate(root))) return;
    while (!queue_.empty()) {
      if (!limit_.allows_pop()) return hooks_.finish(queue_, Ended::BudgetExhausted);
      const Pair top = queue_.pop();
      ++trees_.counters.nodes_visited;
      if constexpr (driver_detail::HasTakenHook<Hooks, Pair>)
        if (hooks_.taken(top) == Step::Decided) return;
      if (trees_.is_leaf_pair(top)) {
        if (hooks_.leaf_pair(top) == Step::Decided) return;
        continue;
      }
      staged_.count = 0;
      if (!Descent::expand(trees_, top, *this)) {
        if constexpr (!kStaged) return;  // a child decided
        queue_.push(top);                // unexpanded: it keeps its key for a best-effort answer
        return hooks_.finish(queue_, Ended::BudgetExhausted);
      }
      if constexpr (kStaged) {
        if constexpr (driver_detail::HasChildrenHook<Hooks, Pair, Score>)
          if (hooks_.children_evaluated(top, staged_.scores, staged_.count) == Step::Decided) return;
        for (int c = 0; c < staged_.count; ++c)
          if (file(staged_.pairs.at[c], staged_.scores[c])) return;
      }
    }
    hooks_.finish(queue_, Ended::QueueEmpty);
  }

  // The step-wise form repeats run()'s body rather than run() calling it: written as begin() and a loop of
  // step(), run() cost up to 4% more instructions (ADB on the restricted boxtree).
  /// The step-wise form (header comment, "Resumable"): the root pair evaluated and admitted.
  [[gnu::always_inline]] TraversalState begin() {
    if (!limit_.allows_test(trees_.counters)) return TraversalState::Stopped;
    if (Pair root = trees_.template root<Pair>(); file(root, hooks_.evaluate(root)))
      return TraversalState::Done;
    return settled();
  }

  /// One pair taken off the (non-empty) queue: a leaf pair tested, any other expanded and its children filed.
  [[gnu::always_inline]] TraversalState step() {
    const Pair top = queue_.pop();
    ++trees_.counters.nodes_visited;
    if constexpr (driver_detail::HasTakenHook<Hooks, Pair>)
      if (hooks_.taken(top) == Step::Decided) return TraversalState::Done;
    if (trees_.is_leaf_pair(top)) {
      if (hooks_.leaf_pair(top) == Step::Decided) return TraversalState::Done;
      return settled();
    }
    staged_.count = 0;
    if (!Descent::expand(trees_, top, *this)) {
      if constexpr (!kStaged) return TraversalState::Done;  // a child decided
      queue_.push(top);  // unexpanded: it keeps its key for a best-effort answer
      return TraversalState::Stopped;
    }
    if constexpr (kStaged) {
      if constexpr (driver_detail::HasChildrenHook<Hooks, Pair, Score>)
        if (hooks_.children_evaluated(top, staged_.scores, staged_.count) == Step::Decided)
          return TraversalState::Done;
      for (int c = 0; c < staged_.count; ++c)
        if (file(staged_.pairs.at[c], staged_.scores[c])) return TraversalState::Done;
    }
    return settled();
  }

  /// Ends a stopped traversal with its best-effort answer (finish with Ended::BudgetExhausted).
  void stop() { hooks_.finish(queue_, Ended::BudgetExhausted); }

  /// The next child pair of the pair being expanded. False ends the expansion: a child decided, or (staged)
  /// the limit forbids its test.
  [[gnu::always_inline]] bool child(Pair&& p) {
    if constexpr (!kStaged) {
      return !file(p, hooks_.evaluate(p));
    } else {
      if (!limit_.allows_test(trees_.counters)) return false;
      staged_.scores[staged_.count] = hooks_.evaluate(p);
      ::new (&staged_.pairs.at[staged_.count++]) Pair(p);
      return true;
    }
  }

  /// Children are staged (all evaluated, then all admitted) when a hook or the limit needs it; otherwise
  /// each is admitted right after its test, which keeps a small pair in registers.
  static constexpr bool kStaged = driver_detail::HasChildrenHook<Hooks, Pair, Score> || !Limit::never_stops;

 private:
  /// Running while pairs are queued; otherwise the traversal ends with an empty queue.
  [[gnu::always_inline]] TraversalState settled() {
    if (!queue_.empty()) return TraversalState::Running;
    hooks_.finish(queue_, Ended::QueueEmpty);
    return TraversalState::Done;
  }
  /// Files an evaluated pair; true when the hook decided.
  [[gnu::always_inline]] bool file(Pair& p, Score s) {
    const Admission admission = hooks_.admit(p, s);
    if (admission == Admission::Queue) queue_.push(p);
    return admission == Admission::Decide;
  }

  const TreePair<BV, Leaves>& trees_;
  Hooks& hooks_;
  Limit& limit_;
  Queue& queue_;
  Staged& staged_;
};

/// Runs one traversal; see the header comment for the order of the calls.
template <class QueuePolicy, class Descent, TreeVolume BV, class Leaves, class Hooks, class Limit>
[[gnu::always_inline]] inline void traverse(const TreePair<BV, Leaves>& trees, Hooks& hooks, Limit& limit) {
  using Run = Traversal<QueuePolicy, Descent, BV, Hooks, Limit, Leaves>;
  typename Run::Queue queue;
  typename Run::Staged staged;
  Run(trees, hooks, limit, queue, staged).run();
}

}  // namespace bvhlab
