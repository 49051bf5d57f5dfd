// The points scene: its section is parsed with every refusal named, and a report run on the small shipped
// scene writes rows that agree with the scene (every density, distance and series) and with each other.
#include "bench/points/points.hpp"
#include "bench/run.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <set>
#include <sstream>

namespace bvhlab {
namespace {

class PointsSceneTest : public testing::SceneParsing {
 protected:
  PointsSceneTest() : SceneParsing("points.json") {}
  void SetUp() override { testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj"); }
};

std::string points_scene(const std::string& points, const std::string& extra = "") {
  return R"({"objects": [{"mesh": "torus.obj", "normalize": true}])" + extra + R"(, "points": )" + points +
         "}";
}

TEST_F(PointsSceneTest, TheSectionIsReadWithItsDefaults) {
  const Scene scene = parse(points_scene(R"({"densities": [100, 400], "sampling": "varying", "ratio": 2,
                                             "distances": [1.5], "steps": 3, "p_min": [0.9]})"));
  ASSERT_TRUE(scene.points);
  EXPECT_EQ(scene.points->densities, (std::vector<double>{100, 400}));
  EXPECT_TRUE(scene.points->varying);
  EXPECT_DOUBLE_EQ(scene.points->ratio, 2);
  EXPECT_EQ(scene.points->steps, 3);
  EXPECT_EQ(scene.points->p_mins, (std::vector<double>{0.9}));
  EXPECT_EQ(scene.points->bv_tests, (std::vector<double>{50, 200}));
  EXPECT_TRUE(scene.points->confirm_levels.empty());  // no confirmed series unless asked for
  const Scene confirmed = parse(points_scene(R"({"confirm_levels": [2, 4], "confirm_p_min": [0.95]})"));
  EXPECT_EQ(confirmed.points->confirm_levels, (std::vector<double>{2, 4}));
  EXPECT_EQ(confirmed.points->confirm_p_mins, (std::vector<double>{0.95}));
  ASSERT_EQ(scene.pairs.size(), 1u);
  EXPECT_EQ(scene.pairs[0].label(), "torus");
}

TEST_F(PointsSceneTest, RefusalsNameTheField) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {points_scene(R"({"densities": [10]})"), "/points/densities/0: a cloud needs at least 11 points"},
      {points_scene(R"({"densities": [2.5]})"), "/points/densities/0: expected an integer"},
      {points_scene(R"({"densities": []})"), "/points/densities: expected a non-empty array"},
      {points_scene(R"({"p_min": [0.9, 0]})"), "/points/p_min/1: expected a p_min in (0, 1]"},
      {points_scene(R"({"p_min": [1.5]})"), "/points/p_min/0"},
      {points_scene(R"({"sampling": "grid"})"), "/points/sampling: expected one of uniform, varying"},
      {points_scene(R"({"ratio": 3})"), "/points/ratio: applies to \"sampling\": \"varying\" only"},
      {points_scene(R"({"steps": 0})"), "/points/steps"},
      {points_scene(R"({"distances": [1, 2], "steps": 500001})"),
       "/points: 2 distances of 500001 steps make 1000002 poses; a scene generates at most 1000000"},
      {points_scene(R"({"distances": []})"), "/points/distances"},
      {points_scene(R"({"grid": 5})"), "/points/grid"},
      {points_scene(R"({"bv_tests": [0]})"), "/points/bv_tests/0"},
      {points_scene(R"({"confirm_levels": [0]})"), "/points/confirm_levels/0"},
      {points_scene(R"({"confirm_levels": [256]})"), "/points/confirm_levels/0"},
      {points_scene(R"({"confirm_levels": [2], "confirm_p_min": [0]})"), "/points/confirm_p_min/0"},
      {points_scene(R"({"confirm_p_min": [0.9]})"),
       "/points/confirm_p_min: applies with \"confirm_levels\" only"},
      {points_scene(R"({"pmin": [0.9]})"), "/points/pmin: unknown field"},
      {points_scene("{}", R"(, "strategies": [{"type": "exact"}])"),
       "/strategies: does not apply to a points"},
      {points_scene("{}", R"(, "pairs": [["torus", "ring"]])"), "/pairs/0/1: no object named \"ring\""},
#ifdef BVHLAB_HAVE_FCL
      {points_scene(R"({"octree_res": [1, 0]})"), "/points/octree_res/1: expected a voxel side"},
#else
      {points_scene(R"({"octree_res": [1]})"), "/points/octree_res: FCL's octree needs a build with FCL"},
#endif
  };
  for (const auto& [text, expected] : cases)
    EXPECT_NE(error_of(text).find(expected), std::string::npos) << text << "\n" << error_of(text);
}

TEST_F(PointsSceneTest, TheRunnerRefusesASceneWithoutPoints) {
  const Scene scene = parse(R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
                                "strategies": [{"type": "exact"}], "workload": {"steps": 2}})");
  EXPECT_THROW(run_points(scene, true), std::invalid_argument);
}

