#include "coherent_state.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bvhlab {

void CoherenceOptions::validate() const {
  if (max_pairs == 0) throw std::invalid_argument("coherence: max_pairs must be at least 1");
  if (!(max_jump >= 0) || !std::isfinite(max_jump))
    throw std::invalid_argument("coherence: max_jump must be a finite number >= 0");
}

CoherentState::CoherentState(CoherenceOptions options) : options_(options) {
  options_.validate();
}

std::string_view to_string(CoherenceOptions::Judge judge) {
  return judge == CoherenceOptions::Judge::time ? "time" : "work";
}

CoherenceOptions::Judge judge_from_string(std::string_view name) {
  if (name == "work") return CoherenceOptions::Judge::work;
  if (name == "time") return CoherenceOptions::Judge::time;
  throw std::invalid_argument("unknown judge '" + std::string(name) + "' (expected work or time)");
}

void CoherentState::reset() {
  pairs_.clear();
  stamped_ = last_jumped_ = jumping_on_ = false;
  witness.reset();
  front_cost_ = root_cost_ = -1;
  root_count_ = root_next_ = 0;
  cold_left_ = 0;
  cold_run_ = 2;
  root_backoff_ = root_wait_ = 0;
}

std::size_t CoherentState::front_size() const {
  return static_cast<std::size_t>(
      std::count_if(pairs_.begin(), pairs_.end(), [](const FrontPair& p) { return p.count == 0; }));
}

void CoherentState::bind(const TreeKey& a, const TreeKey& b, const Vec3& centre, double radius) {
  check_trees(a, b);
  a_ = a, b_ = b;
  b_centre_ = centre;
  b_radius_ = radius;
}

void CoherentState::refuse_other_trees() {
  throw std::invalid_argument(
      "coherent query: the state was made for other trees (one state per pair of trees; a tree rebuilt or "
      "made anew needs a new state; reset() does not rebind it)");
}

void CoherentState::InUse::acquire() {
  if (state_.busy_.busy.exchange(true, std::memory_order_acquire))
    throw std::logic_error(
        "coherent query: the state is in use by another query (a state belongs to one caller; give each "
        "thread its own)");
  owner_ = true;
  outer_ = held_here_;
  held_here_ = &state_;
}

void CoherentState::InUse::release() {
  held_here_ = outer_;
  state_.busy_.busy.store(false, std::memory_order_release);
}

bool CoherentState::jumped(const RigidTransform& pose) {
  // A state that has seen no pose knows nothing a front could start from: its first query counts as one in
  // a run of jumps (the cold query, the pose noted), and a walk from the root waits for a pose that stays
  // near it. Poses that jump from the first then never pay for a walk.
  const bool jump = !stamped_ || moved_too_far(pose);
  jumping_on_ = jump && (last_jumped_ || !stamped_);
  last_jumped_ = jump;
  if (jump && stamped_) ++jumps_;
  return jump;
}

bool CoherentState::moved_too_far(const RigidTransform& pose) const {
  if (!stamped_) return false;
  // Every point p of B's root sphere moves by (R - R0) p + (t - t0). |R - R0| = 2 sin(angle / 2), which is
  // sqrt(3 - trace(R R0^T)); the trace is the entrywise product of R and R0.
  const Mat3 turn = pose.rotation - pose_.rotation;
  const double trace = pose.rotation.cwiseProduct(pose_.rotation).sum();
  const double spread = std::sqrt(std::max(0.0, 3 - trace));
  const double moved = (turn * b_centre_ + pose.translation - pose_.translation).norm() + spread * b_radius_;
  return moved > options_.max_jump * b_radius_;
}

namespace {
/// A query's work: a node pair taken, a BV test, and a triangle test worth about four BV tests. A walk also
/// stores its tree, kStoredPairWork units a pair: a walk's pair takes two to three times a cold traversal's
/// node pair in time, which its counts do not show. 5 was measured against 0.5 to 3.5 (bench/RESULTS.md,
/// "What a stored pair weighs"): with half a unit, walks that took 1.5 times the cold query's time looked
/// cheaper by work.
constexpr double kStoredPairWork = 5;
double work_of(const Counters& c) {
  return static_cast<double>(c.nodes_visited + c.bv_tests + 4 * c.triangle_tests);
}
/// A running average that forgets (weight: the newest sample's share), so a change of step size is
/// followed. A sample is capped at 8 times the average: a stall of the machine is not a query's cost.
void average_into(double& average, double sample, double weight) {
  if (average < 0) {
    average = sample;
    return;
  }
  average = (1 - weight) * average + weight * std::min(sample, 8 * average);
}
}  // namespace

void CoherentState::record_cost(const Counters& counters, double seconds, Start start,
                                std::size_t pairs_written) {
  if (options_.max_cold_run == 0) return;
  const double cost = options_.judge == CoherenceOptions::Judge::time
                          ? seconds
                          : work_of(counters) + kStoredPairWork * static_cast<double>(pairs_written);
  if (start == Start::Root) {
    add_root_cost(cost);
    if (cold_left_ > 0) {
      --cold_left_;
      ++cold_queries_;
    }
    return;
  }
  average_into(front_cost_, cost, 0.25);
  if (root_cost_ < 0) return;
  if (front_cost_ > root_cost_) {
    cold_left_ = std::min(cold_run_, options_.max_cold_run);
    cold_run_ = std::min(2 * cold_run_, options_.max_cold_run);
    front_cost_ = -1;  // after the run, the front's next walk is judged on its own
  } else if (2 * front_cost_ < root_cost_) {
    cold_run_ = std::max(cold_run_ / 2, 2u);  // the front pays again: a later loss starts a shorter run
  }
}

void CoherentState::add_root_cost(double cost) {
  root_costs_[root_next_] = cost;
  root_next_ = static_cast<std::uint8_t>((root_next_ + 1) % root_costs_.size());
  root_count_ = static_cast<std::uint8_t>(std::min<std::size_t>(root_count_ + 1, root_costs_.size()));
  // The lower median: of two samples, the cheaper one.
  auto sorted = root_costs_;  // a copy: the ring keeps its order
  const auto middle = sorted.begin() + (root_count_ - 1) / 2;
  std::nth_element(sorted.begin(), middle, sorted.begin() + root_count_);
  root_cost_ = *middle;
}

void CoherentState::store(std::vector<FrontPair>& next, const RigidTransform& pose) {
  restamp(pose);
  if (next.size() > options_.max_pairs) {
    pairs_.clear();
    next = {};  // give the memory back: the bound is on what the state holds
    return;
  }
  pairs_.swap(next);
}

}  // namespace bvhlab
