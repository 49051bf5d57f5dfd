// The report follows its scene: the distances it summarises are the ones the run has, a pose file is
// summarised over all its poses unless the scene says otherwise, the workload text names the scene's
// objects and units, and a strategy that reads no density is sized without one.
#include "bench/pairs/report.hpp"
#include "bench/run.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace bvhlab {
namespace {

using testing::TempDir;

class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
    testing::write_obj(testing::make_torus(0.5, 0.2, 16, 8), dir / "ring.obj");
    options.cache_dir.clear();
    options.threads = 2;
    options.warmup_queries = 0;
    options.log = [](const std::string&) {};
  }

  /// A protocol scene on the torus; `extra` adds or overrides top-level fields.
  Scene protocol_scene(const std::string& distances, const std::string& extra = "") {
    return parse_scene(R"({"name": "r", "objects": [{"mesh": "torus.obj", "normalize": true}],
        "hierarchies": [{"bv": "aabb"}, {"bv": "dop24"}],
        "annotation": {"type": "adb", "grid": 2, "tau": 0.5},
        "strategies": [{"type": "exact"}, {"type": "adb", "p_min": [0.9], "hierarchies": ["aabb"]}],
        "workload": {"distances": )" +
                           distances + R"(, "steps": 8}, "report": {"cgal_sample": 2)" + extra + "}}",
                       dir.path(), "r.json");
  }

  std::string readme(const RunOutput& run) {
    ReportOptions no_figures;
    no_figures.figures = false;
    return testing::read_text(write_report(run, dir / "report", no_figures).readme);
  }

  TempDir dir;
  RunOptions options;
};

TEST_F(ReportTest, NamesTheDistancesTheRunHasNotTheWholeQualityRange) {
  const RunOutput run =
      run_scene(protocol_scene("[0.8, 1.2, 1.6]", R"(, "quality_distances": [1.2, 2])"), options);
  const std::string text = readme(run);
  EXPECT_NE(text.find("distances 1.2–1.6 (the scene's quality_distances)"), std::string::npos) << text;
  EXPECT_EQ(text.find("1.2–2"), std::string::npos) << text;
}

// Without quality distances, each pair's band is where its ground truth has 5% to 95% colliding poses; the
// summary, the operating point and results.csv's in_summary column all use it.
TEST_F(ReportTest, TheDefaultBandFollowsTheGroundTruth) {
  const RunOutput run = run_scene(protocol_scene("[0.2, 0.8, 1.2, 1.4, 1.6, 2.4]"), options);
  std::vector<double> mixed;
  for (const TruthSummary& t : run.truth) {
    const double share = double(t.colliding) / double(t.poses);
    if (share >= 0.05 && share <= 0.95) mixed.push_back(t.distance);
  }
  ASSERT_FALSE(mixed.empty()) << "the torus at these distances should collide at some poses only";
  std::size_t inside = 0;
  for (const ResultRow& r : run.rows) {
    EXPECT_EQ(r.in_summary, r.distance >= mixed.front() && r.distance <= mixed.back()) << r.distance;
    inside += r.in_summary && r.label == "adb p_min=0.9" ? r.queries : 0;
  }
  ASSERT_EQ(operating_points(run).size(), 1u);
  EXPECT_EQ(operating_points(run)[0].adb.queries, inside);
  EXPECT_NE(readme(run).find("where the ground truth has 5% to 95% colliding poses"), std::string::npos);
}

TEST_F(ReportTest, PoseFileGroupsAreSummarisedWhereTheSceneSays) {
  testing::write_text(dir / "poses.json", R"({"poses": [
      {"translation": [0, 0, 0], "group": 0}, {"translation": [0.3, 0, 0], "group": 0},
      {"translation": [1.5, 0, 0], "group": 1.5}, {"translation": [5, 0, 0], "group": 5}]})");
  const auto pose_scene = [&](const std::string& report) {
    return parse_scene(R"({"objects": [{"mesh": "torus.obj", "normalize": true}],
        "hierarchies": [{"bv": "aabb"}, {"bv": "dop24"}], "annotation": {"type": "adb", "grid": 2, "tau": 0.5},
        "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.9, "hierarchies": ["aabb"]}],
        "workload": {"type": "poses", "file": "poses.json", "axis": "group"}, "report": {"cgal_sample": 1)" +
                           report + "}}",
                       dir.path(), "p.json");
  };
  const RunOutput some = run_scene(pose_scene(R"(, "quality_distances": [1, 2])"), options);
  ASSERT_EQ(operating_points(some).size(), 1u);
  EXPECT_EQ(operating_points(some)[0].adb.queries, 1u);
  EXPECT_NE(readme(some).find("pose group 1.5 (the scene's quality_distances); 1 poses"), std::string::npos)
      << readme(some);
}

