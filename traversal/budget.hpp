// The budget a query may be given: a value type of its own, so that the spec and scene headers name it
// without including the traversal loops (a change to a strategy then rebuilds only what runs one).
#pragma once

#include <cstdint>

namespace bvhlab {

/// Limits for time-critical queries. Zero means "no limit".
struct Budget {
  std::uint64_t max_bv_tests = 0;  ///< hard cap on BV-pair tests (never exceeded)
  double deadline_us = 0;          ///< wall-clock limit from the query's start (see BudgetLimit)
  [[nodiscard]] bool unlimited() const { return max_bv_tests == 0 && deadline_us <= 0; }
};

}  // namespace bvhlab
