#include "engine/timing.hpp"

#include <algorithm>
#include <cstdio>

namespace bvhlab {

void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                  PoseQueryRef warm_up, PoseQueryRef query) {
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

}  // namespace bvhlab
