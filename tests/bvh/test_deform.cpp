// Procedural deformations, the cloth grid, the topology check and mesh sequences from files.
#include "bvh/deform.hpp"
#include "bvh/mesh_io.hpp"
#include "bvh/mesh_sequence.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>

namespace bvhlab {
namespace {

constexpr DeformationKind kKinds[] = {DeformationKind::Twist, DeformationKind::Bend, DeformationKind::Pulsate,
                                      DeformationKind::Wave};

// Throws f and returns the message, failing the test if nothing of type E is thrown.
template <class E = std::invalid_argument, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "nothing thrown";
  return {};
}

double max_displacement(const Mesh& a, const Mesh& b) {
  double out = 0;
  for (std::size_t v = 0; v < a.vertices.size(); ++v)
    out = std::max(out, (a.vertices[v] - b.vertices[v]).norm());
  return out;
}

TEST(Deform, KeepsTopologyAndMovesVertices) {
  for (const Mesh& rest : {cloth_grid(12), testing::make_torus(0.7, 0.25, 16, 8)})
    for (DeformationKind kind : kKinds) {
      const Mesh moved = deform(rest, default_deformation(kind), 0.25);
      ASSERT_EQ(moved.vertices.size(), rest.vertices.size());
      EXPECT_EQ(moved.triangles, rest.triangles);
      EXPECT_EQ(moved.name, rest.name);
      EXPECT_EQ(topology_fingerprint(moved), topology_fingerprint(rest));
      for (const auto& v : moved.vertices) ASSERT_TRUE(v.allFinite());
      // A quarter period is the strongest pose: every kind moves the mesh by a visible fraction of its size.
      EXPECT_GT(max_displacement(rest, moved), 0.01) << to_string(kind) << " on " << rest.name;
    }
}

TEST(Deform, DeterministicAndPeriodic) {
  const Mesh rest = testing::make_torus(0.7, 0.25, 16, 8);
  for (DeformationKind kind : kKinds) {
    const Deformation d = default_deformation(kind);
    const Mesh a = deform(rest, d, 0.3), b = deform(rest, d, 0.3), c = deform(rest, d, 1.3);
    EXPECT_EQ(a.vertices, b.vertices) << to_string(kind);
    EXPECT_LT(max_displacement(a, c), 1e-12) << to_string(kind);
  }
}

TEST(Deform, AmplitudeZeroAndTimeZeroGiveTheRestMesh) {
  const Mesh rest = testing::make_torus(0.7, 0.25, 16, 8);
  for (DeformationKind kind : kKinds) {
    Deformation d = default_deformation(kind);
    if (kind != DeformationKind::Wave) {
      EXPECT_EQ(deform(rest, d, 0.0).vertices, rest.vertices) << to_string(kind);
    }
    d.amplitude = 0;
    EXPECT_EQ(deform(rest, d, 0.37).vertices, rest.vertices) << to_string(kind);
  }
}

TEST(Deform, EachKindDoesWhatItSays) {
  const Mesh cloth = cloth_grid(10);  // longest axis x (a tie with y), normal z
  // Twist about the x axis through the centre: the distance to that axis is kept.
  const Mesh twisted = deform(cloth, default_deformation(DeformationKind::Twist), 0.25);
  for (std::size_t v = 0; v < cloth.vertices.size(); ++v) {
    const Vec3 &p = cloth.vertices[v], &q = twisted.vertices[v];
    EXPECT_DOUBLE_EQ(q.x(), p.x());
    EXPECT_NEAR(std::hypot(q.y() - 0.5, q.z()), std::hypot(p.y() - 0.5, p.z()), 1e-12);
  }
  EXPECT_GT(max_displacement(cloth, twisted), 0.3);
  // Pulsation scales the bounds about their centre by 1 + amplitude at a quarter period.
  const Mesh pulsed = deform(cloth, parse_deformation("pulsate:amplitude=0.5"), 0.25);
  EXPECT_NEAR(pulsed.bounds().extent().x(), 1.5, 1e-12);
  EXPECT_NEAR((pulsed.bounds().center() - cloth.bounds().center()).norm(), 0, 1e-12);
  // Bending keeps lengths along the bent axis (the arc): neighbours 1/n apart on the arc of curvature
  // 3 (amplitude 3 over length 1) are a chord of 2 sin(0.15) / 3 apart.
  const Mesh bent = deform(cloth, parse_deformation("bend:amplitude=3"), 0.25);
  for (std::size_t i = 0; i + 1 < 11; ++i)
    EXPECT_NEAR((bent.vertices[i + 1] - bent.vertices[i]).norm(), 2 * std::sin(0.15) / 3, 1e-12);
  EXPECT_GT(bent.bounds().extent().z(), 0.1);
  // The wave moves vertices along the normal only, at most amplitude times the size.
  const Mesh waved = deform(cloth, parse_deformation("wave:amplitude=0.1,wavelength=0.25"), 0.6);
  for (std::size_t v = 0; v < cloth.vertices.size(); ++v) {
    EXPECT_EQ(waved.vertices[v].head<2>(), cloth.vertices[v].head<2>());
    EXPECT_LE(std::abs(waved.vertices[v].z()), 0.1 + 1e-15);
  }
  EXPECT_GT(waved.bounds().extent().z(), 0.15);
}

TEST(Deform, ParsesNamesAndParameters) {
  const Deformation w = parse_deformation("wave:amplitude=0.1,wavelength=0.25,cycles=2");
  EXPECT_EQ(w.kind, DeformationKind::Wave);
  EXPECT_EQ(w.amplitude, 0.1);
  EXPECT_EQ(w.wavelength, 0.25);
  EXPECT_EQ(w.cycles, 2);
  const Deformation t = parse_deformation("twist");
  EXPECT_EQ(t.kind, DeformationKind::Twist);
  EXPECT_EQ(t.amplitude, std::numbers::pi / 2);
  EXPECT_EQ(parse_deformation("bend:amplitude=-1").amplitude, -1);
  EXPECT_EQ(parse_deformation("pulsate").kind, DeformationKind::Pulsate);
}

TEST(Deform, RefusesBadNamesAndValues) {
  EXPECT_NE(message_of([] { parse_deformation("twsit"); }).find("unknown name 'twsit'"), std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation(""); }).find("known: twist, bend, pulsate, wave"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:amplitude=abc"); }).find("'abc' is not a finite number"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:amplitude=nan"); }).find("not a finite number"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:amplitude=1x"); }).find("not a finite number"),
            std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:amplitude"); }).find("not key=value"),
            std::string::npos);
  EXPECT_NE(
      message_of([] { parse_deformation("twist:wavelength=1"); }).find("unknown parameter 'wavelength'"),
      std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:cycles=0"); }).find("cycles"), std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("twist:cycles=1.5"); }).find("cycles"), std::string::npos);
  EXPECT_NE(
      message_of([] { parse_deformation("pulsate:amplitude=1"); }).find("amplitude must lie in (-1, 1)"),
      std::string::npos);
  EXPECT_NE(message_of([] { parse_deformation("wave:wavelength=0"); }).find("wavelength"), std::string::npos);
  const Mesh cloth = cloth_grid(2);
  EXPECT_NE(message_of([&] { deform(cloth, default_deformation(DeformationKind::Twist), NAN); }).find("time"),
            std::string::npos);
  Mesh broken = cloth;
  broken.vertices[4].x() = std::numeric_limits<double>::infinity();
  EXPECT_NE(
      message_of([&] { deform(broken, default_deformation(DeformationKind::Bend), 0.1); }).find("vertex 4"),
      std::string::npos);
  EXPECT_NE(message_of([] { deform(Mesh{}, default_deformation(DeformationKind::Bend), 0.1); }).find("empty"),
            std::string::npos);
  EXPECT_THROW(cloth_grid(0), std::invalid_argument);
  EXPECT_THROW(frame_time(0, 0), std::invalid_argument);
}

