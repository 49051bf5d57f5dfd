// The bvhlab CLI end to end, run as a user runs it: units (the mesh files' own unless --normalize, recorded
// in saved trees), options that do not apply refused with a reason, values checked before any work, the
// saved trees `build` writes queryable, and --repeat, --all-contacts and --poses.
#include "adb/saved_tree.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <string>

namespace bvhlab {
namespace {

using testing::TempDir;

struct Outcome {
  int status = -1;
  std::string out, err;
};

/// An axis-aligned cube of side `side` centred at (x, 0, 0), as an OBJ file.
void write_cube(const std::filesystem::path& file, double side, double x = 0) {
  const double h = side / 2;
  std::string text;
  for (int k = 0; k < 8; ++k)
    text += "v " + std::to_string(x + (k & 1 ? h : -h)) + " " + std::to_string(k & 2 ? h : -h) + " " +
            std::to_string(k & 4 ? h : -h) + "\n";
  text +=
      "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\n"
      "f 4 8 6\n";
  testing::write_text(file, text);
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    write_cube(dir / "big.obj", 10);   // [-5, 5]^3
    write_cube(dir / "small.obj", 1);  // [-0.5, 0.5]^3
  }

  /// Runs `bvhlab ARGS` in the test's folder, without the tree cache of the build.
  Outcome run(const std::string& args) const {
    const std::string command = "cd '" + dir.path().string() + "' && BVHLAB_CACHE_DIR='" +
                                (dir / "cache").string() + "' '" + BVHLAB_CLI + "' " + args +
                                " > out.txt 2> err.txt";
    const int raw = std::system(command.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, testing::read_text(dir / "out.txt"),
            testing::read_text(dir / "err.txt")};
  }
  /// Runs and expects a refusal whose message contains `fragment`, and no output: status 1 (a failure) or 2
  /// (a bad command line), and every line of the message that is not a hint prefixed "bvhlab:".
  Outcome expect_refused(const std::string& args, const std::string& fragment) const {
    const Outcome o = run(args);
    EXPECT_TRUE(o.status == 1 || o.status == 2) << args << "\nstatus " << o.status << "\n" << o.out;
    EXPECT_NE(o.err.find(fragment), std::string::npos) << args << "\nstderr: " << o.err;
    EXPECT_EQ(o.err.rfind("bvhlab: ", 0), 0u) << args << "\nstderr: " << o.err;
    EXPECT_EQ(o.out, "") << args;
    return o;
  }
  /// Runs and expects success.
  Outcome ok(const std::string& args) const {
    Outcome o = run(args);
    EXPECT_EQ(o.status, 0) << args << "\nstderr: " << o.err;
    return o;
  }