// A workload of random poses is summarised over all of them: the figures take that range too (its lower end,
// -1e300, once reached the plot script as an option name and no figure was drawn).
TEST_F(ReportTest, FiguresAreDrawnForRandomPoses) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0 &&
      std::system("python3 -c 'import matplotlib' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "no Python with matplotlib";
  const Scene random = parse_scene(R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
      "annotation": {"type": "adb", "grid": 2, "tau": 0.5},
      "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.9}],
      "workload": {"type": "random", "count": 8, "box": [[-1, -1, -1], [1, 1, 1]]}, "report": {"cgal_sample": 1}})",
                                   dir.path(), "random.json");
  const ReportFiles files = write_report(run_scene(random, options), dir / "report");
  EXPECT_EQ(files.plot_error, "");
  EXPECT_FALSE(files.figures.empty());
}

// A pair of two objects is labelled "a|b": in the README's tables the bar must not split a cell, so every
// table row keeps as many cells as its header.
TEST_F(ReportTest, PairLabelsKeepTheTablesColumns) {
  const Scene pair = parse_scene(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "ring.obj"}],
      "pairs": [["torus", "ring"]], "hierarchies": [{"bv": "aabb"}],
      "annotation": {"type": "adb", "grid": 2, "tau": 0.5},
      "strategies": [{"type": "exact"}, {"type": "adb", "p_min": 0.9}],
      "workload": {"type": "random", "count": 8, "box": [[-1, -1, -1], [1, 1, 1]]}, "report": {"cgal_sample": 1}})",
                                 dir.path(), "pair.json");
  const std::string text = readme(run_scene(pair, options));
  auto cells = [](const std::string& line) {  // unescaped bars
    int bars = 0;
    for (std::size_t i = 0; i < line.size(); ++i) bars += line[i] == '|' && (i == 0 || line[i - 1] != '\\');
    return bars;
  };
  std::istringstream lines(text);
  std::string line;
  int header = 0, rows = 0;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] != '|') {
      header = 0;
      continue;
    }
    if (!header) {
      header = cells(line);
      continue;
    }
    EXPECT_EQ(cells(line), header) << line;
    rows += line.find("torus\\|ring") != std::string::npos;
  }
  EXPECT_GT(rows, 3);
}

TEST_F(ReportTest, WorkloadTextAndDistanceLabelFollowTheSceneObjects) {
  const Scene normalised = protocol_scene("[1.2]");
  const std::string normalised_text = readme(run_scene(normalised, options));
  EXPECT_NE(normalised_text.find("`torus` (torus.obj, normalised: centred, longest side 2) against a copy of "
                                 "itself"),
            std::string::npos)
      << normalised_text;
  EXPECT_NE(normalised_text.find("normalised model's units"), std::string::npos);
  EXPECT_NE(distance_label(normalised).find("normalised"), std::string::npos);

  const Scene raw = parse_scene(R"({"objects": [{"mesh": "torus.obj", "normalize": false},
      {"mesh": "ring.obj", "normalize": false, "scale": 0.5}], "pairs": [["torus", "ring"]],
      "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
      "workload": {"distances": [1.2], "steps": 4}, "report": {"cgal_sample": 1}})",
                                dir.path(), "raw.json");
  const std::string raw_text = readme(run_scene(raw, options));
  EXPECT_NE(raw_text.find("`torus` (torus.obj, in its file's units) against `ring` (ring.obj, in its file's "
                          "units, scaled by 0.5)"),
            std::string::npos)
      << raw_text;
  EXPECT_EQ(raw_text.find("normalised"), std::string::npos) << raw_text;
  EXPECT_NE(distance_label(raw).find("scene units"), std::string::npos);
}