TEST(Deform, ClothGridAndFrameTime) {
  const Mesh m = cloth_grid(7);
  EXPECT_EQ(m.vertices.size(), 64u);
  EXPECT_EQ(m.triangles.size(), 98u);
  EXPECT_EQ(m.bounds().min, Vec3(0, 0, 0));
  EXPECT_EQ(m.bounds().max, Vec3(1, 1, 0));
  double area = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const auto p = m.triangle(t);
    area += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).z();  // counter-clockwise seen from +z: positive
  }
  EXPECT_NEAR(area, 1.0, 1e-12);
  EXPECT_EQ(frame_time(3, 4), 0.75);
  EXPECT_EQ(frame_time(5, 4), 0.25);
}

TEST(Deform, TopologyCheckNamesTheDifference) {
  const Mesh a = cloth_grid(3);
  EXPECT_NO_THROW(check_same_topology(a, deform(a, default_deformation(DeformationKind::Wave), 0.2), "f"));
  Mesh fewer = a;
  fewer.vertices.pop_back();
  EXPECT_NE(message_of([&] { check_same_topology(a, fewer, "frame 2"); }).find("frame 2: 15 vertices"),
            std::string::npos);
  Mesh flipped = a;
  std::swap(flipped.triangles[5][1], flipped.triangles[5][2]);
  EXPECT_NE(message_of([&] { check_same_topology(a, flipped, "frame 3"); }).find("frame 3: triangle 5"),
            std::string::npos);
  Mesh nan = a;
  nan.vertices[9].y() = NAN;
  EXPECT_NE(message_of([&] { check_same_topology(a, nan, "frame 4"); }).find("vertex 9 is not finite"),
            std::string::npos);
}

