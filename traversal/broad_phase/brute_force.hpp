// BruteForce: every pair tested, O(n^2) per frame. The reference the other broad phases are tested against.
#pragma once

#include "broad_phase.hpp"

namespace bvhlab {

class BruteForce {
 public:
  static constexpr std::string_view name() { return "brute_force"; }

  void update(std::span<const Box> boxes) {
    broad_phase_detail::check_update(name(), boxes, registered_);
    registered_ = static_cast<std::int64_t>(boxes.size());
    pairs_.clear();
    // i < j in this loop order already gives the pairs sorted.
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
      for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
        if (broad_phase_detail::boxes_touch(boxes[i], boxes[j])) pairs_.push_back({i, j});
  }

  [[nodiscard]] const std::vector<ObjectPair>& pairs() const { return pairs_; }

 private:
  std::int64_t registered_ = -1;
  std::vector<ObjectPair> pairs_;
};

static_assert(BroadPhase<BruteForce>);

}  // namespace bvhlab