TEST_F(ReportTest, AStrategyWithoutDensityIsSizedWithoutTheAnnotation) {
  const RunOutput annotated = run_scene(protocol_scene("[1.2]"), options);
  const RunOutput plain = run_scene(parse_scene(R"({"objects": [{"mesh": "torus.obj", "normalize": true}],
      "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
      "workload": {"distances": [1.2], "steps": 8}, "report": {"cgal_sample": 1}})",
                                                dir.path(), "plain.json"),
                                    options);
  const auto row_of = [](const RunOutput& run, const std::string& strategy) {
    for (const ResultRow& r : run.rows)
      if (r.hierarchy == "aabb" && r.strategy == strategy) return r;
    ADD_FAILURE() << "no aabb " << strategy << " row";
    return ResultRow{};
  };
  const ResultRow exact = row_of(annotated, "exact"), adb = row_of(annotated, "adb");
  EXPECT_DOUBLE_EQ(exact.bytes_per_triangle, row_of(plain, "exact").bytes_per_triangle);
  EXPECT_GT(adb.bytes_per_triangle, exact.bytes_per_triangle);  // the annotation is not free
}

TEST(ErrorTimeFront, FastestExactAgainstFastestInexactWithinTheErrorBound) {
  auto series = [](std::string mesh, std::string label, bool exact, double us, double fp, double fn) {
    SeriesSummary s;
    s.mesh = std::move(mesh);
    s.hierarchy = "aabb";
    s.label = std::move(label);
    s.exact_strategy = exact;
    s.mean_time_us = us;
    s.fp_rate = fp;
    s.fn_rate = fn;
    return s;
  };
  const std::vector<SeriesSummary> all = {
      series("jeep", "exact", true, 10, 0, 0),       series("jeep", "exact dop", true, 8, 0, 0),
      series("jeep", "adb 0.5", false, 1, 0.3, 0),   series("jeep", "adb 0.9", false, 2, 0.03, 0.01),
      series("jeep", "adb 0.99", false, 4, 0.01, 0), series("bunny", "exact", true, 6, 0, 0),
      series("bunny", "adb 0.9", false, 1, 0.05, 0)};
  const auto front = error_time_front(all, 0.04);
  ASSERT_EQ(front.size(), 2u);
  EXPECT_EQ(front[0].mesh, "jeep");
  ASSERT_TRUE(front[0].fastest_exact && front[0].fastest_inexact);
  EXPECT_EQ(front[0].fastest_exact->label, "exact dop");
  EXPECT_EQ(front[0].fastest_inexact->label, "adb 0.9");  // 4% wrong: within the bound, faster than 0.99
  EXPECT_DOUBLE_EQ(front[0].speedup, 4.0);
  EXPECT_EQ(front[1].mesh, "bunny");
  EXPECT_FALSE(front[1].fastest_inexact);  // 5% wrong is outside
  EXPECT_EQ(front[1].speedup, 0.0);
}

/// A point of a p_min curve on mesh "m", hierarchy "aabb": 200 poses, each `us` within ±20%, in a pattern
/// that `phase` shifts (so that two points' per-pose ratios vary as measured ones do).
SeriesSummary curve_point(const std::string& label, double p_min, double bv_tests, double us, int phase) {
  SeriesSummary s;
  s.mesh = "m";
  s.hierarchy = "aabb";
  s.strategy = "adb";
  s.label = label;
  s.exact_strategy = false;
  s.p_min = p_min;
  s.bv_tests_per_query = s.estimates_per_query = bv_tests;
  for (int k = 0; k < 200; ++k) s.pose_times_us.push_back(us * (1 + 0.2 * ((k * 7 + phase) % 5 - 2) / 2));
  s.mean_time_us = us;
  return s;
}