  TempDir dir;
};

// ---------------------------------------------------------------------------------------------------------
// Units

// A pose is read in the meshes' own units: the small cube at x = 5.2 crosses the big cube's face at x = 5.
// Normalised (both cubes 2 wide), it is far from it, and the CLI says that it normalised.
TEST_F(Cli, PosesAreInTheMeshFilesUnitsUnlessNormalised) {
  const Outcome raw = ok("query big.obj small.obj --pose 5.2,0,0 --json");
  EXPECT_TRUE(nlohmann::json::parse(raw.out)["collides"].get<bool>()) << raw.out;
  EXPECT_EQ(raw.err.find("normalised"), std::string::npos) << raw.err;
  const Outcome normalised = ok("query big.obj small.obj --pose 5.2,0,0 --json --normalize");
  EXPECT_FALSE(nlohmann::json::parse(normalised.out)["collides"].get<bool>()) << normalised.out;
  EXPECT_NE(normalised.err.find("big was normalised: scale 0.2, centre (0, 0, 0)"), std::string::npos)
      << normalised.err;
  EXPECT_NE(normalised.err.find("small was normalised: scale 2, centre (0, 0, 0)"), std::string::npos)
      << normalised.err;
  expect_refused("query big.obj small.obj --pose 5.2,0,0 --no-normalize", "--no-normalize");
}

TEST_F(Cli, SavedTreesRecordTheirUnitsAndAreNotMixed) {
  ok("build big.obj --adb -o big.tree");
  const Outcome built = ok("build small.obj --adb --normalize -o small.tree");
  EXPECT_NE(built.err.find("small normalised: scale 2"), std::string::npos) << built.err;
  EXPECT_NE(built.out.find("units           normalised: scale 2, centre (0, 0, 0)"), std::string::npos)
      << built.out;
  const Outcome info = ok("info big.tree");
  EXPECT_NE(info.out.find("units           the mesh file's units"), std::string::npos) << info.out;
  const nlohmann::json j = nlohmann::json::parse(ok("info small.tree --json").out);
  EXPECT_TRUE(j["normalized"].get<bool>());
  EXPECT_EQ(j["normalization"]["scale"].get<double>(), 2.0);
  // A normalised tree and a raw one: a pose cannot be in both units.
  expect_refused("query big.tree small.tree --pose 5.2,0,0 --strategy adb",
                 "saved trees in different units: small.tree is normalised: scale 2, centre (0, 0, 0), "
                 "big.tree is in its mesh file's units");
  // Trees answer in their units: a ring of radius 4 overlaps its copy at x = 5; normalised (radius 1) not.
  testing::write_obj(testing::make_torus(3.0, 1.0, 24, 12), dir / "ring.obj");
  ok("build ring.obj --adb -o ring.tree");
  ok("build ring.obj --adb --normalize -o ring-normalised.tree");
  const Outcome raw = ok("query ring.tree ring.tree --pose 5,0,0 --strategy adb --json");
  EXPECT_TRUE(nlohmann::json::parse(raw.out)["collides"].get<bool>()) << raw.out;
  const Outcome normalised =
      ok("query ring-normalised.tree ring-normalised.tree --pose 5,0,0 --strategy adb --json");
  EXPECT_FALSE(nlohmann::json::parse(normalised.out)["collides"].get<bool>()) << normalised.out;
  EXPECT_NE(normalised.err.find("ring-normalised.tree is normalised: scale 0.25"), std::string::npos)
      << normalised.err;
}

TEST_F(Cli, TreesOfAnOlderFormatAreRefusedByVersion) {
  ok("build small.obj --adb -o small.tree");
  std::vector<std::byte> bytes = saved_tree_detail::read_file(dir / "small.tree");
  bytes[8] = std::byte{2};  // the format version
  saved_tree_detail::write_file_atomically(dir / "old.tree", bytes);
  expect_refused("info old.tree", "format version 2, this build reads version 3");
}

// ---------------------------------------------------------------------------------------------------------
// Options that do not apply are refused with a reason

TEST_F(Cli, OptionsThatDoNotApplyAreRefused) {
  expect_refused("query small.obj small.obj --pose 0.5,0,0 --strategy adb --all-contacts",
                 "--all-contacts: lists exact contacts; it does not apply to strategy adb");
  expect_refused("query small.obj small.obj --pose 0.5,0,0 --strategy exact --bv-tests 5",
                 "strategy exact takes no budget");
  expect_refused("build small.obj --tau 0.5 --grid 3 -o x.tree", "does not apply to density none");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.tree"));
  ok("build small.obj --adb -o small.tree");
  for (const char* option :
       {"--bv obb", "--tau 0.5", "--grid 3", "--normalize", "--density adb", "--no-cache", "--cache c"})
    expect_refused(std::string("query small.tree small.tree --pose 0.5,0,0 --strategy adb ") + option,
                   "does not apply");
}

// Point clouds (--cloud): a cloud of the small cube's surface against the cube's mesh or itself, queried
// through the implicit surfaces; what does not apply to clouds is refused by name.
TEST_F(Cli, PointCloudsAreQueriedThroughTheirSurfaces) {
  std::string xyz;
  for (int face = 0; face < 6; ++face)
    for (int i = 0; i < 15; ++i)
      for (int j = 0; j < 15; ++j) {
        double p[3];
        p[face % 3] = face < 3 ? -0.5 : 0.5;
        p[(face + 1) % 3] = -0.5 + (i + 0.5) / 15;
        p[(face + 2) % 3] = -0.5 + (j + 0.5) / 15;
        xyz += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
      }
  testing::write_text(dir / "cube.xyz", xyz);
  const auto collides = [&](const std::string& args) {
    return nlohmann::json::parse(ok("query " + args + " --json").out)["collides"].get<bool>();
  };
  // Turned a little: no face of one cube lies in a face's plane of the other, where only coplanar points
  // would touch.
  const std::string near = " --pose 0.5,0.2,0.1,1,2,3,20", far = " --pose 1.5,0.2,0.1,1,2,3,20";
  for (const std::string sides :
       {"cube.xyz small.obj --cloud a", "small.obj cube.xyz --cloud b", "cube.xyz cube.xyz --cloud both"}) {
    EXPECT_TRUE(collides(sides + near)) << sides;
    EXPECT_FALSE(collides(sides + far)) << sides;
    EXPECT_TRUE(collides(sides + near + " --strategy adb --p-min 0.999 --confirm-levels 4")) << sides;
    EXPECT_FALSE(collides(sides + far + " --strategy adb")) << sides;
  }
  const Outcome text = ok("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --bv obb");
  EXPECT_NE(text.out.find("cube.xyz vs small.obj, exact on obb"), std::string::npos) << text.out;

  ok("build small.obj --adb -o small.tree");
  expect_refused("query cube.xyz small.tree --cloud a --pose 0.5,0,0", "'small.tree' is a saved tree");
  expect_refused("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --normalize", "applies to meshes");
  expect_refused("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --no-cache", "not cached");
  expect_refused("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --bv fcl_obb", "hold no point clouds");
  expect_refused("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --all-contacts",
                 "lists intersecting triangle pairs, and a point cloud has none");
  expect_refused("query cube.xyz small.obj --cloud a --pose 0.5,0,0 --strategy adb --density adb_paper",
                 "does not annotate trees over points");
  expect_refused("query cube.xyz small.obj --cloud c --pose 0.5,0,0", "--cloud");
  testing::write_text(dir / "bad.xyz", "0 0 0\n1 1\n");
  expect_refused("query bad.xyz small.obj --cloud a --pose 0.5,0,0", "bad.xyz");
}

TEST_F(Cli, InfoOfASavedTreePrintsJson) {
  ok("build small.obj --adb -o small.tree");
  const nlohmann::json j = nlohmann::json::parse(ok("info small.tree --json").out);
  EXPECT_EQ(j["annotation"], "adb grid=2 tau=0.25");
  EXPECT_EQ(j["triangles"], 12);
}

// A saved tree has no polygons: without a density no shipped strategy could query it, so it is not built.
TEST_F(Cli, BuildRefusesATreeNothingCouldQuery) {
  expect_refused("build small.obj -o plain.tree",
                 "a saved tree carries no polygons, and no strategy queries a tree with density none");
  EXPECT_FALSE(std::filesystem::exists(dir / "plain.tree"));
  ok("build small.obj --adb -o adb.tree");
  ok("query adb.tree adb.tree --pose 0.5,0,0 --strategy adb");
}

// ---------------------------------------------------------------------------------------------------------
// Values are checked before any work, with the ranges scenes use

TEST_F(Cli, ValuesAreCheckedBeforeWorkStarts) {
  expect_refused("build small.obj --adb --tau 1.5 -o x.tree", "tau must be a number in [0, 1], got 1.5");
  EXPECT_FALSE(std::filesystem::exists(dir / "x.tree"));
  expect_refused("query small.obj small.obj --protocol -1,0,10", "distance must be a number in [0, 1e+06]");
  expect_refused("query small.obj small.obj --protocol 1,10,10", "STEP must be an integer in [0, STEPS - 1]");
  expect_refused("query small.obj small.obj --protocol 1,0,0", "steps must be an integer in [1, 1e+07]");
  expect_refused("query small.obj small.obj --pose 1,0,0 --strategy time_critical --bv-tests 0",
                 "bv_tests must be an integer in [1, 1099511627776]");
  expect_refused("query small.obj small.obj --pose 1,0,0 --strategy time_critical --deadline-us 0",
                 "deadline_us must be a number in (0, 1e+09]");
  expect_refused("query small.obj small.obj --pose 1,0,0,0,0,0,90", "the rotation axis must be finite");
  expect_refused("query small.obj small.obj --pose 1,0,0 --repeat 0", "--repeat");
  expect_refused("query small.obj small.obj --protocol 1,2000000", "poses must be an integer in [1, 1e+06]");
  ok("query small.obj small.obj --protocol 1,9,10");
}

// The LB table starts at tau = 0 (every cell with some area counts); it is a value like any other.
// A deadline that has passed before the query could finish (a picosecond) is reported, in text and JSON,
// whether the traversal was stopped or ended late; a deadline never reached is not.
TEST_F(Cli, AnExhaustedDeadlineIsReported) {
  for (const char* pose : {"0.5,0,0", "0.9,0.1,0,1,1,0,30", "20,0,0"}) {
    const std::string query =
        std::string("query small.obj small.obj --pose ") + pose + " --strategy time_critical";
    const Outcome text = ok(query + " --deadline-us 1e-6");
    EXPECT_NE(text.out.find("budget            exhausted"), std::string::npos) << pose << "\n" << text.out;
    EXPECT_TRUE(
        nlohmann::json::parse(ok(query + " --deadline-us 1e-6 --json").out)["budget_exhausted"].get<bool>())
        << pose;
    EXPECT_FALSE(
        nlohmann::json::parse(ok(query + " --deadline-us 1e9 --json").out)["budget_exhausted"].get<bool>())
        << pose;
  }
}

TEST_F(Cli, TauZeroIsAccepted) {
  const Outcome built = ok("build small.obj --adb --tau 0 -o zero.tree");
  EXPECT_NE(built.out.find("adb grid=2 tau=0"), std::string::npos) << built.out;
  ok("query zero.tree zero.tree --pose 0.5,0,0 --strategy adb");
}

// ---------------------------------------------------------------------------------------------------------
// --repeat, --all-contacts, --poses

TEST_F(Cli, RepeatTimesWarmQueries) {
  const Outcome text = ok("query small.obj small.obj --pose 0.5,0,0 --repeat 7");
  EXPECT_NE(text.out.find("warm time         median "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("over 7 queries"), std::string::npos) << text.out;
  const nlohmann::json j =
      nlohmann::json::parse(ok("query small.obj small.obj --pose 0.5,0,0 --repeat 7 --json").out);
  EXPECT_EQ(j["warm_time_us"]["queries"], 7);
  EXPECT_LE(j["warm_time_us"]["min"].get<double>(), j["warm_time_us"]["median"].get<double>());
  EXPECT_LE(j["warm_time_us"]["median"].get<double>(), j["warm_time_us"]["max"].get<double>());
  ok("build small.obj --adb -o small.tree");
  const nlohmann::json t = nlohmann::json::parse(
      ok("query small.tree small.tree --pose 0.5,0,0 --strategy adb --repeat 3 --json").out);
  EXPECT_EQ(t["warm_time_us"]["queries"], 3);
}

// With a pose list, --repeat times passes over all the poses, so each pose gets its own warm times.
TEST_F(Cli, RepeatTimesPassesOverEveryPose) {
  testing::write_text(dir / "poses.txt", "0.5 0 0\n0.8 0 0\n3 0 0\n");
  const nlohmann::json j =
      nlohmann::json::parse(ok("query small.obj small.obj --poses poses.txt --repeat 4 --json").out);
  ASSERT_EQ(j["results"].size(), 3u) << j.dump();
  for (const auto& answer : j["results"]) EXPECT_EQ(answer["warm_time_us"]["queries"], 4) << answer.dump();
}

// ADB splits both nodes of a pair: on objects of very different size the CLI names the strategy made for it.
TEST_F(Cli, AdbOnObjectsOfDifferentSizeNamesAdbLarger) {
  const Outcome adb = ok("query big.obj small.obj --pose 0,0,0 --strategy adb");
  EXPECT_NE(adb.err.find("bvhlab: note: `adb` on big|small: the objects' root volumes differ by 1000×"),
            std::string::npos)
      << adb.err;
  EXPECT_NE(adb.err.find("`adb_larger` splits only the larger node"), std::string::npos) << adb.err;
  EXPECT_EQ(ok("query big.obj small.obj --pose 0,0,0 --strategy adb_larger").err.find("note:"),
            std::string::npos);
  EXPECT_EQ(ok("query small.obj small.obj --pose 0,0,0 --strategy adb").err.find("note:"), std::string::npos);
}

TEST_F(Cli, AllContactsListsThePairsInTextToo) {
  const std::string args = "query small.obj small.obj --pose 0.5,0.2,0.1 --all-contacts";
  const nlohmann::json j = nlohmann::json::parse(ok(args + " --json").out);
  const auto contacts = j["contacts"];
  ASSERT_GT(contacts.size(), 1u);
  const std::string text = ok(args).out;
  EXPECT_NE(text.find("contacts          " + std::to_string(contacts.size()) + " triangle pairs"),
            std::string::npos)
      << text;
  for (const auto& c : contacts)
    EXPECT_NE(
        text.find("\n    " + std::to_string(c[0].get<int>()) + " " + std::to_string(c[1].get<int>()) + "\n"),
        std::string::npos)
        << c << "\n"
        << text;
  // Naming the strategy lists them as the flag does.
  const nlohmann::json named = nlohmann::json::parse(
      ok("query small.obj small.obj --pose 0.5,0.2,0.1 --strategy all_contacts --json").out);
  EXPECT_EQ(named["contacts"], contacts);
}

// Two unit cubes 3 apart along x face each other across a gap of exactly 2.
TEST_F(Cli, DistanceAndToleranceAnswerWithTheirPoints) {
  const nlohmann::json j =
      nlohmann::json::parse(ok("query small.obj small.obj --pose 3,0,0 --strategy distance --json").out);
  EXPECT_FALSE(j["collides"].get<bool>());
  EXPECT_EQ(j["distance"]["distance"].get<double>(), 2.0) << j;
  EXPECT_EQ(j["distance"]["lower_bound"].get<double>(), 2.0) << j;
  EXPECT_EQ(j["distance"]["on_a"][0].get<double>(), 0.5) << j;
  EXPECT_EQ(j["distance"]["on_b"][0].get<double>(), 2.5) << j;
  EXPECT_EQ(j["distance"]["triangles"].size(), 2u) << j;
  const std::string text = ok("query small.obj small.obj --pose 3,0,0 --strategy distance").out;
  EXPECT_NE(text.find("  distance          2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  point on B        2.5 "), std::string::npos) << text;
  // In contact the distance is 0 with a witness; a pose list prints a distance column.
  const nlohmann::json touching = nlohmann::json::parse(
      ok("query small.obj small.obj --pose 0.5,0.2,0.1 --strategy distance --json").out);
  EXPECT_TRUE(touching["collides"].get<bool>());
  EXPECT_EQ(touching["distance"]["distance"].get<double>(), 0.0);
  EXPECT_TRUE(touching.contains("witness"));
  // --tolerance alone asks the tolerance query.
  EXPECT_TRUE(nlohmann::json::parse(
                  ok("query small.obj small.obj --pose 3,0,0 --tolerance 2.5 --json").out)["collides"]
                  .get<bool>());
  EXPECT_FALSE(nlohmann::json::parse(
                   ok("query small.obj small.obj --pose 3,0,0 --tolerance 1.5 --json").out)["collides"]
                   .get<bool>());
  expect_refused("query small.obj small.obj --pose 3,0,0 --tolerance -1",
                 "tolerance must be a number in [0, ");
  expect_refused("query small.obj small.obj --pose 3,0,0 --strategy exact --tolerance 1", "--tolerance");
  expect_refused("query small.obj small.obj --pose 3,0,0 --strategy distance --bv rbox",
                 "does not run on trees of volume 'rbox'");
  expect_refused("query small.obj small.obj --pose 3,0,0 --strategy distance_anytime", "needs --bv-tests");
  const nlohmann::json anytime = nlohmann::json::parse(
      ok("query small.obj small.obj --pose 3,0,0 --strategy distance_anytime --bv-tests 1 --json").out);
  EXPECT_LE(anytime["distance"]["lower_bound"].get<double>(), 2.0) << anytime;
}

#ifdef BVHLAB_HAVE_FCL
TEST_F(Cli, FclAnswersTheDistanceToo) {
  const std::string pose = " --pose 3,0.2,0.1,0,0,1,20 --strategy distance --json";
  const nlohmann::json fcl =
      nlohmann::json::parse(ok("query small.obj small.obj --bv fcl_obbrss" + pose).out);
  const nlohmann::json own = nlohmann::json::parse(ok("query small.obj small.obj --bv obb" + pose).out);
  const double d = own["distance"]["distance"].get<double>();
  EXPECT_GT(d, 1.0);
  EXPECT_NEAR(fcl["distance"]["distance"].get<double>(), d, 1e-12 * d) << fcl;
  // FCL's nearest points realise its distance, the one on A on A's face x = 0.5 (B turned about z meets it
  // with an edge: the points along it are not unique, so they are not compared with bvhlab's).
  const auto on_a = fcl["distance"]["on_a"].get<std::array<double, 3>>();
  const auto on_b = fcl["distance"]["on_b"].get<std::array<double, 3>>();
  EXPECT_NEAR(std::hypot(on_b[0] - on_a[0], on_b[1] - on_a[1], on_b[2] - on_a[2]), d, 1e-12 * d) << fcl;
  EXPECT_NEAR(on_a[0], 0.5, 1e-12) << fcl;
  expect_refused("query small.obj small.obj --bv fcl_obb" + pose, "does not run on fcl_obb");
}
#endif

TEST_F(Cli, ContactGeometryGivesEachContactItsSegment) {
  // B, the unit cube moved by (0.5, 0.2, 0.1), overlaps A in [0, 0.5] x [-0.3, 0.5] x [-0.4, 0.5].
  const nlohmann::json j = nlohmann::json::parse(
      ok("query small.obj small.obj --pose 0.5,0.2,0.1 --all-contacts --contact-geometry --json").out);
  ASSERT_GT(j["contacts"].size(), 0u) << j;
  ASSERT_EQ(j["contact_geometry"].size(), j["contacts"].size()) << j;
  for (std::size_t k = 0; k < j["contacts"].size(); ++k) {
    const nlohmann::json& g = j["contact_geometry"][k];
    EXPECT_EQ(g["triangles"], j["contacts"][k]);
    for (const char* end : {"from", "to", "point"}) {
      const auto p = g[end].get<std::array<double, 3>>();
      for (int c = 0; c < 3; ++c) {
        const double low = std::array{0.0, -0.3, -0.4}[c];
        EXPECT_GE(p[c], low - 1e-12) << g;
        EXPECT_LE(p[c], 0.5 + 1e-12) << g;
      }
    }
    const auto n = g["normal"].get<std::array<double, 3>>();
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-12) << g;
  }
  const std::string text = ok("query small.obj small.obj --pose 0.5,0.2,0.1 --contact-geometry").out;
  EXPECT_NE(text.find("  contact geometry  in A's frame"), std::string::npos) << text;
  expect_refused("query small.obj small.obj --pose 0.5,0,0 --strategy adb --contact-geometry",
                 "strategy adb tests no triangles");
  expect_refused("query small.obj small.obj --pose 0.5,0,0 --bv fcl_obb --contact-geometry",
                 "FCL hierarchies give no contact geometry");
}

TEST_F(Cli, PoseListsAreQueriedInOrder) {
  testing::write_text(dir / "poses.txt",
                      "# a pose per line\n0.5 0 0\n\n3,0,0\n0.9 0 0 0 0 1 45\n1 0 0 0  0 1 0 0  0 0 1 0\n");
  const nlohmann::json j =
      nlohmann::json::parse(ok("query small.obj small.obj --poses poses.txt --json").out);
  ASSERT_EQ(j["results"].size(), 4u);
  const int lines[] = {2, 4, 5, 6};
  const bool collides[] = {true, false, true, true};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(j["results"][k]["line"], lines[k]);
    EXPECT_EQ(j["results"][k]["collides"], collides[k]) << k;
  }
  const std::string text = ok("query small.obj small.obj --poses poses.txt --repeat 2").out;
  EXPECT_NE(text.find("small vs small, exact on aabb, 4 poses\n"), std::string::npos) << text;
  EXPECT_NE(text.find("warm_median_us"), std::string::npos) << text;
  EXPECT_NE(text.find("\n       6  yes "), std::string::npos) << text;
  EXPECT_NE(text.find("\n       4  no "), std::string::npos) << text;
  testing::write_text(dir / "bad.txt", "0.5 0 0\n0.5 0\n");
  expect_refused("query small.obj small.obj --poses bad.txt", "bad.txt:2: expected 3 numbers");
  expect_refused("query small.obj small.obj --poses poses.txt --pose 1,0,0",
                 "one of --pose, --protocol, --poses");
}

