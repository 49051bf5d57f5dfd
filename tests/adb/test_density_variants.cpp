// The ADB density variants beside "adb": "adb_paper" (same counts, the paper's rule) and "adb_normal" (the
// counts plus each node's normal axis and flatness).
#include "adb/adb_normal_density.hpp"
#include "adb/adb_paper_density.hpp"
#include "adb/saved_tree.hpp"
#include "support/generated_meshes.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bvhlab {
namespace {

Mesh square_in_plane(const Vec3& u, const Vec3& v) {
  return {{-u - v, u - v, u + v, -u + v}, {{0, 1, 2}, {0, 2, 3}}, "square"};
}

TEST(AdbNormal, AFlatNodeHasItsNormalAsAxisAndFlatnessOne) {
  const Mesh square = square_in_plane(Vec3(1, 0, 0), Vec3(0, 1, 1).normalized());
  const Bvh<Aabb> bvh = Bvh<Aabb>::build(square);
  const auto orientation = node_orientations(node_triangle_ranges(bvh.nodes()), bvh.triangles());
  ASSERT_EQ(orientation.size(), bvh.nodes().size());
  const Eigen::Vector3f normal = Vec3(0, -1, 1).normalized().cast<float>();
  for (const NodeOrientation& o : orientation) {
    EXPECT_NEAR(std::abs(o.axis.dot(normal)), 1.0f, 1e-5f);
    EXPECT_NEAR(o.flatness, 1.0f, 1e-5f);
  }
}

TEST(AdbNormal, AClosedSurfaceSpreadsItsNormals) {
  const Mesh torus = testing::make_torus(1.0, 0.3, 48, 24);
  const Bvh<Aabb> bvh = Bvh<Aabb>::build(torus);
  const auto orientation = node_orientations(node_triangle_ranges(bvh.nodes()), bvh.triangles());
  EXPECT_LT(orientation[0].flatness, 0.3f);  // the root holds normals in every direction
  EXPECT_NEAR(orientation[0].axis.norm(), 1.0f, 1e-5f);
  // Leaves (one triangle each) are flat.
  for (std::size_t i = 0; i < bvh.nodes().size(); ++i)
    if (bvh.nodes()[i].is_leaf()) {
      EXPECT_NEAR(orientation[i].flatness, 1.0f, 1e-5f);
    }
}

TEST(AdbNormal, ParallelSheetsAreLessLikelyThanCrossingOnes) {
  AnnotateOptions options;
  options.threads = 1;
  const Mesh flat = square_in_plane(Vec3(1, 0, 0), Vec3(0, 1, 0));
  const auto params = density_params<AdbNormalDensity>({{"grid", 2}, {"tau", 0.25}});
  const auto a = annotate_tree<AdbNormalDensity>(Bvh<Aabb>::build(flat), params, {1, {}});
  const auto plain = annotate_adb(Bvh<Aabb>::build(flat), 2, options);
  const Box box{Vec3(-1, -1, -0.01), Vec3(1, 1, 0.01)};
  const double overlap = box.volume() / 2;
  const double adb = AdbDensity::estimator(plain.density, plain.density)(0, box, 0, box, overlap);
  ASSERT_GT(adb, 0.0);
  const auto parallel = AdbNormalDensity::estimator(a.density, a.density, Mat3::Identity());
  EXPECT_NEAR(parallel(0, box, 0, box, overlap), adb * AdbNormalDensity::kMinParallelFactor, 1e-12);
  const Mat3 quarter_turn = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()).toRotationMatrix();
  const auto crossing = AdbNormalDensity::estimator(a.density, a.density, quarter_turn);
  EXPECT_NEAR(crossing(0, box, 0, box, overlap), adb, 1e-12);
  // Without a pose the orientation is not used.
  EXPECT_NEAR(AdbNormalDensity::estimator(a.density, a.density)(0, box, 0, box, overlap), adb, 1e-12);
}

TEST(AdbNormal, SavedTreesRoundTripAndBadOrientationsAreRefused) {
  const auto params = density_params<AdbNormalDensity>({{"grid", 3}, {"tau", 0.25}});
  const auto tree = annotate_tree<AdbNormalDensity>(Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 12, 6)),
                                                    params, {1, {}});
  const auto bytes = save_tree_to_buffer(tree);
  const auto loaded = load_tree_from_buffer<Aabb, AdbNormalDensity>(bytes, "t.tree");
  EXPECT_EQ(loaded.density.counts.possible_collision_cells, tree.density.counts.possible_collision_cells);
  ASSERT_EQ(loaded.density.orientation.size(), tree.density.orientation.size());
  for (std::size_t i = 0; i < tree.density.orientation.size(); ++i) {
    EXPECT_EQ(loaded.density.orientation[i].axis, tree.density.orientation[i].axis);
    EXPECT_EQ(loaded.density.orientation[i].flatness, tree.density.orientation[i].flatness);
  }
  auto encoded = AdbNormalDensity::encode(tree.density);
  const std::size_t nodes = tree.bvh.nodes().size();
  encoded[encoded.size() - 1] = std::byte{0x7f};  // the last flatness becomes a huge or NaN float
  EXPECT_THROW(AdbNormalDensity::decode(encoded, nodes), std::invalid_argument);
  EXPECT_THROW(AdbNormalDensity::decode(std::span(encoded).first(10), nodes), std::invalid_argument);
}

TEST(AdbPaper, SameCountsAsAdbAndItsOwnName) {
  AnnotateOptions options;
  options.threads = 1;
  const auto adb = annotate_adb(Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 12, 6)), 2, options);
  const auto paper = annotate_tree<AdbPaperDensity>(Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 12, 6)),
                                                    density_params<AdbPaperDensity>({}), {1, {}});
  EXPECT_EQ(paper.density.possible_collision_cells, adb.density.possible_collision_cells);
  EXPECT_EQ(AdbPaperDensity::describe(paper.density), "adb_paper grid=2 tau=0.25");
  EXPECT_EQ(AdbPaperDensity::encode(paper.density), AdbDensity::encode(adb.density));
}

}  // namespace
}  // namespace bvhlab
