// How the run-time layer times a query: one record per pose, each pose timed on its own. The loop is
// compiled once and calls the typed query through one indirect call (no virtual call per query). The
// runner, `bvhlab query --repeat` and Python's timings all time through this loop.
#pragma once

#include "traversal/result.hpp"
#include "volumes/geometry.hpp"

#include <chrono>
#include <limits>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>
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

class CoherentState;

/// A non-owning reference to a callable `Result(Args...)` (a lambda around the typed query): the timing
/// loops call it, so that they are compiled once (engine/timing.cpp) instead of once per strategy, volume
/// and density. The cost is one indirect call per query, beside the query itself.
template <class... Args>
class QueryRef {
 public:
  template <class F>
  requires(!std::is_same_v<std::remove_cvref_t<F>, QueryRef> && std::is_invocable_r_v<Result, F&, Args...>)
      QueryRef(F&& f)  // NOLINT(google-explicit-constructor): a reference to any such callable
      : object_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
        call_([](void* object, Args... args) -> Result {
          return (*static_cast<std::remove_reference_t<F>*>(object))(std::forward<Args>(args)...);
        }) {}

  Result operator()(Args... args) const { return call_(object_, std::forward<Args>(args)...); }

 private:
  void* object_;
  Result (*call_)(void*, Args...);
};
/// A query at one pose.
using PoseQueryRef = QueryRef<const RigidTransform&>;
/// A coherent query: at one pose, from a state it leaves its own front in (traversal/coherent.hpp).
using CoherentQueryRef = QueryRef<const RigidTransform&, CoherentState&>;

/// The timing loop: `warmup` untimed queries through `warm_up`, then each pose timed on its own through
/// `query`. A separate warm-up query lets a coherent series warm up on a copy of its state. The callables
/// must outlive the call (a lambda written in the call does).
void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                  PoseQueryRef warm_up, PoseQueryRef query);

/// The timing loop with the timed query as its own warm-up.
inline void timed_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                         PoseQueryRef query) {
  timed_series(poses, warmup, out, query, query);
}

/// A coherent series from `state`, which it leaves as the last pose left it. The warm-up runs on a copy,
/// so `state` continues as if there had been none.
void timed_coherent_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                           CoherentQueryRef query, CoherentState& state);

/// Every pose from its own state (states[i] for poses[i]); the warm-up runs on copies of the first states.
/// Throws std::invalid_argument unless there is one state per pose.
void timed_per_pose_series(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                           CoherentQueryRef query, std::span<CoherentState> states);

}  // namespace bvhlab
