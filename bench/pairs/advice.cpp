#include "bench/pairs/advice.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace bvhlab {
namespace {

double thick_volume(const Mesh& mesh) {
  const Vec3 extent = mesh.bounds().extent();
  const double floor = 1e-3 * std::max(1e-300, double(extent.maxCoeff()));
  return std::max(double(extent.x()), floor) * std::max(double(extent.y()), floor) *
         std::max(double(extent.z()), floor);
}

}  // namespace

double root_volume_ratio(const Mesh& a, const Mesh& b) {
  if (a.vertices.empty() || b.vertices.empty()) return 1;
  const double va = thick_volume(a), vb = thick_volume(b);
  return std::max(va, vb) / std::min(va, vb);
}

std::string size_advice(std::string_view strategy, const std::string& pair, const Mesh& a, const Mesh& b) {
  if (strategy != "adb" && strategy != "adb_dfs") return "";
  const double ratio = root_volume_ratio(a, b);
  if (!(ratio > kSizeRatioForLarger)) return "";
  return fmt::format(
      "`{}` on {}: the objects' root volumes differ by {:.0f}×. `{}` splits both nodes of a pair, so the "
      "small object's tree is opened against every level of the large one's; `adb_larger` splits only the "
      "larger node, as the exact traversal does, and is made for this case (measured on jeep1 against "
      "dragon_11k, longest sides 100× apart, OBB trees: 2,404 BV tests per query for `adb`, 17 for "
      "`adb_larger`; adb/README.md, \"Splitting the larger node\").",
      strategy, pair, ratio, strategy);
}

std::string root_round_advice(const RootRoundShortfall& s) {
  if (s.untested == 0) return "";
  auto missed = [](std::size_t n, std::size_t of) {
    return of ? fmt::format("{:.1f}%", 100.0 * double(n) / double(of)) : std::string("none");
  };
  std::string text = fmt::format(
      "`{}` on {}: in {} of {} frames the budget ended before every candidate pair had its root test: {} of "
      "{} candidate pairs had no test at all and were answered without one ({} of them collide in truth); "
      "the series missed {} of the colliding pairs. No schedule can rank a pair it has not tested once, and "
      "the root round tests the pairs in the broad phase's order, so the same pairs go untested frame after "
      "frame. A frame of n candidate pairs needs n BV tests before the first expansion; this run's frames "
      "had up to {}: give the frame {}.",
      s.series, s.hierarchy, s.frames_short, s.frames, s.untested, s.candidates, s.untested_colliding,
      missed(s.missed, s.colliding), s.most_candidates,
      s.counts_tests
          ? fmt::format("at least {} BV tests", s.most_candidates)
          : fmt::format("a deadline that covers {} root tests and the frame's set-up", s.most_candidates));
  if (!s.covered_series.empty())
    text += fmt::format(" Measured in this run: `{}`, which covered every root round, missed {}.",
                        s.covered_series, missed(s.covered_missed, s.covered_colliding));
  return text;
}

}  // namespace bvhlab