TEST(PminCurves, AStepGoesAgainstItsWorkOnlyWhenItsIntervalSaysSo) {
  const std::vector<SeriesSummary> series = {
      curve_point("adb p_min=0.5", 0.5, 4, 1.0, 0),
      curve_point("adb p_min=0.8", 0.8, 8.1, 2.1, 1),
      curve_point("adb p_min=0.9", 0.9, 12.4, 1.2, 2),     // more work, measurably less time: against
      curve_point("adb p_min=0.95", 0.95, 12.45, 3.0, 3),  // same work (within 1%): no direction
      curve_point("adb p_min=0.99", 0.99, 20, 2.98, 4),    // more work, less time within the noise
      curve_point("adb p_min=0.9 confirm_levels=1", 0.9, 30, 0.5, 0)};  // a curve of its own
  const std::vector<CurveStep> steps = pmin_curve_steps(series);
  ASSERT_EQ(steps.size(), 4u);
  for (const CurveStep& s : steps) EXPECT_EQ(s.curve, "adb");
  EXPECT_FALSE(steps[0].against_work);
  EXPECT_TRUE(steps[1].against_work);
  EXPECT_DOUBLE_EQ(steps[1].p_min, 0.8);
  EXPECT_NEAR(steps[1].time_ratio.value, 1.2 / 2.1, 1e-9);
  EXPECT_LT(steps[1].time_ratio.hi, 1);
  EXPECT_TRUE(steps[2].same_work);
  EXPECT_FALSE(steps[2].against_work);
  EXPECT_FALSE(steps[3].against_work);
  EXPECT_TRUE(steps[3].time_ratio.contains(1));
  EXPECT_TRUE(pmin_curve_steps({series.back()}).empty());
}

/// One decile of a series on mesh "m", hierarchy "aabb", strategy "adb".
CalibrationBin decile(double p_min, int bin, std::size_t count, double reported, double observed) {
  CalibrationBin b{"m", "aabb", "adb", "", p_min};
  b.bin_low = bin / 10.0;
  b.bin_high = (bin + 1) / 10.0;
  b.count = count;
  b.mean_probability = reported;
  b.collision_frequency = observed;
  return b;
}

TEST(CalibrationSummary, JudgesOnlyDecilesWithEnoughAnswers) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<CalibrationBin> bins{
      // p_min 0.9: within 0.05 where it counts; the 10-answer decile is far off but too small to judge.
      decile(0.9, 1, 100, 0.15, 0.12), decile(0.9, 5, 10, 0.55, 0.0), decile(0.9, 9, 60, 0.95, 0.99),
      decile(0.9, 0, 50, 0.02, 0.0), decile(0.9, 3, 0, nan, nan),
      // p_min 0.5: 50 answers exactly qualify (gap 0.06, too far); 49 do not (gap 0.9).
      decile(0.5, 2, 50, 0.26, 0.20), decile(0.5, 7, 49, 0.9, 0.0), decile(0.5, 8, 500, 0.85, 0.83),
      // p_min 0.7: answers, but no decile holds enough of them.
      decile(0.7, 4, 30, 0.45, 0.4)};
  const auto s = calibration_summary(bins, {});
  ASSERT_EQ(s.size(), 3u);

  EXPECT_EQ(s[0].p_min, 0.9);
  EXPECT_EQ(s[0].answers, 220u);
  EXPECT_EQ(s[0].qualifying_bins, 3u);
  EXPECT_TRUE(s[0].judgeable);
  EXPECT_NEAR(s[0].max_gap, 0.04, 1e-12);
  EXPECT_DOUBLE_EQ(s[0].worst_low, 0.9);
  EXPECT_TRUE(s[0].meets);

  EXPECT_EQ(s[1].qualifying_bins, 2u);
  EXPECT_NEAR(s[1].max_gap, 0.06, 1e-12);
  EXPECT_DOUBLE_EQ(s[1].worst_reported, 0.26);
  EXPECT_DOUBLE_EQ(s[1].worst_observed, 0.20);
  EXPECT_FALSE(s[1].judgeable);  // two deciles: too little spread for a verdict either way
  EXPECT_FALSE(s[1].meets);

  EXPECT_EQ(s[2].answers, 30u);
  EXPECT_EQ(s[2].qualifying_bins, 0u);
  EXPECT_TRUE(std::isnan(s[2].max_gap));
  EXPECT_FALSE(s[2].meets);  // nothing to judge is not a pass
}

