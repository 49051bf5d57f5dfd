#include "adb/probability.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace bvhlab {
namespace {

void check_counts(int s, int s_a, int s_b) {
  if (s < 0 || s > kMaxProbabilityCells) {
    throw std::invalid_argument("ADB probability: cell count s = " + std::to_string(s) + " is outside [0, " +
                                std::to_string(kMaxProbabilityCells) + "]");
  }
  if (s_a < 0 || s_a > s || s_b < 0 || s_b > s) {
    throw std::invalid_argument(
        "ADB probability: possible collision cell counts s_a = " + std::to_string(s_a) +
        ", s_b = " + std::to_string(s_b) + " must lie in [0, s = " + std::to_string(s) + "]");
  }
}

void check_lb(double lb) {
  if (!(lb >= 0.0 && lb <= 1.0)) {  // also rejects NaN
    throw std::invalid_argument("ADB probability: LB = " + std::to_string(lb) + " is not a probability");
  }
}

// Support of cc: [k_lo, k_hi].
struct Support {
  int k_lo;
  int k_hi;
};

// Fills tail[i - k_lo] with the unnormalised upper tail sum_{j >= i} w_j of the hypergeometric weights,
// where w is scaled so that w(mode) = 1. Normalising by tail[0] (the total) then gives Pr[cc >= i]
// without any binomial coefficient, lgamma or overflow: every weight is at most about 1, the total is at
// least 1, and terms far from the mode simply underflow to 0, where they are negligible anyway. The ratio
// of neighbouring weights is a quotient of products of two counts <= kMaxProbabilityCells, exact in a
// double; each weight carries about two roundings per step away from the mode.
Support upper_tails(int s, int s_a, int s_b, std::vector<double>& tail) {
  const Support sup{std::max(0, s_a + s_b - s), std::min(s_a, s_b)};
  tail.assign(static_cast<std::size_t>(sup.k_hi - sup.k_lo + 1), 0.0);
  const std::int64_t mode_guess =
      (static_cast<std::int64_t>(s_a) + 1) * (static_cast<std::int64_t>(s_b) + 1) / (s + 2);
  const int mode = static_cast<int>(std::clamp<std::int64_t>(mode_guess, sup.k_lo, sup.k_hi));
  const double spare = static_cast<double>(s) - s_a - s_b;  // cells in neither set when cc = 0; may be < 0
  auto w = [&](int i) -> double& { return tail[static_cast<std::size_t>(i - sup.k_lo)]; };

  w(mode) = 1.0;
  for (int i = mode; i < sup.k_hi; ++i) {  // w(i+1) / w(i)
    const double ratio = (static_cast<double>(s_a - i) * static_cast<double>(s_b - i)) /
                         (static_cast<double>(i + 1) * (spare + i + 1));
    w(i + 1) = w(i) * ratio;
    if (w(i + 1) == 0.0) break;  // the rest underflows as well and stays 0
  }
  for (int i = mode; i > sup.k_lo; --i) {  // w(i-1) / w(i)
    const double ratio = (static_cast<double>(i) * (spare + i)) /
                         (static_cast<double>(s_a - i + 1) * static_cast<double>(s_b - i + 1));
    w(i - 1) = w(i) * ratio;
    if (w(i - 1) == 0.0) break;
  }
  // Suffix sums, smallest terms first. Adding non-negative terms never decreases a float sum, so
  // tail[i] <= tail[0] and every ratio tail[i] / tail[0] lies in [0, 1].
  for (std::size_t j = tail.size() - 1; j-- > 0;) tail[j] += tail[j + 1];
  return sup;
}

// The maximisation shared by the free function and the table, so both give bit-identical values.
template <class HitOfX>
ProbabilityEstimate maximise(int s, int s_a, int s_b, std::vector<double>& tail, const HitOfX& hit_of_x) {
  if (std::min(s_a, s_b) < 1) return {};  // no collision cell can exist
  const Support sup = upper_tails(s, s_a, s_b, tail);
  const double total = tail[0];
  ProbabilityEstimate best;
  for (int x = std::max(1, sup.k_lo); x <= sup.k_hi; ++x) {
    const double p = tail[static_cast<std::size_t>(x - sup.k_lo)] / total * hit_of_x(x);
    if (p > best.probability) best = {p, x};
  }
  if (best.best_x == 0) best.best_x = std::max(1, sup.k_lo);  // every candidate was 0 (lb = 0)
  best.probability = std::clamp(best.probability, 0.0, 1.0);
  return best;
}

}  // namespace

double pr_collision_cells_at_least(int s, int s_a, int s_b, int x) {
  check_counts(s, s_a, s_b);
  const int k_lo = std::max(0, s_a + s_b - s);
  const int k_hi = std::min(s_a, s_b);
  if (x <= k_lo) return 1.0;
  if (x > k_hi) return 0.0;
  std::vector<double> tail;
  upper_tails(s, s_a, s_b, tail);
  return std::clamp(tail[static_cast<std::size_t>(x - k_lo)] / tail[0], 0.0, 1.0);
}

double hit_probability(double lb, int x) {
  check_lb(lb);
  if (x < 0)
    throw std::invalid_argument("ADB probability: negative collision cell count " + std::to_string(x));
  if (x == 0) return 0.0;  // also avoids 0 * log1p(-1) = 0 * -inf
  return std::clamp(-std::expm1(static_cast<double>(x) * std::log1p(-lb)), 0.0, 1.0);
}

ProbabilityEstimate estimate_probability_detailed(int s, int s_a, int s_b, double lb) {
  check_counts(s, s_a, s_b);
  check_lb(lb);
  std::vector<double> tail;
  return maximise(s, s_a, s_b, tail, [lb](int x) { return hit_probability(lb, x); });
}

ProbabilityTable::ProbabilityTable(int s_max, double lb) : s_max_(s_max), lb_(lb) {
  if (s_max < 0 || s_max > kMaxTableCells) {
    throw std::invalid_argument("ProbabilityTable: s_max = " + std::to_string(s_max) + " is outside [0, " +
                                std::to_string(kMaxTableCells) + "]");
  }
  check_lb(lb);
  std::vector<double> hit(static_cast<std::size_t>(s_max) + 1);
  for (int x = 0; x <= s_max; ++x) hit[static_cast<std::size_t>(x)] = hit_probability(lb, x);
  const auto hit_of_x = [&hit](int x) { return hit[static_cast<std::size_t>(x)]; };

  values_.resize(index(s_max + 1, 0, 0));
  std::vector<double> tail;
  for (int s = 0; s <= s_max; ++s) {
    for (int hi = 0; hi <= s; ++hi) {
      for (int lo = 0; lo <= hi; ++lo)
        values_[index(s, hi, lo)] = maximise(s, hi, lo, tail, hit_of_x).probability;
    }
  }
}

double ProbabilityTable::estimate(int s, int s_a, int s_b) const {
  if (s >= 0 && s <= s_max_) {
    check_counts(s, s_a, s_b);
    return lookup(s, s_a, s_b);
  }
  return estimate_probability(s, s_a, s_b, lb_);
}

}  // namespace bvhlab