// One OBJ file per frame in a fresh temporary directory.
class MeshSequenceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() /
        ("bvhlab_sequence_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& name, const Mesh& m) {
    const auto path = dir_ / name;
    std::ofstream out(path);
    out.precision(17);
    for (const auto& v : m.vertices) out << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
    for (const auto& t : m.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(MeshSequenceTest, LoadsFramesOfOneTopology) {
  const Mesh rest = cloth_grid(6);
  const Deformation d = default_deformation(DeformationKind::Twist);
  std::vector<std::filesystem::path> files;
  for (int f = 0; f < 3; ++f)
    files.push_back(write("f" + std::to_string(f) + ".obj", deform(rest, d, 0.1 * f)));
  const auto frames = load_mesh_sequence(files);
  ASSERT_EQ(frames.size(), 3u);
  for (const auto& m : frames) EXPECT_EQ(topology_fingerprint(m), topology_fingerprint(frames[0]));
  EXPECT_GT(max_displacement(frames[0], frames[2]), 0.05);
}

TEST_F(MeshSequenceTest, RefusesAnotherTopologyNamingTheFile) {
  const Mesh rest = cloth_grid(6);
  const auto first = write("first.obj", rest);
  Mesh flipped = rest;  // the other diagonal in one cell: same vertices, other triangles
  flipped.triangles[0] = {0, 1, 7};
  flipped.triangles[1] = {1, 8, 7};
  const auto other = write("other.obj", flipped);
  const auto smaller = write("smaller.obj", cloth_grid(5));
  const MeshSequence sequence({first, other, smaller});
  EXPECT_EQ(sequence.first().triangles, load_mesh(first).mesh.triangles);
  const std::string m1 = message_of<MeshError>([&] { (void)sequence.frame(1); });
  EXPECT_NE(m1.find(other.string() + ": triangle"), std::string::npos) << m1;
  EXPECT_NE(m1.find(first.string()), std::string::npos) << m1;
  const std::string m2 = message_of<MeshError>([&] { (void)sequence.frame(2); });
  EXPECT_NE(m2.find(smaller.string() + ": 36 vertices, the first frame has 49"), std::string::npos) << m2;
  EXPECT_THROW((void)sequence.frame(3), std::out_of_range);
  EXPECT_THROW(load_mesh_sequence({first, smaller}), MeshError);
  EXPECT_THROW(MeshSequence({}), MeshError);
}

TEST_F(MeshSequenceTest, RefusesANonFiniteFrameNamingTheFile) {
  const auto first = write("first.obj", cloth_grid(3));
  const auto bad = dir_ / "bad.obj";
  {
    std::ifstream in(first);
    std::ofstream out(bad);
    std::string line;
    for (int k = 0; std::getline(in, line); ++k) out << (k == 5 ? "v nan 0 0" : line) << '\n';
  }
  const MeshSequence sequence({first, bad});
  const std::string m = message_of<MeshError>([&] { (void)sequence.frame(1); });
  EXPECT_NE(m.find(bad.string()), std::string::npos) << m;
}

}  // namespace
}  // namespace bvhlab
