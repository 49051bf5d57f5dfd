// What one ADB query is configured with (traversal/adb.hpp): apart from the loop, so that code that only
// names the options (a frame budget's, traversal/frame_budget.hpp) does not parse the loop.
#pragma once

#include "budget.hpp"

#include <cstdint>
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
  /// A pair whose estimate exceeds p_min decides "collision" only once this many generations below it
  /// exceed p_min too, one pair per generation (a child of a candidate that exceeds p_min carries the
  /// count down; a leaf pair ends the chain and decides). Coarse pairs of closed surfaces fill every cell, so
  /// the estimate passes any p_min wherever their boxes overlap widely, touching or not; a chain of
  /// candidates must find pairs small enough to see the gap. Costs about four BV tests per level per
  /// decision. 0: the paper's rule. Not with confirm_with_children.
  std::uint8_t confirm_levels = 0;

  /// Throws std::invalid_argument for nonsense values (NaN, outside [0, 1], negative deadline) and for both
  /// confirmations at once.
  void validate() const {
    if (!(p_min >= 0 && p_min <= 1)) throw std::invalid_argument("adb: p_min must lie in [0, 1]");
    if (confirm_with_children && confirm_levels > 0)
      throw std::invalid_argument("adb: confirm_with_children and confirm_levels exclude each other");
    if (!(best_effort_threshold >= 0 && best_effort_threshold <= 1))
      throw std::invalid_argument("adb: best_effort_threshold must lie in [0, 1]");
    if (!(budget.deadline_us >= 0)) throw std::invalid_argument("adb: deadline must be >= 0 microseconds");
  }
};

}  // namespace bvhlab
