// The measuring instrument: per-pose times from warm passes, stalls found and counted, intervals that hold
// the truth and say "no difference" when there is none, work compared beside time, summary bands that follow
// the ground truth, calibration verdicts only with spread, and the scene fields that set it all, refused when
// they make no sense.
#include "bench/pairs/report.hpp"
#include "bench/pairs/slices.hpp"
#include "bench/pairs/summary_band.hpp"
#include "bench/pairs/timing_stats.hpp"
#include "bench/run.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace bvhlab {
namespace {

using Statistic = TimingSpec::Statistic;

TEST(RepresentativeSample, MedianIsTheMiddleSampleAndMinTheSmallest) {
  const std::vector<double> samples{5.0, 1.0, 4000.0, 2.0, 3.0};
  EXPECT_EQ(representative_sample(samples, Statistic::Median), 4u);  // 3.0
  EXPECT_EQ(representative_sample(samples, Statistic::Min), 1u);
  const std::vector<double> even{2.0, 9.0, 1.0, 7.0};
  EXPECT_EQ(representative_sample(even, Statistic::Median), 3u);  // the upper middle: 7.0
}

TEST(Disturbance, CountsOnlySamplesFarAboveTheirPosesMedian) {
  Disturbance d;
  d.add(std::vector<double>{1.0, 1.1, 0.9});     // quiet
  d.add(std::vector<double>{2.0, 2.0, 4000.0});  // one stall of about 4 ms
  d.add(std::vector<double>{10.0, 14.0, 12.0});  // spread, no stall
  EXPECT_EQ(d.samples, 9u);
  EXPECT_EQ(d.stalled, 1u);
  EXPECT_NEAR(d.lost_us, 3998.0, 1e-9);
  EXPECT_GT(d.share(), 0.9);
  Disturbance single;
  single.add(std::vector<double>{4000.0});  // one sample: nothing to compare it with
  EXPECT_EQ(single.stalled, 0u);
}

TEST(RatioOfMeans, TheIntervalHoldsTheTrueRatioAndExcludesOneWhenTheyDiffer) {
  std::mt19937_64 rng(7);
  std::lognormal_distribution<double> noise(0.0, 0.3);
  std::vector<double> slow, fast, same;
  for (int i = 0; i < 2000; ++i) {
    const double pose_cost = 1.0 + (i % 17);  // poses differ; the series differ by 2x on every pose
    slow.push_back(2 * pose_cost * noise(rng));
    fast.push_back(pose_cost * noise(rng));
    same.push_back(pose_cost * noise(rng));
  }
  const Interval r = ratio_of_means(slow, fast);
  EXPECT_NEAR(r.value, 2.0, 0.1);
  EXPECT_TRUE(r.contains(2.0) || std::abs(r.value - 2.0) < 0.05) << r.lo << " " << r.hi;
  EXPECT_GT(r.lo, 1.5);
  const Interval none = ratio_of_means(same, fast);
  EXPECT_TRUE(none.contains(1.0)) << none.lo << " " << none.hi;
  EXPECT_LT(none.hi - none.lo, 0.2);
  // Deterministic: the same data give the same interval.
  const Interval again = ratio_of_means(slow, fast);
  EXPECT_EQ(again.lo, r.lo);
  EXPECT_EQ(again.hi, r.hi);
  EXPECT_TRUE(std::isnan(ratio_of_means({}, fast).value));
}

SeriesSummary work(double bv, double tri, double estimates, double us) {
  SeriesSummary s;
  s.bv_tests_per_query = bv;
  s.triangle_tests_per_query = tri;
  s.estimates_per_query = estimates;
  s.mean_time_us = us;
  return s;
}

TEST(Comparison, SameWorkIsNeverASpeedUp) {
  EXPECT_TRUE(same_work(work(100, 10, 0, 1.0), work(100.5, 10, 0, 1.14)));
  EXPECT_FALSE(same_work(work(100, 10, 0, 1.0), work(103, 10, 0, 1.0)));
  EXPECT_FALSE(same_work(work(100, 10, 5, 1.0), work(100, 10, 8, 1.0)));
  EXPECT_FALSE(same_work(work(NAN, NAN, NAN, 1.0), work(NAN, NAN, NAN, 1.0)));  // FCL: unknown work
  const std::string same = speedup_text({1.14, 1.1, 1.18}, true);
  EXPECT_NE(same.find("same work"), std::string::npos) << same;
  EXPECT_EQ(same.find("faster"), std::string::npos) << same;
  const std::string unclear = speedup_text({1.03, 0.97, 1.09}, false);
  EXPECT_NE(unclear.find("no measurable difference"), std::string::npos) << unclear;
  const std::string faster = speedup_text({3.1, 2.9, 3.3}, false);
  EXPECT_NE(faster.find("3.10× faster"), std::string::npos) << faster;
  EXPECT_NE(faster.find("2.90–3.30"), std::string::npos) << faster;
  const std::string slower = speedup_text({0.5, 0.4, 0.625}, false);
  EXPECT_NE(slower.find("2.00× slower"), std::string::npos) << slower;
  EXPECT_NE(slower.find("95% interval 1.60–2.50×"), std::string::npos) << slower;  // inverted with the ratio
}

TEST(Separation, BinsFollowTheObjectsBoundingSpheres) {
  const Mesh unit = testing::make_torus(0.7, 0.25, 12, 8);  // radius about 0.95 about the origin
  const BoundingSphere s = bounding_sphere(unit);
  EXPECT_NEAR(s.radius, 0.95, 0.01);
  WorkloadSpec w;
  w.kind = WorkloadSpec::Kind::Random;
  RigidTransform near, far, beyond;
  near.translation = Vec3(0.1 * s.radius, 0, 0);      // separation 0.05: bin 0.05
  far.translation = Vec3(2 * 0.92 * s.radius, 0, 0);  // 0.92: bin 0.95
  beyond.translation = Vec3(2 * 7 * s.radius, 0, 0);  // 7: the open bin, filed at 1.55
  w.groups.push_back({0, {near, far, beyond, near}});
  const std::vector<PoseSlice> slices = separation_slices(w, unit, unit);
  ASSERT_EQ(slices.size(), 3u);
  EXPECT_DOUBLE_EQ(slices[0].distance, 0.05);
  EXPECT_EQ(slices[0].poses.size(), 2u);
  EXPECT_DOUBLE_EQ(slices[1].distance, 0.95);
  EXPECT_DOUBLE_EQ(slices[2].distance, 1.55);
  EXPECT_EQ(slices[2].poses.front(), std::make_pair(std::size_t{0}, std::size_t{2}));
}

RunOutput run_with_truth(const std::vector<std::pair<double, double>>& colliding_shares, bool given = false) {
  RunOutput run;
  run.scene.report.quality_given = given;
  run.scene.report.quality_min = 1.0;
  run.scene.report.quality_max = 1.4;
  for (const auto& [d, share] : colliding_shares)
    run.truth.push_back({"m", d, 100, static_cast<std::size_t>(std::lround(share * 100))});
  return run;
}

TEST(SummaryBand, FoundWhereTheTruthHasBothAnswers) {
  const auto bands =
      summary_bands(run_with_truth({{0.4, 1.0}, {0.8, 0.96}, {1.0, 0.6}, {1.2, 0.1}, {1.4, 0.02}, {1.6, 0}}));
  ASSERT_EQ(bands.size(), 1u);
  EXPECT_FALSE(bands[0].all);
  EXPECT_DOUBLE_EQ(bands[0].lo, 1.0);
  EXPECT_DOUBLE_EQ(bands[0].hi, 1.2);
  EXPECT_EQ(bands[0].poses, 200u);
  EXPECT_EQ(bands[0].colliding, 70u);
  EXPECT_TRUE(bands[0].informative());
  EXPECT_NE(bands[0].text.find("distances 1–1.2"), std::string::npos) << bands[0].text;
}

TEST(SummaryBand, ABandWithoutCollisionsSaysSoInsteadOfComparing) {
  const auto given = summary_bands(run_with_truth({{0.4, 1.0}, {1.2, 0}, {1.4, 0}}, true));
  ASSERT_EQ(given.size(), 1u);
  EXPECT_EQ(given[0].colliding, 0u);
  EXPECT_FALSE(given[0].informative());
  const auto none = summary_bands(run_with_truth({{1.2, 0}, {1.6, 0}}));
  EXPECT_TRUE(none[0].all);
  EXPECT_FALSE(none[0].informative());
  EXPECT_NE(none[0].text.find("no distance of the run has between 5% and 95%"), std::string::npos);
}

class TimingSceneTest : public testing::SceneParsing {
 protected:
  TimingSceneTest() : SceneParsing("t.json") {}
  void SetUp() override { testing::write_obj(testing::make_torus(0.7, 0.25, 12, 8), dir / "torus.obj"); }
  static std::string scene(const std::string& extra) {
    return R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
               "strategies": [{"type": "exact"}])" +
           extra + "}";
  }
};