// Two --json runs of the same poses: the same exact answers, in order, some colliding and some not, and
// the second with less of `work` in all.
void expect_same_answers_with_less_work(const std::string& reference_out, const std::string& other_out,
                                        const char* work, std::size_t poses) {
  const nlohmann::json reference = nlohmann::json::parse(reference_out)["results"];
  const nlohmann::json other = nlohmann::json::parse(other_out)["results"];
  ASSERT_EQ(reference.size(), poses);
  ASSERT_EQ(other.size(), poses);
  std::size_t colliding = 0;
  std::uint64_t reference_work = 0, other_work = 0;
  for (std::size_t k = 0; k < poses; ++k) {
    EXPECT_EQ(other[k]["step"], k);
    EXPECT_EQ(other[k]["collides"], reference[k]["collides"]) << k;
    EXPECT_EQ(other[k]["exact"], true) << k;
    colliding += reference[k]["collides"].get<bool>();
    reference_work += reference[k][work].get<std::uint64_t>();
    other_work += other[k][work].get<std::uint64_t>();
  }
  EXPECT_GT(colliding, 0u);
  EXPECT_LT(colliding, poses);
  EXPECT_LT(other_work, reference_work) << work;
}

// --coherent over a protocol turn (--protocol DISTANCE,STEPS: every step in order): the cold answers, with
// fewer BV tests in all; strategies that do not run coherent and FCL hierarchies are refused by name.
TEST_F(Cli, CoherentQueriesAnswerAsColdOverAProtocolTurn) {
  testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
  const std::string turn = "query torus.obj torus.obj --protocol 1.2,120 --json";
  expect_same_answers_with_less_work(ok(turn).out, ok(turn + " --coherent").out, "bv_tests", 120);
  const std::string text = ok("query torus.obj torus.obj --protocol 1.2,120 --coherent --all-contacts").out;
  EXPECT_NE(text.find("torus vs torus, all_contacts coherent on aabb, 120 poses\n"), std::string::npos)
      << text;
  // The ADB strategies remember their deciding pair (the refusal by name: tests/bench/test_policies.cpp).
  const nlohmann::json adb =
      nlohmann::json::parse(ok(turn + " --strategy adb --density adb --coherent").out)["results"];
  ASSERT_EQ(adb.size(), 120u);
#ifdef BVHLAB_HAVE_FCL
  expect_refused("query torus.obj torus.obj --protocol 1.2,120 --coherent --bv fcl_obb",
                 "FCL hierarchies do not run coherent");
#endif
  expect_refused("query torus.obj torus.obj --protocol 1.2",
                 "expected DISTANCE,STEP,STEPS or DISTANCE,STEPS");
}