// A series whose answers all sit in the lowest decile (every answer "no") cannot show calibration, however
// close its one decile is; nor can three deciles that are all at or below 0.1.
TEST(CalibrationSummary, NoVerdictWithoutSpread) {
  const auto one = calibration_summary({decile(0.9, 0, 5000, 0.0, 0.0)}, {});
  EXPECT_FALSE(one[0].judgeable);
  EXPECT_FALSE(one[0].meets);
  CalibrationBin low = decile(0.9, 0, 100, 0.01, 0.0);
  const auto all_low = calibration_summary({low, low, low}, {});
  EXPECT_EQ(all_low[0].qualifying_bins, 3u);
  EXPECT_FALSE(all_low[0].judgeable);
  const auto spread = calibration_summary(
      {decile(0.9, 0, 100, 0.01, 0.0), decile(0.9, 4, 60, 0.45, 0.43), decile(0.9, 9, 70, 0.97, 0.99)}, {});
  EXPECT_TRUE(spread[0].judgeable);
  EXPECT_TRUE(spread[0].meets);
}

TEST(CalibrationSummary, SeriesDifferingOnlyInBudgetStayApartAndTakeTheirLabelFromTheRows) {
  CalibrationBin a = decile(0.9, 9, 80, 0.95, 0.95), b = a;
  b.budget = "bv_tests=50";
  b.collision_frequency = 0.5;
  CalibrationBin a0 = decile(0.9, 0, 80, 0.02, 0.0), a5 = decile(0.9, 5, 80, 0.55, 0.55), b0 = a0, b5 = a5;
  b0.budget = b5.budget = "bv_tests=50";
  ResultRow row;
  row.mesh = "m";
  row.hierarchy = "aabb";
  row.strategy = "adb";
  row.p_min = 0.9;
  row.budget = "bv_tests=50";
  row.label = "adb p_min=0.9 budget 50";
  const auto s = calibration_summary({a0, a5, a, b0, b5, b}, {row});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_TRUE(s[0].meets);
  EXPECT_FALSE(s[1].meets);
  EXPECT_EQ(s[1].label, "adb p_min=0.9 budget 50");
  EXPECT_EQ(s[0].label, "adb p_min=0.9");  // no row: made of its parts
}

TEST(CalibrationSummary, ABinWithAnswersButNoProbabilityIsAnError) {
  const std::vector<CalibrationBin> bins{decile(0.9, 2, 70, std::numeric_limits<double>::quiet_NaN(), 0.1)};
  EXPECT_THROW(calibration_summary(bins, {}), std::invalid_argument);
}

TEST_F(ReportTest, ReadmeSaysWhichSeriesMeetTheCalibrationTarget) {
  RunOutput run = run_scene(protocol_scene("[1.2]"), options);
  run.calibration = {decile(0.9, 1, 100, 0.15, 0.12), decile(0.9, 8, 200, 0.85, 0.2),
                     decile(0.9, 0, 100, 0.01, 0),    decile(0.5, 2, 70, 0.25, 0.26),
                     decile(0.5, 0, 60, 0.01, 0.0),   decile(0.5, 9, 60, 0.95, 0.95),
                     decile(0.7, 2, 70, 0.25, 0.26)};
  for (auto& b : run.calibration) b.mesh = run.rows.front().mesh;
  const std::string text = readme(run);
  EXPECT_NE(text.find("## Calibration"), std::string::npos) << text;
  EXPECT_NE(text.find("| 400 | 3 | 0.650 | 0.8–0.9: 0.850 → 0.200 | no |"), std::string::npos) << text;
  EXPECT_NE(text.find("| 190 | 3 | 0.010 | 0.2–0.3: 0.250 → 0.260 | yes |"), std::string::npos) << text;
  EXPECT_NE(text.find("| 70 | 1 | 0.010 | 0.2–0.3: 0.250 → 0.260 | too little spread to judge |"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("Meeting the target: " + run.rows.front().mesh + " aabb adb p_min=0.5."),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace bvhlab
