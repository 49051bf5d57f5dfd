// Far frames: the ADB strategies on a scene moved far from the origin stay honest, and the loader warns or
// refuses where a file's coordinates lose the model. The exact protocol in far and rescaled frames, for every
// volume, is test_far_frame_protocol.cpp (label `protocol`).
#include "bench/core/ground_truth.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/mesh_catalog.hpp"
#include "robust_support.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>

namespace bvhlab::robust {
namespace {

// The ADB strategies in a far frame: probabilities stay probabilities, exact answers stay right. At 1e9 a
// small torus stands in for the jeep, since nothing is culled there (see above).
TEST(FarFrames, AdbStrategiesStayHonestFarFromTheOrigin) {
  struct Case {
    Mesh mesh;
    double offset;
    int poses_per_distance;
  };
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");
  const Mesh torus = testing::make_torus(0.7, 0.25, 12, 6);
  for (const Case& c : {Case{jeep, 1e6, 12}, Case{torus, 1e9, 12}}) {
    const CgalGroundTruth truth(c.mesh, c.mesh);
    const Vec3 offset(c.offset, c.offset, -c.offset);
    const auto tree = annotated<Aabb>(reframe(c.mesh, 1.0, offset));
    int colliding = 0;
    for (const Query& q : protocol_queries(c.poses_per_distance)) {
      const bool expected = truth.collides(q.pose);
      colliding += expected;
      const RigidTransform pose = reframe(q.pose, 1.0, offset);
      for (Strategy s : kAllStrategies) {
        const Result r = run<Aabb>(s, tree, tree, pose);
        ASSERT_TRUE(honest(r, expected)) << to_string(s) << " offset " << c.offset << " d " << q.distance;
        if (is_exact(s)) {
          ASSERT_EQ(r.collides, expected) << to_string(s) << " d " << q.distance;
        }
      }
    }
    EXPECT_GT(colliding, 0);
  }
}

// ---------------------------------------------------------------------------------------------------------
// The loader. assimp parses coordinates into float (ai_real), so a file describes its vertices to about
// 6e-8 of max |coordinate|. Where that spacing is a visible part of the model, the loader must say so
// (warning) or refuse; a silently distorted model is a wrong answer for every later query.

std::string to_obj(const Mesh& m) {
  std::ostringstream out;
  out.precision(17);
  for (const Vec3& v : m.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  for (const auto& t : m.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  return out.str();
}

// Largest distance between a loaded triangle's corner and the written one, relative to the model's
// diagonal. The loader keeps the faces' order and winding (one sub-mesh, no mirroring), so triangle i of
// both meshes is the same face.
double relative_distortion(const Mesh& written, const Mesh& loaded) {
  EXPECT_EQ(written.triangle_count(), loaded.triangle_count());
  const double diagonal = written.bounds().extent().norm();
  double worst = 0;
  for (std::size_t i = 0; i < std::min(written.triangle_count(), loaded.triangle_count()); ++i)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, (written.triangle(i)[k] - loaded.triangle(i)[k]).norm());
  return worst / diagonal;
}

bool mentions_precision(const LoadReport& report) {
  for (const auto& w : report.warnings)
    if (w.find("far from the origin") != std::string::npos || w.find("precision") != std::string::npos)
      return true;
  return false;
}

// assimp reads coordinates as 32-bit floats: measured distortion 1.5e-6 of the model size at offset 100,
// 1.9e-4 at 1e4, 1.5e-3 at 1e5, 1.2e-2 at 1e6. The loader must warn (or refuse) wherever that loss exceeds
// 1e-5 of the model size.
TEST(FarFrames, LoaderWarnsOrRefusesWhereFileCoordinatesLoseTheModel) {
  const Mesh jeep = load_protocol_mesh("jeep1.ms3d");  // size 2
  for (double offset : {0.0, 1e2, 1e4, 1e5, 1e6, 1e9, 1e16}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    const Mesh far = reframe(jeep, 1.0, Vec3(offset, 0, 0));
    const std::string text = to_obj(far);
    try {
      const LoadedMesh loaded =
          load_mesh_from_memory(std::as_bytes(std::span(text.data(), text.size())), "obj", "far.obj");
      const double distortion = relative_distortion(far, loaded.mesh);
      std::printf("[loader] offset %-8g distortion %.3g of the diagonal, %s\n", offset, distortion,
                  mentions_precision(loaded.report) ? "warned" : "no warning");
      // Without a warning the model must come through to 1e-5 of its own size (float holds ~6e-8 of
      // max|coordinate|, so this allows offsets up to ~100 model sizes).
      if (!mentions_precision(loaded.report)) {
        EXPECT_LE(distortion, 1e-5);
      }
    } catch (const MeshError& e) {
      std::printf("[loader] offset %-8g refused: %s\n", offset, e.what());
      EXPECT_NE(std::string(e.what()).find("far.obj"), std::string::npos) << e.what();
      EXPECT_GE(offset, 1e6) << "refused a file whose coordinates float holds well: " << e.what();
    }
  }
}

}  // namespace
}  // namespace bvhlab::robust