// --wide over a protocol turn: the binary walk's answers on fewer node pairs; refused by name where it does
// not run (a strategy without a wide walk, a volume without a layout, coherent, FCL).
TEST_F(Cli, WideQueriesAnswerAsTheBinaryWalk) {
  testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
  const std::string turn = "query torus.obj torus.obj --protocol 1.2,120 --json --bv obb";
  // Fewer node pairs: four children settled a step.
  expect_same_answers_with_less_work(ok(turn).out, ok(turn + " --wide").out, "nodes_visited", 120);
  const std::string text =
      ok("query torus.obj torus.obj --protocol 1.2,12 --bv dop24 --wide --all-contacts").out;
  EXPECT_NE(text.find("torus vs torus, all_contacts wide on dop24, 12 poses\n"), std::string::npos) << text;
  // ADB's wide walk: its own answers, four BV tests a step after the roots.
  const std::string adb_text =
      ok("query torus.obj torus.obj --protocol 1.2,12 --density adb --strategy adb --wide").out;
  EXPECT_NE(adb_text.find("torus vs torus, adb p_min=0.9 wide on aabb, 12 poses\n"), std::string::npos)
      << adb_text;
  expect_refused(
      "query torus.obj torus.obj --pose 1,0,0 --wide --strategy adb_dfs --density adb",
      "strategy adb_dfs does not run on wide trees (the strategies that do: exact, all_contacts, adb, "
      "time_critical, distance)");
  expect_refused("query torus.obj torus.obj --pose 1,0,0 --wide --bv rss",
                 "bounding volume 'rss' has no wide layout (the volumes that do: aabb, ");
  expect_refused("query torus.obj torus.obj --pose 1,0,0 --wide --coherent", "give --coherent or --wide");
#ifdef BVHLAB_HAVE_FCL
  expect_refused("query torus.obj torus.obj --pose 1,0,0 --wide --bv fcl_obb",
                 "FCL hierarchies have no wide");
#endif
}

