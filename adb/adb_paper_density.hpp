// AdbPaperDensity ("adb_paper"): the ADB cell counts read by the paper's literal rule, kept beside the
// default "adb" so that the two can be compared in one run. A node whose count is 0 gives the probability 0,
// and differently sized nodes are counted on the coarser node's cells (adb/model.hpp, AdbRule). The saved
// bytes are those of "adb"; only the name and the estimate differ.
#pragma once

#include "adb_density.hpp"

namespace bvhlab {

struct PaperAdbVariant {
  static constexpr std::string_view name = "adb_paper";
  static constexpr AdbRule rule = kAdbPaperRule;
};
using AdbPaperDensity = BasicAdbDensity<PaperAdbVariant>;
static_assert(ProbabilityDensity<AdbPaperDensity>);

}  // namespace bvhlab
