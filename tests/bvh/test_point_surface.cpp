// The implicit surface of a point cloud: sign and distance on a sphere and a plane, sphere coverings, and the
// leaf test on crossing and parallel planes.
#include "bvh/point_surface.hpp"

#include "support/random_draws.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace bvhlab {
namespace {

using testing::draw_vec3;

/// A UV sphere of radius 1 about the origin, triangles turned outward.
Mesh uv_sphere(int rings, int segments) {
  Mesh m;
  m.name = "sphere";
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double theta = std::numbers::pi * i / rings, phi = 2 * std::numbers::pi * j / segments;
      m.vertices.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
    }
  auto v = [&](int i, int j) { return std::uint32_t(i * segments + (j % segments)); };
  auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    const Vec3 n = (m.vertices[b] - m.vertices[a]).cross(m.vertices[c] - m.vertices[a]);
    if (n.squaredNorm() == 0) return;  // the poles' slivers
    if (n.dot(m.vertices[a] + m.vertices[b] + m.vertices[c]) < 0) std::swap(b, c);
    m.triangles.push_back({a, b, c});
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      add(v(i, j), v(i + 1, j), v(i + 1, j + 1));
      add(v(i, j), v(i + 1, j + 1), v(i, j + 1));
    }
  return m;
}

/// An n x n grid of points with the given spacing in the plane z = 0, normals +z.
PointCloud plane_grid(int n, double spacing) {
  PointCloud c;
  c.name = "plane";
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      c.positions.emplace_back(i * spacing, j * spacing, 0);
      c.normals.emplace_back(0, 0, 1);
    }
  return c;
}

std::vector<Vec3> directions(int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;  // a test's own inputs: need not match across platforms
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) out.push_back(draw_vec3(g, rng).normalized());
  return out;
}

void expect_sphere_sign_and_distance(const PointSurface& s, const char* what) {
  // Spacing about sqrt(4 pi / 3000) = 0.065, kernel radius about 0.12. Averaging over a curved patch pulls
  // a(x) inward, which shifts the zero set outward by some h^2 / (2R): measured up to 0.012 here.
  for (const Vec3& u : directions(200, 5))
    for (double delta : {-0.08, -0.03, 0.03, 0.08}) {
      const std::optional<double> f = s.value((1 + delta) * u);
      ASSERT_TRUE(f.has_value()) << what << " at distance " << delta;
      EXPECT_EQ(*f > 0, delta > 0) << what << " at distance " << delta << ": f = " << *f;
      EXPECT_NEAR(*f, delta, 0.02) << what;
    }
  EXPECT_FALSE(s.value(Vec3::Zero()).has_value()) << what << ": the centre is far from every point";
  EXPECT_FALSE(s.value(Vec3(3, 0, 0)).has_value()) << what;
}

TEST(PointSurface, SphereSignIsInsideOutsideAndValueIsTheDistance) {
  const PointCloud cloud = sample_uniform(uv_sphere(48, 96), 3000, 9);
  expect_sphere_sign_and_distance(PointSurface(cloud), "with normals");
  PointCloud bare = cloud;
  bare.normals.clear();
  const PointSurface estimated(bare);
  expect_sphere_sign_and_distance(estimated, "estimated normals");
  for (std::size_t i = 0; i < bare.size(); ++i)
    ASSERT_GT(estimated.normals()[i].dot(cloud.normals[i]), 0.9) << "estimated normal " << i;
}

TEST(PointSurface, PlaneValueIsTheHeight) {
  const PointSurface s(plane_grid(21, 0.05));
  for (double z : {-0.1, -0.01, 0.0, 0.02, 0.1})
    for (const Vec3& xy : {Vec3(0.5, 0.5, 0), Vec3(0.33, 0.71, 0), Vec3(0.02, 0.9, 0)}) {
      const auto f = s.value(xy + Vec3(0, 0, z));
      ASSERT_TRUE(f.has_value());
      EXPECT_NEAR(*f, z, 1e-9);
    }
  EXPECT_FALSE(s.value(Vec3(0.5, 0.5, 2)).has_value());
}

TEST(PointSurface, RefusesCloudsTheKernelCannotUse) {
  PointCloud few = plane_grid(3, 0.1);  // 9 points, k = 10 needs 11
  try {
    PointSurface s(few);
    ADD_FAILURE() << "accepted 9 points for k = 10";
  } catch (const PointCloudError& e) {
    EXPECT_NE(std::string(e.what()).find("has 9 points, the kernel needs at least 11"), std::string::npos)
        << e.what();
  }
  PointCloud same;
  same.positions.assign(20, Vec3(1, 1, 1));
  EXPECT_THROW(PointSurface{same}, PointCloudError);
  PointCloud nan = plane_grid(5, 0.1);
  nan.positions[7].x() = std::nan("");
  EXPECT_THROW(PointSurface{nan}, PointCloudError);
  EXPECT_THROW(PointSurface(plane_grid(5, 0.1), PointSurfaceOptions{.k = 0}), std::invalid_argument);
}

