// The frame scheduler's options and its registry of policies (traversal/frame_budget.hpp).
#include "frame_budget.hpp"

#include "../volumes/type_list.hpp"

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <string>

namespace bvhlab {

namespace {

// A policy: a name, a one-line description, and the rank of a pair's next step (the highest goes first).

struct AdbProbability {
  static constexpr std::string_view name = "adb_probability";
  static constexpr std::string_view description = "the most probable BV pair of all pairs first";
  static constexpr bool uses_cost = false, equal_shares = false;
  static double priority(const PairStatus& s) { return s.probability; }
};

struct UncertaintyPerCost {
  static constexpr std::string_view name = "uncertainty_per_cost";
  static constexpr std::string_view description = "the pair maximising p (1 - p) / expected BV tests first";
  static constexpr bool uses_cost = true, equal_shares = false;
  static double priority(const PairStatus& s) { return s.probability * (1 - s.probability) / s.cost; }
};

struct EqualSplit {
  static constexpr std::string_view name = "equal_split";
  static constexpr std::string_view description = "budget / n per pair, one pair after the other";
  static constexpr bool uses_cost = false, equal_shares = true;
  static double priority(const PairStatus& s) { return -static_cast<double>(s.index); }
};

struct RoundRobin {
  static constexpr std::string_view name = "round_robin";
  static constexpr std::string_view description = "one step per undecided pair in turn";
  static constexpr bool uses_cost = false, equal_shares = false;
  static double priority(const PairStatus& s) { return -static_cast<double>(s.expansions); }
};

template <class P>
constexpr FramePolicy entry() {
  return {P::name, P::description, &P::priority, P::uses_cost, P::equal_shares};
}

const FramePolicy kPolicies[] = {
    entry<AdbProbability>(),
    entry<UncertaintyPerCost>(),
    entry<EqualSplit>(),
    entry<RoundRobin>(),
};

}  // namespace

const FrameMemory::Entry* FrameMemory::recall(std::uint64_t identity, const void* tree_a,
                                              const void* tree_b) const {
  const auto it = std::lower_bound(previous_.begin(), previous_.end(), identity,
                                   [](const Entry& e, std::uint64_t id) { return e.identity < id; });
  if (it == previous_.end() || it->identity != identity || it->tree_a != tree_a || it->tree_b != tree_b)
    return nullptr;
  return &*it;
}

void FrameMemory::end_frame() {
  std::sort(next_.begin(), next_.end(),
            [](const Entry& x, const Entry& y) { return x.identity < y.identity; });
  const auto twice = std::adjacent_find(
      next_.begin(), next_.end(), [](const Entry& x, const Entry& y) { return x.identity == y.identity; });
  if (twice != next_.end()) {
    const std::uint64_t identity = twice->identity;
    next_.clear();  // the memory stays as the previous frame left it
    throw std::invalid_argument("frame memory: two pairs of one frame have identity " +
                                std::to_string(identity));
  }
  previous_.swap(next_);
  next_.clear();
}

std::span<const FramePolicy> frame_policies() {
  return kPolicies;
}

const FramePolicy& frame_policy(std::string_view name) {
  for (const FramePolicy& policy : kPolicies)
    if (policy.name == name) return policy;
  std::vector<std::string> known;
  for (const FramePolicy& policy : kPolicies) known.emplace_back(policy.name);
  throw unknown_name("frame policy", name, known);
}

namespace {
constexpr FrameOrder kOrders[] = {FrameOrder::best_first, FrameOrder::depth_first};
}  // namespace

std::span<const FrameOrder> frame_orders() {
  return kOrders;
}

std::string_view frame_order_name(FrameOrder order) {
  return order == FrameOrder::depth_first ? "depth_first" : "best_first";
}

FrameOrder frame_order(std::string_view name) {
  std::vector<std::string> known;
  for (FrameOrder order : frame_orders()) {
    if (frame_order_name(order) == name) return order;
    known.emplace_back(frame_order_name(order));
  }
  throw unknown_name("frame order", name, known);
}

void FrameOptions::validate() const {
  if (!(p_min > 0 && p_min <= 1))
    throw std::invalid_argument("frame: p_min must lie in (0, 1], got " + std::to_string(p_min));
  if (!(budget.deadline_us >= 0))
    throw std::invalid_argument("frame: the deadline must be >= 0 microseconds, got " +
                                std::to_string(budget.deadline_us));
  if (!adb.budget.unlimited())
    throw std::invalid_argument(
        "frame: adb.budget must be empty; the frame's budget is FrameOptions::budget");
  frame_policy(policy);
  if (std::find(kOrders, std::end(kOrders), order) == std::end(kOrders))
    throw std::invalid_argument("frame: order is neither best_first nor depth_first");
  pair_options().validate();
}

AdbOptions FrameOptions::pair_options() const {
  AdbOptions options = adb;
  options.p_min = p_min;
  options.budget = {};
  return options;
}

}  // namespace bvhlab
