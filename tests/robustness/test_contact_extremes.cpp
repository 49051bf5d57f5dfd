// Contact at the limit of resolution: exactly touching faces, edges and corners; gaps and penetrations of
// 1e-7; identical meshes exactly overlapping; rotations at and near theta = pi.
//
// Decision (bvh/triangle_intersection.hpp): triangles are closed, so touching counts as colliding. Every
// registered BV and both exact strategies (exact traversal, guided exact) must agree on that; the ADB
// strategies may answer either way for a touching pair but must never claim an exact "no".
#include "bench/core/ground_truth.hpp"
#include "engine/mesh_catalog.hpp"
#include "engine/protocol.hpp"
#include "engine/registry.hpp"
#include "robust_support.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace bvhlab::robust {
namespace {

// Rotations whose entries are 0 and +-1: exactly orthonormal, so the cube's faces stay exactly in place.
std::vector<Mat3> exact_rotations() {
  std::vector<Mat3> out;
  Mat3 m;
  out.push_back(Mat3::Identity());
  m << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // 90 degrees about z
  out.push_back(m);
  m << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // 180 degrees about x
  out.push_back(m);
  m << 0, 0, 1, 1, 0, 0, 0, 1, 0;  // 120 degrees about (1, 1, 1)
  out.push_back(m);
  m << -1, 0, 0, 0, -1, 0, 0, 0, 1;  // 180 degrees about z
  out.push_back(m);
  return out;
}

// Offsets where two cubes [-1, 1]^3 touch in a face, an edge and a corner.
const std::vector<Vec3> kTouchingOffsets = {Vec3(2, 0, 0),  Vec3(-2, 0, 0),  Vec3(0, 2, 0),
                                            Vec3(0, 0, -2), Vec3(2, 2, 0),   Vec3(0, -2, 2),
                                            Vec3(2, 2, 2),  Vec3(-2, 2, -2), Vec3(2, 0.5, 0.25)};

TEST(ContactExtremes, CubesAtExactlyTwoTouchAndCollideForEveryVolumeAndStrategy) {
  const Mesh cube = make_cube();
  int checked = 0;
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(cube);
    for (const Mat3& rotation : exact_rotations())
      for (const Vec3& offset : kTouchingOffsets) {
        const RigidTransform pose{rotation, offset};
        for (Strategy s : kAllStrategies) {
          const Result r = run<BV>(s, tree, tree, pose);
          ASSERT_TRUE(honest(r, true)) << to_string(s) << " at " << offset.transpose();
          if (is_exact(s)) {
            ASSERT_TRUE(r.collides) << to_string(s) << " at " << offset.transpose();
          }
          ++checked;
        }
      }
  });
  EXPECT_GT(checked, 0);
  // The ground truth agrees with the decision on the same poses.
  const CgalGroundTruth truth(cube, cube);
  for (const Vec3& offset : kTouchingOffsets) EXPECT_TRUE(truth.collides(RigidTransform::translate(offset)));
}

TEST(ContactExtremes, CubesOneTenMillionthApartDoNotCollide) {
  const Mesh cube = make_cube();
  const CgalGroundTruth truth(cube, cube);
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(cube);
    for (const Mat3& rotation : exact_rotations())
      for (const Vec3& offset : kTouchingOffsets) {
        // Push B away along every axis in which it touches: a gap of 1e-7 in each.
        const Vec3 apart = offset + 1e-7 * offset.cwiseSign().cwiseProduct(
                                               (offset.cwiseAbs().array() == 2).cast<double>().matrix());
        const RigidTransform pose{rotation, apart};
        ASSERT_FALSE(truth.collides(pose)) << apart.transpose();
        for (Strategy s : kAllStrategies) {
          const Result r = run<BV>(s, tree, tree, pose);
          ASSERT_TRUE(honest(r, false)) << to_string(s) << " at " << apart.transpose();
          if (is_exact(s)) {
            ASSERT_FALSE(r.collides) << to_string(s) << " at " << apart.transpose();
          }
        }
      }
  });
}

// A tilted cube whose lowest vertex is 1e-7 above, or 1e-7 into, the face x = 1 of the other cube.
TEST(ContactExtremes, TiltedCubeAtGapAndPenetrationOfOneTenMillionth) {
  const Mesh cube = make_cube();
  const CgalGroundTruth truth(cube, cube);
  std::mt19937_64 rng(2024);
  int poses = 0;
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(cube);
    std::mt19937_64 local(rng());
    for (int k = 0; k < 40; ++k) {
      RigidTransform pose = testing::random_pose(local, 0.0);
      double min_x = std::numeric_limits<double>::infinity();
      for (const Vec3& v : cube.vertices) min_x = std::min(min_x, (pose.rotation * v).x());
      // The nearest vertex lands on (1 + gap, y, z) with |y|, |z| <= 0.87: inside the face, off its rim.
      const Vec3 nearest = *std::min_element(
          cube.vertices.begin(), cube.vertices.end(),
          [&](const Vec3& p, const Vec3& q) { return (pose.rotation * p).x() < (pose.rotation * q).x(); });
      const Vec3 rotated = pose.rotation * nearest;
      for (double gap : {1e-7, -1e-7}) {
        pose.translation = Vec3(1 + gap - min_x, -rotated.y() * 0.5, -rotated.z() * 0.5);
        const bool expected = gap < 0;
        ASSERT_EQ(truth.collides(pose), expected) << "gap " << gap;
        for (Strategy s : kAllStrategies) {
          const Result r = run<BV>(s, tree, tree, pose);
          ASSERT_TRUE(honest(r, expected)) << to_string(s) << " gap " << gap << " pose " << k;
          if (is_exact(s)) {
            ASSERT_EQ(r.collides, expected) << to_string(s) << " gap " << gap << " pose " << k;
          }
        }
        ++poses;
      }
    }
  });
  EXPECT_GT(poses, 0);
}