// ---------------------------------------------------------------------------------------------------------
// Per-pose output

// run and report write poses.csv only with --per-pose; a bad value is refused by name before any work.
TEST_F(Cli, PerPoseIsWrittenOnlyWhenAsked) {
  testing::write_text(dir / "s.json", R"({"objects": [{"mesh": "small.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "workload": {"distances": [0.9, 1.2], "steps": 6},
      "report": {"cgal_sample": 0}})");
  expect_refused("run s.json -o none --per-pose some -q",
                 "--per-pose: expected one of none, all, wrong; got \"some\"");
  EXPECT_FALSE(std::filesystem::exists(dir / "none"));
  ok("run s.json -o plain -q");
  EXPECT_TRUE(std::filesystem::exists(dir / "plain" / "results.csv"));
  EXPECT_FALSE(std::filesystem::exists(dir / "plain" / "poses.csv"));
  ok("run s.json -o all -q --per-pose all");
  EXPECT_EQ(testing::read_csv(dir / "all" / "poses.csv").size(), 1u + 2 * 6);
  ok("report s.json -o report -q --no-figures --per-pose wrong");
  const auto wrong = testing::read_csv(dir / "report" / "poses.csv");  // exact answers: header only
  ASSERT_EQ(wrong.size(), 1u);
  EXPECT_EQ(wrong[0][9], "pose");
}