TEST(PointSurface, CoveringsCoverEveryPointOfTheirNode) {
  const PointCloud cloud = sample_uniform(uv_sphere(24, 48), 2000, 3);
  const PointSurface s(cloud);
  const auto tree = Bvh<Aabb>::build(cloud);
  const auto coverings = sphere_coverings(tree, s);
  ASSERT_EQ(coverings.size(), tree.nodes().size());
  const auto ranges = node_triangle_ranges(tree.nodes());
  for (std::size_t i = 0; i < coverings.size(); ++i) {
    const SphereCovering& c = coverings[i];
    ASSERT_GE(c.count, 1u);
    ASSERT_LE(c.count, SphereCovering::kCoverSpheres);
    EXPECT_GT(c.margin, 0);
    for (std::uint32_t p = ranges[i].first; p < ranges[i].second; ++p) {
      double nearest = INFINITY;
      for (std::uint32_t k = 0; k < c.count; ++k)
        nearest = std::min(nearest, (tree.points()[p] - c.centres[k]).norm());
      ASSERT_LE(nearest, c.radius) << "node " << i << ", point " << p;
    }
  }
  // More than one ball on a large node covers it more tightly than one ball around its first point.
  EXPECT_LT(coverings[0].radius, 2.0);
}

/// Runs the leaf test on every leaf pair whose coverings (with margins) come within reach.
struct Pairs {
  std::size_t tested = 0, crossing = 0;
  std::optional<double> distance;
};
Pairs test_all_leaves(const PointCloud& a, const PointCloud& b, const RigidTransform& b_to_a) {
  const PointSurface sa(a), sb(b);
  const auto ta = Bvh<Aabb>::build(a), tb = Bvh<Aabb>::build(b);
  const auto ca = sphere_coverings(ta, sa), cb = sphere_coverings(tb, sb);
  Pairs out;
  for (std::uint32_t i = 0; i < ta.nodes().size(); ++i) {
    if (!ta.node(i).is_leaf()) continue;
    for (std::uint32_t j = 0; j < tb.nodes().size(); ++j) {
      if (!tb.node(j).is_leaf()) continue;
      bool near = false;
      const double reach = ca[i].radius + ca[i].margin + cb[j].radius + cb[j].margin;
      for (std::uint32_t x = 0; x < ca[i].count; ++x)
        for (std::uint32_t y = 0; y < cb[j].count; ++y)
          near = near || (ca[i].centres[x] - b_to_a.apply(cb[j].centres[y])).norm() <= reach;
      if (!near) continue;
      const LeafSurfaceTest r = test_leaf_surfaces(sa, node_points(ta, i), sb, node_points(tb, j), b_to_a);
      ++out.tested;
      if (r.crossing) ++out.crossing;
      if (r.distance && (!out.distance || *r.distance < *out.distance)) out.distance = r.distance;
    }
  }
  return out;
}

TEST(PointSurface, LeafTestFindsCrossingPlanes) {
  const double spacing = 0.05;
  const PointCloud plane = plane_grid(21, spacing);  // [0, 1]^2 at z = 0
  // B stood up (rotated 90 degrees about x) through y = 0.5, reaching from z = -0.5 to 0.5.
  RigidTransform pose;
  pose.rotation = Eigen::AngleAxisd(std::numbers::pi / 2, Vec3::UnitX()).toRotationMatrix();
  pose.translation = Vec3(0.013, 0.5, -0.5);
  const Pairs r = test_all_leaves(plane, plane, pose);
  EXPECT_GT(r.tested, 0u);
  EXPECT_GT(r.crossing, 0u);
}

TEST(PointSurface, LeafTestSeesParallelPlanesApartAndTheirDistance) {
  const double spacing = 0.05;
  const PointCloud plane = plane_grid(21, spacing);
  for (double gap : {3 * spacing, 4 * spacing}) {
    const Pairs r = test_all_leaves(plane, plane, RigidTransform::translate(Vec3(0.011, 0.023, gap)));
    EXPECT_GT(r.tested, 0u) << gap;
    EXPECT_EQ(r.crossing, 0u) << gap;
    ASSERT_TRUE(r.distance.has_value()) << gap;
    EXPECT_NEAR(*r.distance, gap, 1e-6) << gap;
  }
  // Far apart: the leaves never come within reach, or f is nowhere defined.
  const Pairs far = test_all_leaves(plane, plane, RigidTransform::translate(Vec3(0, 0, 5)));
  EXPECT_EQ(far.crossing, 0u);
  EXPECT_FALSE(far.distance.has_value());
}

}  // namespace
}  // namespace bvhlab
