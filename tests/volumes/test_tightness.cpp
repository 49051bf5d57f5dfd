// Tightness report: how much space each model wastes around real meshes' triangles, per tree depth, against
// the AABB and the convex hull of the same triangles. Printed and recorded as test properties; the only
// assertions are sanity bounds (a volume holds its points, so it cannot be smaller than their hull).
#include "bvh/bvh.hpp"
#include "bvh/mesh_io.hpp"
#include "convex_hull_volume.hpp"
#include "support/meshes.hpp"
#include "volume_models.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>

namespace bvhlab::volume_tests {
namespace {

constexpr std::uint32_t kDepths[] = {0, 3, 6, 9, 12};

/// The triangles' vertices of every node at the reported depths, of one AABB-built topology per mesh, so
/// every model is fitted to the same point sets; with the hull volume of each set.
struct NodeSets {
  std::string mesh;
  std::map<std::uint32_t, std::vector<std::vector<Vec3>>> points;  // depth -> nodes
  std::map<std::uint32_t, double> hull_volume;                     // depth -> sum over nodes
};

const std::vector<NodeSets>& node_sets() {
  static const std::vector<NodeSets> sets = [] {
    std::vector<NodeSets> out;
    for (const char* file : {"pinion.off", "jeep1.ms3d", "teapot.obj"}) {
      Mesh mesh = load_mesh(testing::bundled_mesh(file)).mesh;
      normalize_to_unit_cube(mesh);
      BuildOptions options;
      options.split = SplitMethod::Median;
      options.threads = 1;
      const auto tree = Bvh<Aabb>::build(mesh, options);
      const auto ranges = node_triangle_ranges(tree.nodes());
      NodeSets sets{mesh.name, {}, {}};
      std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 0}};  // node, depth
      while (!stack.empty()) {
        const auto [i, depth] = stack.back();
        stack.pop_back();
        if (std::find(std::begin(kDepths), std::end(kDepths), depth) != std::end(kDepths)) {
          std::vector<Vec3> pts;
          for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t)
            pts.insert(pts.end(), tree.triangles()[t].begin(), tree.triangles()[t].end());
          sets.hull_volume[depth] += convex_hull_volume(pts);
          sets.points[depth].push_back(std::move(pts));
        }
        if (!tree.node(i).is_leaf()) {
          stack.push_back({tree.node(i).left(), depth + 1});
          stack.push_back({tree.node(i).right(), depth + 1});
        }
      }
      out.push_back(std::move(sets));
    }
    return out;
  }();
  return sets;
}

/// One model's volume ratios at every reported depth of every mesh, printed as one line per mesh and
/// recorded as test properties.
template <class BV>
void report_volume_ratios() {
  for (const NodeSets& sets : node_sets()) {
    std::string line = std::string(BV::name()) + " on " + sets.mesh + ":";
    for (const auto& [depth, nodes] : sets.points) {
      double bv_volume = 0, aabb_volume = 0;
      for (const auto& pts : nodes) {
        const BV v = BV::fit(pts);
        bv_volume += v.volume();
        aabb_volume += Aabb::fit(pts).volume();
        ASSERT_GE(v.volume(), 0) << BV::name();
      }
      const double hull = sets.hull_volume.at(depth);
      // A volume holding the points holds their hull (up to float rounding of the stored volume).
      EXPECT_GE(bv_volume, hull * (1 - 1e-5)) << BV::name() << " on " << sets.mesh << " depth " << depth;
      char cell[128];
      std::snprintf(cell, sizeof cell, "  d%u (%zu nodes) /aabb %.3f /hull %.3f", depth, nodes.size(),
                    bv_volume / aabb_volume, hull > 0 ? bv_volume / hull : 0.0);
      line += cell;
      const std::string key = std::string(BV::name()) + "_" + sets.mesh + "_depth" + std::to_string(depth);
      ::testing::Test::RecordProperty(key + "_over_aabb", std::to_string(bv_volume / aabb_volume));
      ::testing::Test::RecordProperty(key + "_over_hull", std::to_string(hull > 0 ? bv_volume / hull : 0.0));
    }
    std::printf("%s\n", line.c_str());
  }
}

template <class... BV>
void report_volume_ratios(::testing::Types<BV...>) {
  (report_volume_ratios<BV>(), ...);
}

// One test for every model, not a typed test: ctest runs each test in a process of its own, and the hulls
// (thousands of CGAL hulls, most of the time, 20 s under ASan) would be computed again for every model.
TEST(Tightness, VolumeRatiosOfEveryModelOnBundledMeshes) {
  report_volume_ratios(AllModels{});
}

}  // namespace
}  // namespace bvhlab::volume_tests