TEST_F(PointsSceneTest, TheMeshRunnerRefusesAPointsScene) {
  EXPECT_THROW(run_scene(parse(points_scene(R"({"densities": [100]})")), RunOptions{}),
               std::invalid_argument);
}

/// A CSV file as rows of named cells (the report's quoting: strings in double quotes, no commas inside).
std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& file) {
  std::istringstream text(testing::read_text(file));
  std::vector<std::string> header;
  std::vector<std::map<std::string, std::string>> rows;
  for (std::string line; std::getline(text, line);) {
    std::vector<std::string> cells;
    std::istringstream cells_text(line);
    for (std::string cell; std::getline(cells_text, cell, ',');)
      cells.push_back(cell.size() >= 2 && cell.front() == '"' ? cell.substr(1, cell.size() - 2) : cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    EXPECT_EQ(cells.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < std::min(cells.size(), header.size()); ++c) row[header[c]] = cells[c];
    rows.push_back(row);
  }
  return rows;
}

std::size_t count(const std::map<std::string, std::string>& row, const std::string& column) {
  return std::stoul(row.at(column));
}

/// The series a scene's "points" asks for, by the label prefixes the runner gives them.
std::size_t expected_series(const PointsSpec& spec) {
  return 3 + spec.p_mins.size() + spec.confirm_levels.size() * spec.confirm_p_mins.size() +
         spec.bv_tests.size() + spec.octree_res.size();
}

TEST(PointsReport, RowsCoverTheSceneAndAgreeWithEachOther) {
  const char* source = std::getenv("BVHLAB_SOURCE_DIR");
  ASSERT_NE(source, nullptr) << "run through ctest, which sets BVHLAB_SOURCE_DIR";
  const Scene scene = load_scene(std::filesystem::path(source) / "bench" / "scenes" / "points_small.json");
  ASSERT_TRUE(scene.points);
  const PointsSpec& spec = *scene.points;
  testing::TempDir dir;
  write_points_csv(run_points(scene, true), dir.path());
  const auto rows = read_csv(dir / "points_rows.csv");
  const auto totals = read_csv(dir / "points_summary.csv");
  ASSERT_EQ(rows.size(), spec.densities.size() * spec.distances.size() * expected_series(spec));
  ASSERT_EQ(totals.size(), spec.densities.size() * expected_series(spec));

  std::set<std::string> series;
  std::set<std::tuple<std::size_t, double, std::string>> cells;
  std::map<std::pair<std::size_t, double>, std::tuple<std::size_t, std::size_t, std::size_t>> truth;
  std::map<std::pair<std::size_t, std::string>, std::array<std::size_t, 5>> sums;
  for (const auto& r : rows) {
    const std::size_t points = count(r, "points"), clear = count(r, "clear"),
                      colliding = count(r, "colliding");
    const double distance = std::stod(r.at("distance"));
    series.insert(r.at("series"));
    EXPECT_TRUE(cells.insert({points, distance, r.at("series")}).second) << "a row twice: " << r.at("series");
    EXPECT_EQ(count(r, "poses"), std::size_t(spec.steps));
    EXPECT_EQ(clear + count(r, "ambiguous"), count(r, "poses"));
    EXPECT_LE(colliding, clear);
    EXPECT_LE(count(r, "fp"), clear - colliding) << r.at("series");
    EXPECT_LE(count(r, "fn"), colliding) << r.at("series");
    EXPECT_GE(std::stod(r.at("median_us")), 0);
    EXPECT_GE(std::stod(r.at("mean_us")), 0);
    // The truth is per pose: every series of a cloud and distance sees the same clear and colliding poses.
    const auto [it, fresh] = truth.try_emplace({points, distance}, clear, count(r, "ambiguous"), colliding);
    if (!fresh) {
      EXPECT_EQ(it->second, std::make_tuple(clear, count(r, "ambiguous"), colliding)) << r.at("series");
    }
    auto& sum = sums[{points, r.at("series")}];
    for (std::size_t c = 0; const char* column : {"poses", "clear", "colliding", "fp", "fn"})
      sum[c++] += count(r, column);
  }
  EXPECT_EQ(series.size(), expected_series(spec));
  for (const char* name : {"exact_mesh", "exact_points", "exact_points_vs_mesh"})
    EXPECT_TRUE(series.count(name));
  ASSERT_FALSE(spec.confirm_levels.empty()) << "points_small.json should run a confirmed series";
  std::ostringstream confirmed;  // default stream formatting is %g, as the runner's labels
  confirmed << "adb p_min=" << spec.confirm_p_mins.front()
            << " confirm_levels=" << spec.confirm_levels.front();
  EXPECT_TRUE(series.count(confirmed.str())) << confirmed.str();
  for (const auto& t : totals) {
    const auto& sum = sums.at({count(t, "points"), t.at("series")});
    for (std::size_t c = 0; const char* column : {"poses", "clear", "colliding", "fp", "fn"})
      EXPECT_EQ(count(t, column), sum[c++]) << t.at("series") << " " << column;
  }
}

}  // namespace
}  // namespace bvhlab
