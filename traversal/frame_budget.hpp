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

#include "../adb/tree.hpp"
#include "adb_options.hpp"
#include "budget.hpp"
#include "result.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
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
/// Declared here, defined in traversal/frame_schedule.hpp with the ADB loop it runs: code that only names
/// a frame's options and outcomes does not compile that loop.
template <TreeVolume BV, ProbabilityDensity D>
std::vector<PairOutcome> schedule_frame(std::span<const FramePair<BV, D>> pairs, const FrameOptions& options,
                                        FrameMemory* memory = nullptr);

}  // namespace bvhlab
