// AdbPaperDensity ("adb_paper"): the ADB cell counts read by the paper's literal rule, kept beside the
// default "adb" so that the two can be compared in one run. A node whose count is 0 gives the probability 0,
// differently sized nodes are counted on the coarser node's cells (adb/model.hpp, AdbRule), and the grid
// lies on each node's bounding box even on OBB trees. The saved bytes have the layout of "adb" (version 1).
#pragma once

#include "adb_density.hpp"

namespace bvhlab {

struct PaperAdbVariant {
  static constexpr std::string_view name = "adb_paper";
  static constexpr AdbRule rule = kAdbPaperRule;
  static constexpr bool cells_in_node_frames = false;  // the grid on the bounding box, on every volume
};
using AdbPaperDensity = BasicAdbDensity<PaperAdbVariant>;
static_assert(ProbabilityDensity<AdbPaperDensity>);

}  // namespace bvhlab
