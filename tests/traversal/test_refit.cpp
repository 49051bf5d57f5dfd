// Refitting a tree to a deformed mesh, for every shipped volume: the refitted volumes bound the deformed
// triangles, exact queries answer as CGAL does on the deformed mesh, refused frames change nothing, and the
// degradation measure tells a scaling from a strong deformation.
#include "bench/core/ground_truth.hpp"
#include "bvh/deform.hpp"
#include "support/generated_meshes.hpp"
#include "support/volume_lists.hpp"
#include "traversal/exact.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace bvhlab {
namespace {

template <class BV>
class Refit : public ::testing::Test {};
TYPED_TEST_SUITE(Refit, testing::TraversalTestVolumes);

constexpr RefitMethod kMethods[] = {RefitMethod::Merge, RefitMethod::Fit};
const char* name_of(RefitMethod m) {
  return m == RefitMethod::Merge ? "merge" : "fit";
}

// The small meshes every case runs on: an open cloth and a closed torus lying in the xy plane.
std::vector<Mesh> rest_meshes() {
  return {cloth_grid(12), testing::make_torus(0.7, 0.25, 18, 9)};
}

std::vector<Deformation> deformations() {
  std::vector<Deformation> out;
  for (const char* spec : {"twist:amplitude=3", "bend:amplitude=4", "pulsate:amplitude=0.5",
                           "wave:amplitude=0.15,wavelength=0.3"})
    out.push_back(parse_deformation(spec));
  return out;
}

// Every node's volume (decoded for a hierarchical one) contains every vertex of every triangle below it.
template <class BV>
void expect_bounds_contain_triangles(const Bvh<BV>& tree, const Mesh& deformed, const std::string& what) {
  const auto ranges = node_triangle_ranges(tree.nodes());
  const auto boxes = tree.node_boxes();
  for (std::uint32_t i = 0; i < tree.nodes().size(); ++i)
    for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t) {
      const TrianglePoints tri = deformed.triangle(tree.triangle_ids()[t]);
      ASSERT_EQ(tree.triangles()[t], tri) << what << ": tree triangle " << t;
      for (const Vec3& v : tri) {
        if constexpr (Bvh<BV>::hierarchical) {
          ASSERT_TRUE(boxes[i].contains(v)) << what << ": node " << i;
        } else {
          ASSERT_TRUE(tree.volume(i).contains(v)) << what << ": node " << i << ", triangle " << t;
        }
      }
    }
}

TYPED_TEST(Refit, RefittedVolumesContainTheDeformedTriangles) {
  for (const Mesh& rest : rest_meshes()) {
    auto tree = Bvh<TypeParam>::build(rest);
    for (const Deformation& d : deformations())
      for (RefitMethod method : kMethods)
        for (double t : {0.25, 0.6, 0.9}) {  // several frames in a row on the same tree
          const Mesh moved = deform(rest, d, t);
          tree.refit(moved, method);
          expect_bounds_contain_triangles(
              tree, moved, rest.name + " " + std::string(to_string(d.kind)) + " " + name_of(method));
          if (::testing::Test::HasFatalFailure()) return;
        }
  }
}

// Poses of B against A: random rotated ones (for a DOP they exercise its re-alignment), the identity
// (for A against itself: everything touches), and poses whose B touches A in exactly one vertex.
std::vector<RigidTransform> poses(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<RigidTransform> out{RigidTransform::identity()};
  for (int k = 0; k < 40; ++k) {
    RigidTransform pose = testing::random_pose(rng, 0.9);
    pose.translation += Vec3(0.5, 0.5, 0);  // around the cloth's centre; the torus is centred at 0
    out.push_back(pose);
  }
  return out;
}

// A sliver whose first vertex is A's vertex v and that points away from A's bounds' centre: B at the
// identity pose touches A there (closed triangles), up to whatever else it meets.
Mesh touching_sliver(const Mesh& a, std::size_t v) {
  const Vec3 p = a.vertices[v];
  Vec3 out = p - a.bounds().center();
  out = out.norm() > 0 ? Vec3(out.normalized()) : Vec3(0, 0, 1);
  const Vec3 side = out.unitOrthogonal();
  Mesh m;
  m.name = "sliver";
  m.vertices = {p, p + 0.5 * out + 0.01 * side, p + 0.5 * out - 0.01 * side};
  m.triangles = {{0, 1, 2}};
  return m;
}

template <class BV>
void expect_exact_answers(const Bvh<BV>& refitted, const Mesh& deformed, const Mesh& b,
                          const std::vector<RigidTransform>& pose_list, const std::string& what) {
  const auto tree_b = Bvh<BV>::build(b);
  const auto rebuilt = Bvh<BV>::build(deformed);
  const CgalGroundTruth truth(deformed, b);
  for (std::size_t k = 0; k < pose_list.size(); ++k) {
    const Result r = query_exact(refitted, tree_b, pose_list[k]);
    ASSERT_EQ(r.collides, truth.collides(pose_list[k])) << what << ", pose " << k;
    ASSERT_EQ(r.collides, query_exact(rebuilt, tree_b, pose_list[k]).collides) << what << ", pose " << k;
    if (r.collides) {
      ASSERT_TRUE(r.witness.has_value());
      const auto ta = deformed.triangle(r.witness->a), tb = b.triangle(r.witness->b);
      const auto& p = pose_list[k];
      ASSERT_TRUE(triangles_intersect_exact(ta, {p.apply(tb[0]), p.apply(tb[1]), p.apply(tb[2])}))
          << what << ", pose " << k;
    }
  }
}

