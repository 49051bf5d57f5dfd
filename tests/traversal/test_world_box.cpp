// World boxes (traversal/broad_phase/world_box.hpp) against every transformed vertex, never larger than the
// root's rotated bounding box, and the k-DOP root's exact support from its vertices.
#include "bench/core/generators.hpp"
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"
#include "support/random_draws.hpp"
#include "support/volume_lists.hpp"
#include "traversal/broad_phase/world_box.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace bvhlab {
namespace {

using testing::draw_quaternion;

// World boxes: every transformed vertex inside, never larger than the root's rotated bounding box.

template <class BV>
class WorldBox : public ::testing::Test {};
TYPED_TEST_SUITE(WorldBox, testing::TraversalTestVolumes);

// The rotated bounding box, computed independently: the AABB of its eight transformed corners.
Box rotated_corners(const Box& local, const RigidTransform& pose) {
  Box out;
  for (int k = 0; k < 8; ++k)
    out.extend(pose.apply(Vec3(k & 1 ? local.max.x() : local.min.x(), k & 2 ? local.max.y() : local.min.y(),
                               k & 4 ? local.max.z() : local.min.z())));
  return out;
}

RigidTransform random_rigid(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> normal;
  const Eigen::Quaterniond q = draw_quaternion(normal, rng);
  RigidTransform pose;
  pose.rotation = q.normalized().toRotationMatrix();
  pose.translation = generators::uniform_point(rng, -reach, reach);
  return pose;
}

TYPED_TEST(WorldBox, ContainsEveryTransformedVertexAndIsNoLargerThanTheRotatedRootBox) {
  using BV = TypeParam;
  std::vector<Mesh> meshes = {generators::make_torus(3, 1, 24, 12), generators::make_box(5, 10, 20),
                              generators::make_cylinder(10, 40, 16)};
  for (auto& v : meshes[0].vertices) v += Vec3(7, -2, 1);  // off-centre
  std::mt19937_64 rng(17);
  for (const Mesh& mesh : meshes) {
    const auto tree = Bvh<BV>::build(mesh);
    const Box local = tree.root_volume().bounding_box();
    for (int k = 0; k < 40; ++k) {
      const RigidTransform pose = random_rigid(rng, k < 20 ? 10.0 : 1e4);
      const Box world = world_box(tree, pose);
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(world.contains(pose.apply(v)))
            << mesh.name << ", pose " << k << ": vertex " << pose.apply(v).transpose() << " outside ["
            << world.min.transpose() << "] - [" << world.max.transpose() << "]";
      // With the bounding ball: still every vertex, and never larger than without it.
      const Box balled = world_box(tree, pose, bounding_ball(tree));
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(balled.contains(pose.apply(v))) << mesh.name << ", pose " << k << " (with the ball)";
      EXPECT_TRUE((balled.min.array() >= world.min.array()).all() &&
                  (balled.max.array() <= world.max.array()).all());
      // With the root bounds (a k-DOP root's vertices): still every vertex, and no looser than with the
      // ball alone but for the vertices' slack (a few 1e-9 of the root's size).
      const RootBounds bounds = root_bounds(tree);
      const Box bounded = world_box(tree, pose, bounds);
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(bounded.contains(pose.apply(v))) << mesh.name << ", pose " << k << " (root bounds)";
      const double slack = 1e-8 * (local.extent().maxCoeff() + local.center().norm());
      EXPECT_TRUE((bounded.min.array() >= balled.min.array() - slack).all() &&
                  (bounded.max.array() <= balled.max.array() + slack).all())
          << mesh.name << ", pose " << k;
      const Box reference = rotated_corners(local, pose);
      const double tolerance =
          1e-9 * (reference.extent().maxCoeff() + pose.translation.cwiseAbs().maxCoeff());
      EXPECT_TRUE((world.min.array() >= reference.min.array() - tolerance).all() &&
                  (world.max.array() <= reference.max.array() + tolerance).all())
          << mesh.name << ", pose " << k;
    }
  }
}

// A DOP of the prototype's own shape: the support bound is exact there, so both sides of every world axis
// must meet the rotated prototype's extreme vertices (the lower side comes from the upper side's search).
TEST(WorldBox, DopOfThePrototypeShapeGivesTheExactRotatedBox) {
  using Dop = KDop<dop_sets::Zachmann24>;
  std::vector<Vec3> corners;
  for (const auto& vertex : Dop::tables().vertices) corners.push_back(vertex.position);
  const Dop prototype = Dop::fit(corners);
  std::mt19937_64 rng(5);
  for (int k = 0; k < 50; ++k) {
    const RigidTransform pose = random_rigid(rng, 10.0);
    Box exact;
    for (const Vec3& c : corners) exact.extend(pose.apply(c));
    const Box world = world_box(prototype, pose);
    // Offsets are floats rounded upwards: a few 1e-7 of the prototype's size of about 1.
    EXPECT_LT((world.max - exact.max).cwiseAbs().maxCoeff(), 1e-5) << "pose " << k;
    EXPECT_LT((world.min - exact.min).cwiseAbs().maxCoeff(), 1e-5) << "pose " << k;
  }
}

// The DOP's vertices by brute force, independently of dop_vertices: every triple of its planes solved by a
// pivoting QR, the points inside every half-space kept, no merging.
template <class Set>
std::vector<Vec3> brute_force_dop_vertices(const KDop<Set>& dop) {
  constexpr std::size_t kAxes = KDop<Set>::kAxes;
  std::vector<Vec3> normals;
  for (const auto& raw : Set::set.raw) normals.push_back(Vec3(raw[0], raw[1], raw[2]).normalized());
  for (std::size_t a = 0; a < kAxes; ++a) normals.push_back(-normals[a]);
  double scale = 0;
  for (const float d : dop.offsets) scale = std::max(scale, std::abs(double(d)));
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < normals.size(); ++i)
    for (std::size_t j = i + 1; j < normals.size(); ++j)
      for (std::size_t l = j + 1; l < normals.size(); ++l) {
        Mat3 m;
        m << normals[i].transpose(), normals[j].transpose(), normals[l].transpose();
        const auto qr = m.colPivHouseholderQr();
        if (qr.rank() < 3) continue;
        const Vec3 x = qr.solve(Vec3(dop.offsets[i], dop.offsets[j], dop.offsets[l]));
        bool inside = true;
        for (std::size_t q = 0; q < normals.size(); ++q)
          inside = inside && normals[q].dot(x) <= double(dop.offsets[q]) + 1e-9 * scale;
        if (inside) out.push_back(x);
      }
  return out;
}

