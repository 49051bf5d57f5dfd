// Transforms a caller gives: a matrix that is not a rotation (non-orthonormal, a reflection, NaN or infinite)
// is refused with an error naming the defect, wherever it enters -- the API's checked constructor, a scene's
// placement, a pose file, a mesh file's node transform. Never a silent wrong answer.
#include "bench/core/scene.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/protocol.hpp"
#include "robust_support.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <fstream>
#include <limits>

namespace bvhlab {
namespace {

namespace fs = std::filesystem;

void expect_refused(const Mat3& r, const Vec3& t, const std::string& defect) {
  try {
    (void)RigidTransform::checked(r, t);
    ADD_FAILURE() << "accepted\n" << r << "\n" << t.transpose();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(defect), std::string::npos) << e.what();
  }
}

TEST(CallerTransforms, CheckedRefusesEveryNonRotation) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  Mat3 r = Mat3::Identity();
  r(1, 2) = nan;
  expect_refused(r, Vec3::Zero(), "NaN or infinite");
  r = Mat3::Identity();
  r(0, 0) = inf;
  expect_refused(r, Vec3::Zero(), "NaN or infinite");
  expect_refused(Mat3::Identity(), Vec3(0, nan, 0), "translation has a NaN");
  expect_refused(Mat3::Identity(), Vec3(-inf, 0, 0), "translation has a NaN");
  expect_refused(2.0 * Mat3::Identity(), Vec3::Zero(), "not orthonormal");         // a scale
  expect_refused((1 + 1e-6) * Mat3::Identity(), Vec3::Zero(), "not orthonormal");  // a slight scale
  r = Mat3::Identity();
  r(0, 1) = 0.1;
  expect_refused(r, Vec3::Zero(), "not orthonormal");  // a shear
  expect_refused(Mat3::Zero(), Vec3::Zero(), "not orthonormal");
  expect_refused(Vec3(1, 1, -1).asDiagonal(), Vec3::Zero(), "reflection");  // a mirror
  expect_refused(-Mat3::Identity(), Vec3::Zero(), "reflection");            // a point reflection
}

TEST(CallerTransforms, CheckedAcceptsRotationsUpToRounding) {
  // Every protocol pose, including theta = pi and its neighbours, passes; so does a rotation off by 1e-12.
  for (int k = 0; k <= 5000; k += 125) {
    const RigidTransform p = protocol_pose(1.0, k, 5000);
    EXPECT_NO_THROW((void)RigidTransform::checked(p.rotation, p.translation)) << k;
  }
  const RigidTransform pi = protocol_pose(1.0, 2500, 5000);
  EXPECT_NO_THROW((void)RigidTransform::checked(pi.rotation, pi.translation));
  Mat3 r = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  r(0, 0) += 1e-12;
  EXPECT_NO_THROW((void)RigidTransform::checked(r, Vec3(1e9, -1e9, 0)));
  // The checked transform is the one given: no silent orthonormalisation.
  EXPECT_EQ(RigidTransform::checked(r, Vec3::Zero()).rotation, r);
}

TEST(CallerTransforms, CheckedDecidesAtTheToleranceAndAtTheLimitsOfDouble) {
  // validate passes plain rotations in one quick pass and sends every other transform through its checks one
  // by one, which decide: a rotation off by between half the tolerance and the tolerance is accepted, beyond
  // it refused; a translation whose sum overflows is finite all the same.
  const Mat3 base = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  for (const double tolerance : {1e-9, 1e-6}) {
    for (const double off : {0.3, 0.7, 1.5}) {
      Mat3 r = base;
      r(0, 0) += off * tolerance / (2 * std::abs(base(0, 0)));  // (R^T R)(0, 0) - 1 is about off * tolerance
      const RigidTransform t{r, Vec3::Zero()};
      if (off < 1)
        EXPECT_NO_THROW(t.validate(tolerance)) << off << " of " << tolerance;
      else
        EXPECT_THROW(t.validate(tolerance), std::invalid_argument) << off << " of " << tolerance;
    }
  }
  const double big = std::numeric_limits<double>::max();
  EXPECT_NO_THROW((void)RigidTransform::checked(base, Vec3(big, big, -0.5 * big)));
  EXPECT_NO_THROW((void)RigidTransform::checked(base, Vec3(-big, -big, 0)));
  expect_refused(base, Vec3(big, std::numeric_limits<double>::infinity(), 0), "translation has a NaN");
  Mat3 mirrored = base;
  mirrored.col(2) *= -1;
  expect_refused(mirrored, Vec3::Zero(), "reflection");
  EXPECT_THROW(RigidTransform{}.validate(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(RigidTransform{}.validate(-1), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------------------
// Scenes and pose files

std::string scene_with_rotation(const std::string& rows) {
  return R"({"objects": [{"mesh": "pinion.off", "placement": {"rotation": )" + rows +
         R"(}}], "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}]})";
}

