// How the run-time layer times a query: one record per pose, each pose timed on its own, the loop compiled
// around the typed query (no virtual call per query). The runner, `bvhlab query --repeat` and Python's
// timings all time through this loop.
#pragma once

#include "traversal/result.hpp"
#include "volumes/geometry.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <span>
#include <vector>

namespace bvhlab {

using Clock = std::chrono::steady_clock;

inline double micros_since(Clock::time_point start) {
  return std::chrono::duration<double, std::micro>(Clock::now() - start).count();
}

inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// One timed query.
struct QueryRecord {
  bool collides = false, exact = true, budget_exhausted = false;
  double probability = 0, micros = 0;
  Counters counters;
  /// The distance strategies' interval [lower_bound, distance] (Result::proximity); NaN for the others.
  double distance = std::numeric_limits<double>::quiet_NaN();
  double lower_bound = std::numeric_limits<double>::quiet_NaN();
};

/// The timing loop: `warmup` untimed queries through `warm_up`, then each pose timed on its own through
/// `query`. A separate warm-up query lets a coherent series warm up on a copy of its state.
template <class WarmUp, class Query>
void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                  WarmUp&& warm_up, Query&& query) {
  out.clear();
  out.reserve(poses.size());
  bool sink = false;
  for (std::size_t k = 0; k < poses.size() && k < static_cast<std::size_t>(std::max(warmup, 0)); ++k)
    sink ^= warm_up(poses[k]).collides;
  for (const RigidTransform& pose : poses) {
    const auto start = Clock::now();
    const Result r = query(pose);
    const auto stop = Clock::now();
    QueryRecord& record = out.emplace_back(
        QueryRecord{r.collides, r.exact, r.budget_exhausted, r.probability,
                    std::chrono::duration<double, std::micro>(stop - start).count(), r.counters});
    if (r.proximity) {
      record.distance = r.proximity->distance;
      record.lower_bound = r.proximity->lower_bound;
    }
  }
  if (sink && out.empty()) std::fputc(' ', stderr);  // keeps the warm-up from being optimised away
}

/// The timing loop with the timed query as its own warm-up.
template <class Query>
void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                  Query&& query) {
  timed_series(poses, warmup, out, query, query);
}

}  // namespace bvhlab
