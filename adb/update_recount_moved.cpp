#include "adb/update_recount_moved.hpp"

#include <algorithm>
#include <cmath>

namespace bvhlab {

namespace {

constexpr ParamSpec kRecountMovedParameters[] = {
    {.name = "fraction",
     .description = "a node is recounted when a box corner moved by more than this fraction of its cell "
                    "side since its last count (0: every node)",
     .min = 0,
     .max = 100,
     .default_value = 0.25},
    {.name = "ignore_translation",
     .description = "1: only the motion of the box corners relative to the box centre counts",
     .min = 0,
     .max = 1,
     .default_value = 0,
     .integer = true},
};

bool moved(const Box& then, const Box& now, double fraction, int grid, bool ignore_translation) {
  for (int a = 0; a < 3; ++a) {
    const double limit = fraction * (then.max[a] - then.min[a]) / grid;
    const double shift =
        ignore_translation ? std::abs((now.max[a] - now.min[a]) - (then.max[a] - then.min[a])) / 2
                           : std::max(std::abs(now.min[a] - then.min[a]), std::abs(now.max[a] - then.max[a]));
    if (!(shift <= limit)) return true;  // NaN included
  }
  return false;
}

}  // namespace

std::span<const ParamSpec> RecountMovedUpdate::parameters() {
  return kRecountMovedParameters;
}

RecountMovedUpdate::Params RecountMovedUpdate::make_params(const ParamValues& values) {
  return {parameter(values, "fraction"), parameter(values, "ignore_translation") != 0};
}

std::vector<std::uint32_t> RecountMovedUpdate::moved_nodes(const State& state, std::span<const Box> boxes,
                                                           int grid) {
  std::vector<std::uint32_t> out;
  for (std::uint32_t i = 0; i < boxes.size(); ++i) {
    if (state.ranges[i].first == state.ranges[i].second) continue;
    if (state.params.fraction == 0 ||
        moved(state.counted[i], boxes[i], state.params.fraction, grid, state.params.ignore_translation))
      out.push_back(i);
  }
  return out;
}

}  // namespace bvhlab