TEST(CallerTransforms, ScenePlacementsMustBeRotations) {
  for (const std::string rows : {"[[2, 0, 0], [0, 1, 0], [0, 0, 1]]", "[[1, 0.01, 0], [0, 1, 0], [0, 0, 1]]",
                                 "[[-1, 0, 0], [0, 1, 0], [0, 0, 1]]", "[[0, 0, 0], [0, 0, 0], [0, 0, 0]]"}) {
    try {
      parse_scene(scene_with_rotation(rows), fs::temp_directory_path(), "t.json");
      ADD_FAILURE() << "accepted " << rows;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("t.json: /objects/0/placement/rotation: not a rotation"),
                std::string::npos)
          << e.what();
    }
  }
  // A rotation written with 7 digits is a rotation to the parser's tolerance, and is accepted as written.
  const Scene scene =
      parse_scene(scene_with_rotation("[[0.7071068, -0.7071068, 0], [0.7071068, 0.7071068, 0], [0, 0, 1]]"),
                  fs::temp_directory_path(), "t.json");
  EXPECT_NEAR(scene.objects[0].placement.rotation(0, 1), -0.7071068, 0);
}

TEST(CallerTransforms, PoseFilesMustHoldRotations) {
  const fs::path file = fs::temp_directory_path() / ("bvhlab-poses-" + std::to_string(getpid()) + ".json");
  std::ofstream(file) << R"({"poses": [{"translation": [1, 0, 0]},
                                       {"translation": [1, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 3]]}]})";
  try {
    load_pose_file(file);
    ADD_FAILURE() << "accepted a scaled pose";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/poses/1/rotation: not a rotation"), std::string::npos) << e.what();
  }
  std::ofstream(file) << R"({"poses": [{"translation": [1, 0, 0], "axis_angle_deg": [0, 0, 1, 180]}]})";
  const auto groups = load_pose_file(file);
  ASSERT_EQ(groups.size(), 1u);
  const Mat3& r = groups[0].poses[0].rotation;
  EXPECT_LT((r.transpose() * r - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  fs::remove(file);
}

// A mesh file's node transform may scale (that is modelling, applied to the vertices), but one that makes a
// coordinate NaN or infinite is refused.
TEST(CallerTransforms, MeshNodeTransformsThatBreakCoordinatesAreRefused) {
  auto gltf_with_matrix = [](const std::string& matrix) {
    // One triangle; positions (0,0,0), (1,0,0), (0,1,0) as little-endian floats, base64-encoded.
    return std::string(R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0, "matrix": )") +
           matrix + R"(}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 4}]}],
      "buffers": [{"byteLength": 36, "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                     "min": [0, 0, 0], "max": [1, 1, 0]}]})";
  };
  const std::string scaled = gltf_with_matrix("[2,0,0,0, 0,2,0,0, 0,0,2,0, 5,0,0,1]");
  const LoadedMesh loaded =
      load_mesh_from_memory(std::as_bytes(std::span(scaled.data(), scaled.size())), "gltf", "scaled.gltf");
  ASSERT_EQ(loaded.mesh.triangle_count(), 1u);
  EXPECT_EQ(loaded.report.bounds.max.x(), 7.0);  // 2 * 1 + 5
  const std::string overflowing = gltf_with_matrix("[3e38,0,0,0, 0,3e38,0,0, 0,0,1,0, 3e38,0,0,1]");
  try {
    load_mesh_from_memory(std::as_bytes(std::span(overflowing.data(), overflowing.size())), "gltf",
                          "inf.gltf");
    ADD_FAILURE() << "accepted coordinates beyond double's range after the node transform";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("inf.gltf"), std::string::npos) << e.what();
  }
}

// A NaN pose passed straight to a query would make every overlap test false, and the answer would be
// "no collision", marked exact -- a silent wrong answer. Queries validate their pose (about 40 flops).
TEST(CallerTransforms, QueriesRefuseAPoseThatIsNoRotation) {
  const Mesh cube = robust::make_cube();
  const auto tree = Bvh<Aabb>::build(cube);
  RigidTransform bad;
  bad.translation = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  EXPECT_THROW((void)query_exact(tree, tree, bad), std::invalid_argument);
  bad = RigidTransform{2.0 * Mat3::Identity(), Vec3::Zero()};
  EXPECT_THROW((void)query_exact(tree, tree, bad), std::invalid_argument);
  bad = RigidTransform{-Mat3::Identity(), Vec3::Zero()};  // a reflection
  EXPECT_THROW((void)query_exact(tree, tree, bad), std::invalid_argument);
}

}  // namespace
}  // namespace bvhlab