// A deform scene keeps rows per frame, not per query: --per-pose is refused there by name, not ignored.
TEST_F(Cli, PerPoseIsRefusedForADeformScene) {
  testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj");
  testing::write_text(dir / "d.json", R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "deform": {"object": "torus", "deformation": "twist:amplitude=2",
      "frames": 2, "poses": {"distances": [1.2], "steps": 4}}})");
  expect_refused("run d.json -o out -q --per-pose all", "--per-pose: does not apply to a deform scene");
  expect_refused("report d.json -o out -q --no-figures --per-pose wrong",
                 "--per-pose: does not apply to a deform scene");
  // A README snippet summarizes a pairs report only: asked of another kind, it is refused, not ignored.
  expect_refused("report d.json -o out -q --no-figures --snippet snippet.md",
                 "--snippet: does not apply to a deform scene");
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  EXPECT_FALSE(std::filesystem::exists(dir / "snippet.md"));
}

// The pose column pasted into `bvhlab query` (as a pose list, one per line as --pose takes it) gives the
// run's answer for each series, and the exact strategy the truth.
TEST_F(Cli, PosesOfPerPoseOutputQueryBackToTheSameAnswers) {
  testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
  testing::write_text(dir / "s.json", R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
      "annotation": {"type": "adb"}, "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.5}],
      "workload": {"distances": [0.8, 1.4], "steps": 10}, "report": {"cgal_sample": 0}})");
  ok("run s.json -o out -q --per-pose all");
  const auto csv = testing::read_csv(dir / "out" / "poses.csv");
  ASSERT_EQ(csv.size(), 1u + 2 * 2 * 10);
  const auto& header = csv[0];
  const auto col = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (const std::string label : {"exact", "adb p_min=0.5"}) {
    std::string list;
    std::vector<const std::vector<std::string>*> rows;
    for (std::size_t i = 1; i < csv.size(); ++i)
      if (csv[i][col("label")] == label) {
        list += csv[i][col("pose")] + "\n";
        rows.push_back(&csv[i]);
      }
    testing::write_text(dir / "poses.txt", list);
    const std::string strategy = label == "exact" ? "--strategy exact" : "--strategy adb --p-min 0.5";
    const nlohmann::json j =
        nlohmann::json::parse(ok("query torus.obj torus.obj --poses poses.txt --json " + strategy).out);
    ASSERT_EQ(j["results"].size(), rows.size()) << label;
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& row = *rows[k];
      EXPECT_EQ(j["results"][k]["collides"], row[col("answer")] == "1") << label << " " << k;
      if (label == "exact") {
        EXPECT_EQ(j["results"][k]["collides"], row[col("truth")] == "1") << k;
      }
      EXPECT_EQ(j["results"][k]["bv_tests"], std::stoull(row[col("bv_tests")])) << label << " " << k;
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// Point cloud files

/// 150 points on the surface of the cube [-0.5, 0.5]^3 (a 5 x 5 grid on each face), as a PLY without faces.
void write_cube_points(const std::filesystem::path& file) {
  std::string body;
  for (int axis = 0; axis < 3; ++axis)
    for (double side : {-0.5, 0.5})
      for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
          double p[3];
          p[axis] = side;
          p[(axis + 1) % 3] = -0.4 + 0.2 * i;
          p[(axis + 2) % 3] = -0.4 + 0.2 * j;
          body += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
        }
  testing::write_text(file,
                      "ply\nformat ascii 1.0\nelement vertex 150\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n" +
                          body);
}