TEST_F(TimingSceneTest, TimingAndAxisDefaultsFollowTheWorkload) {
  const Scene protocol = parse(scene(""));
  EXPECT_EQ(protocol.timing.repeats, 3);
  EXPECT_EQ(protocol.timing.statistic, TimingSpec::Statistic::Min);
  EXPECT_EQ(protocol.workload.axis, WorkloadSpec::Axis::Distance);
  const Scene random = parse(scene(R"(, "workload": {"type": "random", "count": 4, "box": [[0,0,0],[1,1,1]]},
      "timing": {"repeats": 5, "statistic": "median"})"));
  EXPECT_EQ(random.workload.axis, WorkloadSpec::Axis::Separation);
  EXPECT_EQ(random.timing.repeats, 5);
  EXPECT_EQ(random.timing.statistic, TimingSpec::Statistic::Median);
  testing::write_text(dir / "poses.json", R"({"poses": [{"translation": [0, 0, 0]}]})");
  EXPECT_EQ(
      parse(scene(R"(, "workload": {"type": "poses", "file": "poses.json", "axis": "group"})")).workload.axis,
      WorkloadSpec::Axis::Group);
}

TEST_F(TimingSceneTest, NonsenseIsRefusedNamingTheField) {
  EXPECT_NE(error_of(scene(R"(, "timing": {"repeats": 0})")).find("/timing/repeats: expected at least 1"),
            std::string::npos);
  EXPECT_NE(error_of(scene(R"(, "timing": {"statistic": "mean"})"))
                .find("/timing/statistic: expected one of median, min"),
            std::string::npos);
  EXPECT_NE(error_of(scene(R"(, "workload": {"distances": [1.2], "axis": "separation"})"))
                .find("/workload/axis: the protocol's axis is its distances"),
            std::string::npos);
  EXPECT_NE(
      error_of(
          scene(R"(, "workload": {"type": "random", "count": 4, "box": [[0,0,0],[1,1,1]], "axis": "group"})"))
          .find("/workload/axis: expected one of separation"),
      std::string::npos);
  EXPECT_NE(
      error_of(scene(R"(, "workload": {"distances": [0.4, 0.8]}, "report": {"quality_distances": [1.2, 2]})"))
          .find("/report/quality_distances: no pose of the workload lies in [1.2, 2]; its distances are 0.4, "
                "0.8"),
      std::string::npos);
  const std::string world = R"({"objects": [{"mesh": "torus.obj"}], "hierarchies": [{"bv": "aabb"}],
      "strategies": [{"type": "exact"}], "world": {"instances": 2, "frames": 2}, "timing": {"repeats": 2}})";
  EXPECT_NE(error_of(world).find("/timing: does not apply to a world scene"), std::string::npos)
      << error_of(world);
}

// A separation axis is binned per pair from the objects' sizes: summary distances outside its bins are
// refused once the meshes are loaded, before any tree is built or query timed.
TEST_F(TimingSceneTest, SummaryDistancesOutsideTheSeparationBinsAreRefusedBeforeAnyTree) {
  const Scene s = parse(scene(R"(, "workload": {"type": "random", "count": 8, "box": [[-0.2, -0.2, -0.2],
      [0.2, 0.2, 0.2]]}, "report": {"quality_distances": [5, 6]})"));
  RunOptions options;
  options.cache_dir.clear();
  std::vector<std::string> messages;
  options.log = [&](const std::string& m) { messages.push_back(m); };
  try {
    (void)run_scene(s, options);
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_NE(
        std::string(e.what()).find("/report/quality_distances: no pose of torus has a separation in [5, 6]; "
                                   "its separation bins are 0.05"),
        std::string::npos)
        << e.what();
  }
  for (const std::string& m : messages) EXPECT_EQ(m.find("building"), std::string::npos) << m;
}

}  // namespace
}  // namespace bvhlab