// Two needles (aspect ratio 1e6) crossing, touching at the apex, and missing by 1e-7: the closed-triangle
// decision must hold for slivers too, in every BV (whose fits degenerate to nearly flat volumes).
TEST(ContactExtremes, NeedlesCrossTouchAndMiss) {
  auto needle_pair = [](double y) {
    Mesh a, b;
    a.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-6, 0)};
    a.triangles = {{0, 1, 2}};
    b.vertices = {Vec3(0.5, y, -0.5), Vec3(0.5, y, 0.5), Vec3(0.5 + 1e-6, y, 0)};
    b.triangles = {{0, 1, 2}};
    return std::pair{a, b};
  };
  struct Case {
    double y;
    bool collides;
  };
  for (const Case c : {Case{0.25e-6, true}, Case{1e-6, true}, Case{0.0, true}, Case{1.1e-6, false},
                       Case{1e-6 + 1e-13, false}, Case{-1e-13, false}}) {
    const auto needles = needle_pair(c.y);  // not a structured binding: clang 14 cannot capture one
    const Mesh& a = needles.first;
    const Mesh& b = needles.second;
    ASSERT_EQ(CgalGroundTruth(a, b).collides({}), c.collides) << "y " << c.y;
    with_each_volume([&](auto id) {
      using BV = typename decltype(id)::type;
      const auto tree_a = annotated<BV>(a);
      const auto tree_b = annotated<BV>(b);
      for (Strategy s : kAllStrategies) {
        const Result r = run<BV>(s, tree_a, tree_b, {});
        ASSERT_TRUE(honest(r, c.collides)) << BV::name() << " " << to_string(s) << " y " << c.y;
        if (is_exact(s)) {
          ASSERT_EQ(r.collides, c.collides) << BV::name() << " " << to_string(s) << " y " << c.y;
        }
      }
    });
  }
}

TEST(ContactExtremes, IdenticalMeshesExactlyOverlapping) {
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");
  const CgalGroundTruth truth(jeep, jeep);
  auto expected = truth.all_contacts({});
  ASSERT_GE(expected.size(), jeep.triangle_count());  // at least every triangle with itself
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(jeep);
    for (Strategy s : kAllStrategies) {
      Result r = run<BV>(s, tree, tree, {});
      ASSERT_TRUE(honest(r, true)) << to_string(s);
      if (is_exact(s)) {
        EXPECT_TRUE(r.collides) << to_string(s);
      }
      if (s == Strategy::ExactAll) {
        std::sort(r.contacts.begin(), r.contacts.end());
        EXPECT_EQ(r.contacts, expected);
      }
    }
  });
}

// theta = pi makes R_z R_x a half turn about both axes (sin theta = 1.2e-16, not 0); near it the rotation
// matrix's entries pass through 0 with either sign. Exact answers must equal CGAL's on all 9 distances.
TEST(ContactExtremes, RotationsAtAndNearPi) {
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");
  const CgalGroundTruth truth(jeep, jeep);
  const double pi = std::numbers::pi;
  const std::vector<double> thetas = {pi,
                                      std::nextafter(pi, 0.0),
                                      std::nextafter(pi, 4.0),
                                      pi - 1e-12,
                                      pi + 1e-12,
                                      pi - 1e-9,
                                      pi + 1e-9,
                                      pi - 1e-6,
                                      pi + 1e-6};
  int colliding = 0, total = 0;
  with_each_volume([&](auto id) {
    using BV = typename decltype(id)::type;
    SCOPED_TRACE(std::string(BV::name()));
    const auto tree = annotated<BV>(jeep);
    for (double d : ProtocolOptions{}.distances)
      for (double theta : thetas) {
        RigidTransform pose;
        pose.rotation =
            (Eigen::AngleAxisd(theta, Vec3::UnitZ()) * Eigen::AngleAxisd(theta, Vec3::UnitX())).matrix();
        pose.translation = Vec3(d, 0, 0);
        // The protocol's rotations must pass the caller-input check.
        ASSERT_NO_THROW(RigidTransform::checked(pose.rotation, pose.translation));
        const bool expected = truth.collides(pose);
        for (Strategy s : kAllStrategies) {
          const Result r = run<BV>(s, tree, tree, pose);
          ASSERT_TRUE(honest(r, expected)) << to_string(s) << " d " << d << " theta - pi " << theta - pi;
          if (is_exact(s)) {
            ASSERT_EQ(r.collides, expected) << to_string(s) << " d " << d << " theta - pi " << theta - pi;
          }
        }
        colliding += expected;
        ++total;
      }
  });
  // Both answers occur, so the comparison means something.
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, total);
}

}  // namespace
}  // namespace bvhlab::robust