// A PLY without faces is a point cloud to info and query, as --cloud would make it, not a mesh refused for
// having no faces.
TEST_F(Cli, APointCloudFileIsReadAsACloudByInfoAndQuery) {
  write_cube_points(dir / "points.ply");
  const Outcome info = ok("info points.ply");
  EXPECT_NE(info.out.find("(point cloud)"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("points          150"), std::string::npos) << info.out;
  EXPECT_TRUE(nlohmann::json::parse(ok("info points.ply --json").out)["point_cloud"].get<bool>());
  for (const char* pose : {" --pose 5,0,0", " --pose 0,0,0", " --pose 20,0,0"}) {
    const Outcome detected = ok(std::string("query big.obj points.ply --json") + pose);
    EXPECT_NE(detected.err.find("queried as with --cloud b"), std::string::npos) << detected.err;
    const Outcome told = ok(std::string("query big.obj points.ply --json --cloud b") + pose);
    EXPECT_EQ(nlohmann::json::parse(detected.out)["collides"], nlohmann::json::parse(told.out)["collides"])
        << pose;
  }
}

// ---------------------------------------------------------------------------------------------------------
// Exit statuses, output paths, warnings

// The loader warns about coordinates far from the origin (precision lost in reading); `query` on the same
// file says so as `info` does.
TEST_F(Cli, TheLoadersWarningsReachQueryAsTheyReachInfo) {
  write_cube(dir / "far.obj", 4, 1e7);  // |x| / diagonal = 1.4e6: past the limit of a float or double reader
  const Outcome info = ok("info far.obj");
  ASSERT_NE(info.out.find("far from the origin"), std::string::npos) << info.out;
  const Outcome query = ok("query far.obj far.obj --pose 0,0,0");
  EXPECT_NE(query.err.find("bvhlab: warning: far: coordinates are far from the origin"), std::string::npos)
      << query.err;
  EXPECT_EQ(ok("query big.obj small.obj --pose 0,0,0").err.find("warning"), std::string::npos);
}

// A bad command line exits 2 with the prefix, as every other refusal has it; a failure in the work exits 1.
TEST_F(Cli, ABadCommandLineExitsTwoAndAFailureOneBothWithThePrefix) {
  EXPECT_EQ(expect_refused("query big.obj small.obj --no-such-option", "--no-such-option").status, 2);
  EXPECT_EQ(expect_refused("query big.obj", "required").status, 2);
  EXPECT_EQ(expect_refused("build big.obj --leaf 0 -o x.tree", "--leaf").status, 2);
  EXPECT_EQ(expect_refused("info missing.obj", "missing.obj").status, 1);
  const Outcome help = ok("query --help");
  EXPECT_NE(help.out.find("--pose"), std::string::npos) << help.out;
}

// An output path that cannot be written is refused before any tree is built or any scene runs.
TEST_F(Cli, OutputPathsAreCheckedBeforeAnyWork) {
  const Outcome build = expect_refused("build big.obj --adb -o missing/x.tree", "does not exist");
  EXPECT_EQ(build.status, 2);
  EXPECT_EQ(build.err.find("building"), std::string::npos) << build.err;
  EXPECT_EQ(build.err.find("annotating"), std::string::npos) << build.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "missing"));
  expect_refused("build big.obj -o .", "is a folder");
  testing::write_text(dir / "scene.json",
                      R"({"objects": [{"mesh": "big.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "workload": {"type": "protocol", "distances": [1.2], "steps": 10}})");
  testing::write_text(dir / "taken", "a file where the report folder should go");
  const Outcome report =
      expect_refused("report scene.json -o taken/report --no-figures", "cannot make folder");
  EXPECT_EQ(report.err.find("building"), std::string::npos) << report.err;
  expect_refused("report scene.json -o report --no-figures --snippet missing/snippet.md", "does not exist");
  EXPECT_FALSE(std::filesystem::exists(dir / "report" / "results.csv"));
}

}  // namespace
}  // namespace bvhlab
