#include "bench/advice.hpp"

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

}  // namespace bvhlab
