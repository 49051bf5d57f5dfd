// SweepAndPrune: the boxes sorted by their lower end on one sweep axis; a sweep finds, for each box, the
// boxes starting before it ends, and tests those on the other two axes.
//
// Incremental across frames: the sorted order is kept, and each frame's boxes are written into it in
// place and the order repaired by insertion sort. Under coherent motion few boxes pass each other, so the
// repair costs O(n + swaps), not O(n log n); when the swaps pass about what a full sort would cost
// (4 n log2 n moves), the repair finishes with one. The sweep costs O(n + s), s the pairs overlapping on the
// sweep axis.
//
// The sweep axis is the one along which the box centres spread most (largest variance): that axis
// separates the most boxes, so s is smallest. s scales with 1 / spread, i.e. 1 / sqrt(variance), and
// changing the axis costs a full sort, so the axis changes only when another axis's variance exceeds the
// current one's by kSwitchRatio (2.25: the sweep would test a third fewer pairs); a scene drifting across
// the balance point does not flip the axis back and forth.
#pragma once

#include "broad_phase.hpp"

#include <algorithm>
#include <array>
#include <bit>

namespace bvhlab {

class SweepAndPrune {
 public:
  static constexpr std::string_view name() { return "sweep_and_prune"; }
  /// How much larger another axis's centre variance must be before the sweep moves to it.
  static constexpr double kSwitchRatio = 2.25;

  void update(std::span<const Box> boxes) {
    broad_phase_detail::check_update(name(), boxes, registered_);
    const std::array<double, 3> variance = centre_variances(boxes);
    const int best = static_cast<int>(std::max_element(variance.begin(), variance.end()) - variance.begin());
    if (registered_ < 0) {
      registered_ = static_cast<std::int64_t>(boxes.size());
      entries_.resize(boxes.size());
      for (std::uint32_t i = 0; i < entries_.size(); ++i) entries_[i].id = i;
      resort(boxes, best);
    } else if (best != axis_ && variance[best] > kSwitchRatio * variance[axis_]) {
      ++axis_changes_;
      resort(boxes, best);
    } else {
      refresh(boxes);
      repair_order();
    }
    sweep();
  }

  [[nodiscard]] const std::vector<ObjectPair>& pairs() const { return pairs_; }

  /// The current sweep axis (0 = x, 1 = y, 2 = z).
  [[nodiscard]] int axis() const { return axis_; }
  /// How often the sweep axis changed after registration.
  [[nodiscard]] std::uint64_t axis_changes() const { return axis_changes_; }
  /// Entries moved by the insertion sort in the last update: the cost of the frame's repair.
  [[nodiscard]] std::uint64_t last_moves() const { return last_moves_; }
  /// Frames whose repair exceeded its budget of moves and fell back to a full sort.
  [[nodiscard]] std::uint64_t full_sorts() const { return full_sorts_; }

 private:
  // One box in the sweep axis's terms: [lo, hi] on the sweep axis, then the other two axes.
  struct Entry {
    double lo, hi;
    double lo1, hi1, lo2, hi2;
    std::uint32_t id;
  };

  static std::array<double, 3> centre_variances(std::span<const Box> boxes) {
    if (boxes.empty()) return {0, 0, 0};
    // Sums about the first centre: no cancellation for a scene far from the origin.
    const Vec3 shift = boxes[0].center();
    Vec3 sum = Vec3::Zero(), squares = Vec3::Zero();
    for (const Box& b : boxes) {
      const Vec3 c = (b.min + b.max) * 0.5 - shift;
      sum += c;
      squares += c.cwiseProduct(c);
    }
    const double n = static_cast<double>(boxes.size());
    const Vec3 v = squares / n - (sum / n).cwiseProduct(sum / n);
    return {v.x(), v.y(), v.z()};
  }

  void resort(std::span<const Box> boxes, int axis) {
    axis_ = axis;
    refresh(boxes);
    std::sort(entries_.begin(), entries_.end(), [](const Entry& a, const Entry& b) { return a.lo < b.lo; });
    last_moves_ = entries_.size();
  }

  // Writes this frame's boxes into the entries, in their current order.
  void refresh(std::span<const Box> boxes) {
    const int u = (axis_ + 1) % 3, v = (axis_ + 2) % 3;
    for (Entry& e : entries_) {
      const Box& b = boxes[e.id];
      e.lo = b.min[axis_];
      e.hi = b.max[axis_];
      e.lo1 = b.min[u];
      e.hi1 = b.max[u];
      e.lo2 = b.min[v];
      e.hi2 = b.max[v];
    }
  }

  // Insertion sort on lo: linear in n plus the number of inversions motion introduced. Incoherent motion
  // (objects passing many others) would make that quadratic, so past a budget of moves the rest of the
  // work is left to a full sort.
  void repair_order() {
    const std::size_t n = entries_.size();
    const std::uint64_t budget = 4 * n * (std::bit_width(n) + 1);  // about what a full sort costs
    std::uint64_t moves = 0;
    for (std::size_t i = 1; i < n; ++i) {
      if (!(entries_[i].lo < entries_[i - 1].lo)) continue;
      const Entry moving = entries_[i];
      std::size_t j = i;
      do {
        entries_[j] = entries_[j - 1];
        --j;
      } while (j > 0 && moving.lo < entries_[j - 1].lo);
      entries_[j] = moving;
      moves += i - j;
      if (moves > budget) {
        std::sort(entries_.begin(), entries_.end(),
                  [](const Entry& a, const Entry& b) { return a.lo < b.lo; });
        ++full_sorts_;
        break;
      }
    }
    last_moves_ = moves;
  }

  // For each box, the boxes that start (on the sweep axis) no later than it ends: exactly its sweep-axis
  // overlaps that come after it in the order; the other axes decide.
  void sweep() {
    pairs_.clear();
    const std::size_t n = entries_.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Entry& a = entries_[i];
      for (std::size_t j = i + 1; j < n && entries_[j].lo <= a.hi; ++j) {
        const Entry& b = entries_[j];
        if (broad_phase_detail::all_hold(b.lo1 <= a.hi1, a.lo1 <= b.hi1, b.lo2 <= a.hi2, a.lo2 <= b.hi2))
          pairs_.push_back(broad_phase_detail::ordered_pair(a.id, b.id));
      }
    }
    sorter_.sort(pairs_, n);
  }

  std::int64_t registered_ = -1;
  int axis_ = 0;
  std::uint64_t axis_changes_ = 0;
  std::uint64_t last_moves_ = 0;
  std::uint64_t full_sorts_ = 0;
  std::vector<Entry> entries_;  // sorted by lo
  std::vector<ObjectPair> pairs_;
  broad_phase_detail::PairSorter sorter_;
};

static_assert(BroadPhase<SweepAndPrune>);

}  // namespace bvhlab