// The world box from the DOP's vertices, against the points the DOP was fitted to, the LP bound, and the
// brute-force vertices, under random rotations.
template <class Set>
void expect_exact_dop_support(const std::vector<Vec3>& points, const std::string& label,
                              std::mt19937_64& rng) {
  const KDop<Set> dop = KDop<Set>::fit(points);
  const DopVertices vertices = dop_vertices(dop);
  ASSERT_FALSE(vertices.empty()) << label;
  const std::vector<Vec3> brute = brute_force_dop_vertices(dop);
  ASSERT_FALSE(brute.empty()) << label;
  double size = 0;
  for (const Vec3& p : points) size = std::max(size, p.cwiseAbs().maxCoeff());
  for (int k = 0; k < 30; ++k) {
    const RigidTransform pose = random_rigid(rng, k < 15 ? 10.0 : 1e4);
    const Box box = world_box(vertices, pose);
    for (const Vec3& p : points)
      ASSERT_TRUE(box.contains(pose.apply(p)))
          << label << ", pose " << k << ": " << pose.apply(p).transpose();
    Box exact;
    for (const Vec3& v : brute) exact.extend(pose.apply(v));
    const Box lp = world_box(dop, pose);
    const double tolerance = 1e-7 * (size + pose.translation.cwiseAbs().maxCoeff()) + 1e-12;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(box.max[axis], exact.max[axis], tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_NEAR(box.min[axis], exact.min[axis], tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_LE(box.max[axis], lp.max[axis] + tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_GE(box.min[axis], lp.min[axis] - tolerance) << label << ", pose " << k << ", axis " << axis;
    }
  }
}

std::vector<std::pair<std::string, std::vector<Vec3>>> dop_test_point_sets() {
  std::vector<std::pair<std::string, std::vector<Vec3>>> sets;
  for (const char* file : {"pinion.off", "jeep1.ms3d", "teapot.obj"})
    sets.emplace_back(file, load_mesh(testing::bundled_mesh(file)).mesh.vertices);
  std::vector<Vec3> torus = generators::make_torus(3, 1, 24, 12).vertices;
  for (auto& v : torus) v += Vec3(7, -2, 1);
  sets.emplace_back("off-centre torus", torus);
  // Degenerate DOPs: flat (equal offsets on the opposite z planes), a tilted triangle, a segment, points.
  sets.emplace_back("flat quad", std::vector<Vec3>{{-1, -2, 0.5}, {3, -2, 0.5}, {3, 1, 0.5}, {-1, 1, 0.5}});
  sets.emplace_back("tilted triangle",
                    std::vector<Vec3>{{0.3, 1.7, -2.2}, {4.1, -0.6, 0.9}, {-1.3, 2.2, 3.5}});
  sets.emplace_back("segment", std::vector<Vec3>{{1, 2, 3}, {-2, 0.5, 7}});
  sets.emplace_back("point", std::vector<Vec3>{{2.5, -1.25, 4}});
  sets.emplace_back("origin", std::vector<Vec3>{Vec3::Zero()});
  return sets;
}

TEST(WorldBox, DopVerticesGiveTheExactSupportOfTheRotatedDop) {
  std::mt19937_64 rng(23);
  for (const auto& [label, points] : dop_test_point_sets()) {
    expect_exact_dop_support<dop_sets::Zachmann24>(points, label + " (24-DOP)", rng);
    // The 14-DOP's corners join more than three planes: many triples meet in one vertex.
    expect_exact_dop_support<dop_sets::Dop14>(points, label + " (14-DOP)", rng);
  }
}

TEST(WorldBox, DopVerticesOnlyForDopRootsAndNoneForAnEmptyDop) {
  const Mesh box = generators::make_box(5, 10, 20);
  EXPECT_FALSE(root_bounds(Bvh<Dop24>::build(box)).dop.empty());
  EXPECT_TRUE(root_bounds(Bvh<Aabb>::build(box)).dop.empty());
  EXPECT_TRUE(dop_vertices(Dop24{}).empty());
  EXPECT_TRUE(world_box(dop_vertices(Dop24{}), RigidTransform{}).empty());
}

TEST(WorldBox, AabbRootUnder45DegreesIsTighterThanTheCubeAroundItsSphere) {
  const auto tree = Bvh<Aabb>::build(generators::make_box(5, 10, 20));
  RigidTransform pose;
  pose.rotation = Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()).toRotationMatrix();
  pose.translation = Vec3(100, -50, 3);
  const Box world = world_box(tree, pose);
  const Box local = tree.root_volume().bounding_box();
  const double radius = local.extent().norm() / 2;  // the box's circumscribed sphere
  for (int k = 0; k < 3; ++k) EXPECT_LT(world.extent()[k], 2 * radius * 0.9) << "axis " << k;
  // A round object in an Aabb tree: its bounding ball cuts the rotated root box down to the sphere's cube.
  const auto round = Bvh<Aabb>::build(generators::make_sphere(30, 16, 16));
  RigidTransform tilted = pose;
  tilted.rotation = Eigen::AngleAxisd(0.6, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  const Box rotated = world_box(round, tilted), balled = world_box(round, tilted, bounding_ball(round));
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(balled.extent()[k], 60 * (1 + 1e-9)) << "axis " << k;
    EXPECT_GT(rotated.extent()[k], 60 * 1.05) << "axis " << k;
  }
  // And a sphere root really is a sphere: centre and radius, not its rotated bounding box.
  const auto ball = Bvh<Sphere>::build(generators::make_sphere(30, 16, 16));
  const Box ball_box = world_box(ball, pose);
  EXPECT_NEAR(ball_box.extent().x(), 2 * ball.root_volume().radius, 1e-6);
}

}  // namespace
}  // namespace bvhlab