TYPED_TEST(Refit, ExactQueriesOnRefittedTreesMatchCgal) {
  const Mesh other = testing::make_torus(0.45, 0.12, 12, 6);  // the rigid second object
  int colliding = 0, poses_run = 0;
  for (const Mesh& rest : rest_meshes()) {
    for (const Deformation& d : deformations())
      for (RefitMethod method : kMethods) {
        auto tree = Bvh<TypeParam>::build(rest);
        const Mesh moved = deform(rest, d, 0.3);
        tree.refit(moved, method);
        const std::string what = rest.name + " " + std::string(to_string(d.kind)) + " " + name_of(method);
        const auto list = poses(7);
        expect_exact_answers(tree, moved, other, list, what + " vs torus");
        expect_exact_answers(tree, moved, moved, {RigidTransform::identity()}, what + " vs itself");
        expect_exact_answers(tree, moved, touching_sliver(moved, moved.vertices.size() / 3),
                             {RigidTransform::identity()}, what + " vs touching sliver");
        if (::testing::Test::HasFatalFailure()) return;
        const CgalGroundTruth truth(moved, other);
        for (const auto& p : list) colliding += truth.collides(p);
        poses_run += static_cast<int>(list.size());
      }
  }
  // The random poses must exercise both answers, or the comparison proves little.
  EXPECT_GT(colliding, poses_run / 10);
  EXPECT_LT(colliding, poses_run * 9 / 10);
}

TYPED_TEST(Refit, RefusedFramesLeaveTheTreeAsItWas) {
  const Mesh rest = cloth_grid(10);
  const Mesh b = testing::make_torus(0.45, 0.12, 12, 6);
  auto tree = Bvh<TypeParam>::build(rest);
  const Mesh moved = deform(rest, parse_deformation("bend:amplitude=2"), 0.25);
  tree.refit(moved);
  const auto tree_b = Bvh<TypeParam>::build(b);
  const auto list = poses(3);
  std::vector<bool> before;
  for (const auto& p : list) before.push_back(query_exact(tree, tree_b, p).collides);
  const auto boxes = tree.node_boxes();
  const auto triangles = tree.triangles();

  auto expect_refused = [&](const Mesh& bad, const std::string& expected) {
    try {
      tree.refit(bad);
      ADD_FAILURE() << "not refused: " << expected;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_EQ(tree.triangles(), triangles) << expected;
    const auto after = tree.node_boxes();
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      ASSERT_EQ(after[i].min, boxes[i].min) << expected;
      ASSERT_EQ(after[i].max, boxes[i].max) << expected;
    }
    for (std::size_t k = 0; k < list.size(); ++k)
      ASSERT_EQ(query_exact(tree, tree_b, list[k]).collides, before[k]) << expected << ", pose " << k;
  };
  Mesh nan = deform(rest, parse_deformation("bend:amplitude=2"), 0.5);
  nan.vertices[17].z() = std::nan("");
  expect_refused(nan, "vertex 17 is not finite");
  Mesh inf = moved;
  inf.vertices.back().x() = -INFINITY;
  expect_refused(inf, "vertex " + std::to_string(inf.vertices.size() - 1) + " is not finite");
  Mesh more = moved;
  more.vertices.emplace_back(0, 0, 0);
  expect_refused(more, "the mesh has 122 vertices, the tree was built over a mesh of 121");
  Mesh fewer_triangles = moved;
  fewer_triangles.triangles.pop_back();
  expect_refused(fewer_triangles, "the mesh has 199 triangles, the tree was built over 200");
  Mesh other_indices = moved;
  std::swap(other_indices.triangles[3][0], other_indices.triangles[3][1]);
  expect_refused(other_indices, "triangle indices differ");
  // The tree still refits to a good frame afterwards.
  const Mesh next = deform(rest, parse_deformation("bend:amplitude=2"), 0.5);
  tree.refit(next);
  expect_bounds_contain_triangles(tree, next, "after refusals");
}

TYPED_TEST(Refit, DegradationStaysOneUnderScalingAndGrowsUnderStrongDeformation) {
  const Mesh rest = cloth_grid(16);
  for (RefitMethod method : kMethods) {
    auto tree = Bvh<TypeParam>::build(rest);
    EXPECT_DOUBLE_EQ(tree.degradation(), 1.0);
    for (double t : {0.25, 0.75}) {
      tree.refit(deform(rest, parse_deformation("pulsate:amplitude=0.6"), t), method);
      EXPECT_NEAR(tree.degradation(), 1.0, 1e-9) << name_of(method) << " t " << t;
    }
    // A tall, short wave: the flat cloth's subtrees each span a whole crest, their leaves a sliver of it.
    tree.refit(deform(rest, parse_deformation("wave:amplitude=0.3,wavelength=0.2"), 0.1), method);
    EXPECT_GT(tree.degradation(), kRebuildDegradation) << name_of(method);
    // Rebuilding on the deformed mesh starts again at 1.
    EXPECT_DOUBLE_EQ(
        Bvh<TypeParam>::build(deform(rest, parse_deformation("wave:amplitude=0.3,wavelength=0.2"), 0.1))
            .degradation(),
        1.0);
  }
}

}  // namespace
}  // namespace bvhlab
