#include "engine/timing.hpp"

#include "traversal/coherent_state.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

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

void timed_coherent_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                           CoherentQueryRef query, CoherentState& state) {
  CoherentState scratch = warmup > 0 ? state : CoherentState{};
  timed_series(
      poses, warmup, out, [&](const RigidTransform& pose) { return query(pose, scratch); },
      [&](const RigidTransform& pose) { return query(pose, state); });
}

void timed_per_pose_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                           CoherentQueryRef query, std::span<CoherentState> states) {
  if (states.size() != poses.size())
    throw std::invalid_argument("time_per_pose: " + std::to_string(states.size()) + " states for " +
                                std::to_string(poses.size()) + " poses (one per pose)");
  // timed_series warms up on poses 0, 1, ... and then times every pose, in order.
  std::vector<CoherentState> scratch(
      states.begin(), states.begin() + std::min<std::ptrdiff_t>(std::max(warmup, 0), std::ssize(states)));
  std::size_t warmed = 0, timed = 0;
  timed_series(
      poses, warmup, out, [&](const RigidTransform& pose) { return query(pose, scratch[warmed++]); },
      [&](const RigidTransform& pose) { return query(pose, states[timed++]); });
}

}  // namespace bvhlab
