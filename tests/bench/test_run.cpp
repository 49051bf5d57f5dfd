// The scene runner: only what a scene names is built; the cache is used, and a damaged entry is rebuilt,
// never trusted; the CSV keeps its schema; the report is written.
#include "bench/pairs/report.hpp"
#include "bench/pairs/write.hpp"
#include "bench/run.hpp"
#include "engine/protocol.hpp"
#include "engine/tree_cache.hpp"
#include "scene_fixtures.hpp"
#include "support/generated_meshes.hpp"
#include "volumes/aabb.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

namespace bvhlab {
namespace {

using testing::TempDir;

class RunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // Two interlocking-size tori: at the protocol's distances some poses collide and some do not.
    testing::write_obj(testing::make_torus(0.7, 0.25, 24, 12), dir / "torus.obj");
    options.cache_dir = dir / "cache";
    options.log = [this](const std::string& m) { messages.push_back(m); };
    options.threads = 2;
    options.warmup_queries = 1;
  }

  Scene scene(const std::string& hierarchies, const std::string& strategies, const std::string& extra = "",
              int steps = 24) {
    const std::string text = R"({"name": "t", "objects": [{"mesh": "torus.obj"}], "hierarchies": )" +
                             hierarchies + R"(, "strategies": )" + strategies +
                             R"(, "workload": {"distances": [0.8, 1.2, 1.6], "steps": )" +
                             std::to_string(steps) + R"(}, "report": {"cgal_sample": 8})" +
                             (extra.empty() ? "" : ", " + extra) + "}";
    return parse_scene(text, dir.path(), "t.json");
  }
  Scene adb_scene() {
    return scene(R"([{"bv": "aabb"}])",
                 R"([{"type": "exact"}, {"type": "adb", "p_min": [0.5, 0.9]},
                     {"type": "time_critical", "p_min": 0.9, "budgets": [{"bv_tests": 8}]}])",
                 R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5})");
  }

  std::vector<std::filesystem::path> cache_files(const std::string& sub, const std::string& extension) const {
    std::vector<std::filesystem::path> out;
    if (!std::filesystem::exists(dir / "cache" / sub)) return out;
    for (const auto& e : std::filesystem::directory_iterator(dir / "cache" / sub)) {
      const std::string name = e.path().filename().string();
      if (name.size() >= extension.size() &&
          name.compare(name.size() - extension.size(), extension.size(), extension) == 0)
        out.push_back(e.path());
    }
    return out;
  }

  TempDir dir;
  RunOptions options;
  std::vector<std::string> messages;
};

// The answers of a run, for comparing two runs: time columns differ run to run, answers must not.
std::vector<std::tuple<std::string, std::string, double, double, double, double>> answers(
    const RunOutput& run) {
  std::vector<std::tuple<std::string, std::string, double, double, double, double>> out;
  for (const auto& r : run.rows)
    out.emplace_back(r.hierarchy, r.strategy, r.p_min, r.distance, r.fp_rate,
                     r.fn_rate + r.truth_colliding_rate);
  return out;
}

TEST_F(RunTest, ExactAabbSceneNeverAnnotatesNorBuildsFcl) {
  const RunOutput run = run_scene(scene(R"([{"bv": "aabb"}])", R"([{"type": "exact"}])"), options);
  EXPECT_EQ(run.stats.trees_built, 1u);  // A and B are copies of one object: one tree
  EXPECT_EQ(run.stats.trees_annotated, 0u);
  EXPECT_EQ(run.stats.annotation_clip_calls, 0u);
  EXPECT_EQ(run.stats.fcl_models_built, 0u);
  ASSERT_EQ(run.models.size(), 1u);
  EXPECT_EQ(run.models[0].annotation, "none");
  for (const auto& r : run.rows) EXPECT_EQ(r.annotation, "none");
  // The exact strategy agrees with the ground truth, which agrees with CGAL.
  EXPECT_EQ(run.stats.cgal_checked, 8u);
  EXPECT_EQ(run.stats.cgal_mismatches, 0u);
  for (const auto& r : run.rows) {
    EXPECT_EQ(r.fp_rate, 0.0);
    EXPECT_EQ(r.fn_rate, 0.0);
  }
}

// A wide series answers as the binary one (0 errors against the ground truth), and its rows count the
// bytes of both forms: the wide layout and the binary tree whose leaves it reads.
TEST_F(RunTest, WideSeriesAnswerExactlyAndCountTheLayoutsBytes) {
  const RunOutput run = run_scene(
      scene(R"([{"bv": "obb"}, {"bv": "rss"}])", R"([{"type": "exact"}, {"type": "exact", "wide": true}])"),
      options);
  std::size_t wide_rows = 0;
  for (const ResultRow& r : run.rows) {
    EXPECT_EQ(r.fp_rate, 0.0) << r.label;
    EXPECT_EQ(r.fn_rate, 0.0) << r.label;
    if (r.label != "exact wide") continue;
    ++wide_rows;
    EXPECT_EQ(r.hierarchy, "obb");  // rss has no wide layout: left out
    const auto binary = std::find_if(run.rows.begin(), run.rows.end(), [&](const ResultRow& b) {
      return b.label == "exact" && b.hierarchy == r.hierarchy && b.distance == r.distance;
    });
    ASSERT_NE(binary, run.rows.end());
    EXPECT_GT(r.bytes_per_triangle, binary->bytes_per_triangle);
    EXPECT_LT(r.bytes_per_triangle, 2 * binary->bytes_per_triangle);  // a wide node per four binary ones
  }
  EXPECT_GT(wide_rows, 0u);
}

TEST_F(RunTest, AnnotationRunsOnlyWhereAStrategyNeedsIt) {
  const RunOutput run =
      run_scene(scene(R"([{"bv": "aabb"}, {"bv": "dop24"}])",
                      R"([{"type": "exact"}, {"type": "adb", "p_min": [0.9], "hierarchies": ["aabb"]}])",
                      R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5})"),
                options);
  EXPECT_EQ(run.stats.trees_annotated, 1u);  // aabb only; the dop24 tree runs exact and stays bare
  EXPECT_GT(run.stats.annotation_clip_calls, 0u);
  EXPECT_EQ(run.stats.trees_built, 2u);
  for (const auto& m : run.models) {
    if (m.hierarchy == "dop24") {
      EXPECT_EQ(m.annotation, "none");
    }
  }
  EXPECT_EQ(run.stats.fcl_models_built, 0u);
}

#ifdef BVHLAB_HAVE_FCL
TEST_F(RunTest, FclModelsAreBuiltOnlyWhenAsked) {
  const RunOutput run = run_scene(scene(R"([{"bv": "fcl_obbrss"}])", R"([{"type": "exact"}])"), options);
  EXPECT_EQ(run.stats.fcl_models_built, 1u);
  EXPECT_EQ(run.stats.trees_annotated, 0u);
  // The truth still comes from bvhlab's exact traversal (an AABB tree), and FCL agrees with it.
  for (const auto& r : run.rows) {
    EXPECT_EQ(r.fp_rate, 0.0) << r.distance;
    EXPECT_EQ(r.fn_rate, 0.0) << r.distance;
  }
}
#endif

TEST_F(RunTest, DistanceSeriesAreMeasuredAgainstTheirReference) {
  // At 0.8 the tori touch on some poses, at 1.6 they are apart: the exact series is its own reference (error
  // 0); the anytime intervals hold the reference and are tighter with the larger budget.
  const RunOutput run =
      run_scene(scene(R"([{"bv": "obb"}, {"bv": "sphere"}])",
                      R"([{"type": "distance"}, {"type": "distance_anytime", "budgets": [{"bv_tests": 4},
                          {"bv_tests": 400}]}, {"type": "exact"}])"),
                options);
  std::size_t anytime_rows = 0;
  for (const ResultRow& r : run.rows) {
    SCOPED_TRACE(r.hierarchy + " " + r.label + " d=" + std::to_string(r.distance));
    if (r.strategy == "exact") {
      EXPECT_TRUE(std::isnan(r.distance_error));
      continue;
    }
    EXPECT_EQ(r.interval_misses, 0u);
    if (r.strategy == "distance") {
      EXPECT_LE(r.distance_error, r.hierarchy == "obb" ? 0.0 : 1e-12);  // obb's is the reference
      if (r.distance >= 1.6) {
        EXPECT_EQ(r.width_median, 0.0);
      }
      continue;
    }
    ++anytime_rows;
    EXPECT_GE(r.distance_error, 0.0);
    if (r.distance >= 1.6 && r.budget == "bv_tests=4") {
      EXPECT_GT(r.width_median, 0.0);  // 4 BV tests cannot close the interval; 400 may
    }
  }
  EXPECT_EQ(anytime_rows, 2u * 2u * 3u);
  const auto row_of = [&](const std::string& budget) {
    for (const ResultRow& r : run.rows)
      if (r.hierarchy == "obb" && r.strategy == "distance_anytime" && r.budget == budget && r.distance == 1.6)
        return r;
    return ResultRow{};
  };
  EXPECT_LT(row_of("bv_tests=400").width_median, row_of("bv_tests=4").width_median);
  const std::string readme = report_readme(run, true, "");
  EXPECT_NE(readme.find("## Distances: median time"), std::string::npos);
  EXPECT_NE(readme.find("Every interval [lower bound, distance] held its reference."), std::string::npos);
  EXPECT_NE(readme.find("## Anytime distance: median interval width"), std::string::npos);
}

#ifdef BVHLAB_HAVE_FCL
TEST_F(RunTest, FclDistancesAgreeWithBvhlabs) {
  const RunOutput run =
      run_scene(scene(R"([{"bv": "fcl_obbrss"}, {"bv": "aabb"}])",
                      R"([{"type": "distance"}, {"type": "exact", "hierarchies": ["aabb"]}])"),
                options);
  std::size_t fcl_rows = 0;
  for (const ResultRow& r : run.rows) {
    if (r.hierarchy != "fcl_obbrss") continue;
    ++fcl_rows;
    EXPECT_LE(r.distance_error, 1e-9) << r.distance;  // against bvhlab's aabb distance
    EXPECT_EQ(r.fp_rate + r.fn_rate, 0.0) << r.distance;
  }
  EXPECT_EQ(fcl_rows, 3u);
  EXPECT_THROW((void)scene(R"([{"bv": "fcl_obb"}])", R"([{"type": "distance"}])"), SceneError);
}
#endif

TEST_F(RunTest, SecondRunComesFromTheCache) {
  const RunOutput first = run_scene(adb_scene(), options);
  EXPECT_EQ(first.stats.trees_annotated, 1u);
  EXPECT_EQ(first.stats.truth_computed, 1u);
  EXPECT_GT(first.stats.tree_cache_stored, 0u);
  EXPECT_FALSE(cache_files("trees", ".tree").empty());
  EXPECT_EQ(cache_files("truth", ".truth").size(), 1u);

  const RunOutput second = run_scene(adb_scene(), options);
  EXPECT_EQ(second.stats.trees_built, 0u);
  EXPECT_EQ(second.stats.trees_annotated, 0u);
  EXPECT_EQ(second.stats.tree_cache_hits, 1u);  // the annotated tree; its bare parent is not even looked at
  EXPECT_EQ(second.stats.tree_cache_rejected, 0u);
  EXPECT_EQ(second.stats.truth_computed, 0u);
  EXPECT_EQ(second.stats.truth_cache_hits, 1u);
  EXPECT_EQ(answers(first), answers(second));
  ASSERT_FALSE(second.models.empty());
  EXPECT_TRUE(second.models.back().from_cache);
  EXPECT_GT(second.models.back().annotate_seconds, 0.0);  // the cost measured when it was made
}

TEST_F(RunTest, CorruptOrStaleCacheEntriesAreRebuiltNotTrusted) {
  const RunOutput first = run_scene(adb_scene(), options);

  // Flip one byte in the middle of every cached tree: checksum mismatch.
  for (const auto& file : cache_files("trees", ".tree")) {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    const auto size = std::filesystem::file_size(file);
    f.seekg(static_cast<std::streamoff>(size / 2));
    char c = 0;
    f.read(&c, 1);
    f.seekp(static_cast<std::streamoff>(size / 2));
    c = static_cast<char>(c ^ 0x5a);
    f.write(&c, 1);
  }
  // Truncate the ground truth.
  for (const auto& file : cache_files("truth", ".truth")) std::filesystem::resize_file(file, 20);

  messages.clear();
  const RunOutput second = run_scene(adb_scene(), options);
  EXPECT_GE(second.stats.tree_cache_rejected, 1u);
  EXPECT_EQ(second.stats.trees_annotated, 1u);
  EXPECT_EQ(second.stats.truth_cache_rejected, 1u);
  EXPECT_EQ(second.stats.truth_computed, 1u);
  EXPECT_EQ(answers(first), answers(second));
  EXPECT_TRUE(std::any_of(messages.begin(), messages.end(),
                          [](const std::string& m) { return m.find("rejected") != std::string::npos; }));

  // The rebuilt entries were written back: a third run hits again.
  const RunOutput third = run_scene(adb_scene(), options);
  EXPECT_EQ(third.stats.tree_cache_rejected, 0u);
  EXPECT_EQ(third.stats.trees_annotated, 0u);
  EXPECT_EQ(third.stats.truth_cache_hits, 1u);

  // A meta file naming another key (a stale entry) is rejected too.
  for (const auto& file : cache_files("trees", ".meta.json")) {
    auto meta = nlohmann::json::parse(testing::read_text(file));
    meta["key"] = meta["key"].get<std::string>() + "|something else";
    testing::write_text(file, meta.dump());
  }
  const RunOutput fourth = run_scene(adb_scene(), options);
  EXPECT_GE(fourth.stats.tree_cache_rejected, 1u);
  EXPECT_EQ(fourth.stats.trees_annotated, 1u);
  EXPECT_EQ(answers(first), answers(fourth));
}

TEST_F(RunTest, AnEntryWithAValidChecksumButWrongGeometryIsRejected) {
  // A tree whose payload is intact but whose leaf volumes do not contain the mesh: only the structural check
  // against the mesh can catch it (e.g. an entry made for another mesh under a colliding key).
  const Mesh mesh = testing::make_torus(0.7, 0.25, 24, 12);
  const Bvh<Aabb> good = Bvh<Aabb>::build(mesh);
  std::vector<Aabb> shrunk = good.volumes();
  for (auto& v : shrunk) v = Aabb::fit(std::vector<Vec3>{Vec3::Zero()});
  const Tree<Aabb, NoDensity> bad{Bvh<Aabb>::from_parts(good.nodes(), shrunk, good.triangle_ids()), {}};
  // Handles of the run-time layer, as the runner holds them (no mesh: nothing checks the volumes yet).
  const auto handle = [](const Tree<Aabb, NoDensity>& tree) {
    return AnyTree::from_bytes(save_tree_to_buffer(tree), "test tree");
  };
  TreeCache cache(dir / "cache", [this](const std::string& m) { messages.push_back(m); });
  cache.store("key", handle(bad), {});
  EXPECT_FALSE(cache.load("key", "aabb", mesh).has_value());
  EXPECT_EQ(cache.counts().rejected, 1u);
  // The same entry with the right volumes loads, with its polygons re-attached.
  cache.store("key", handle(Tree<Aabb, NoDensity>{good, {}}), {});
  const auto loaded = cache.load("key", "aabb", mesh);
  ASSERT_TRUE(loaded.has_value());
  EXPECT_TRUE(loaded->info().polygons);
  EXPECT_EQ(loaded->info().triangles, mesh.triangle_count());
  // A tree for a mesh with other triangle counts is refused, and so is one asked for as another volume.
  const Mesh other = testing::make_torus(0.7, 0.25, 20, 12);
  EXPECT_FALSE(cache.load("key", "aabb", other).has_value());
  EXPECT_FALSE(cache.load("key", "obb", mesh).has_value());
}

TEST_F(RunTest, CsvSchemaAndRates) {
  const Scene s = adb_scene();
  const RunOutput run = run_scene(s, options);
  write_results_csv(run, dir / "out" / "results.csv");
  write_calibration_csv(run, dir / "out" / "calibration.csv");
  write_results_json(run, dir / "out" / "results.json");

  const auto csv = testing::read_csv(dir / "out" / "results.csv");
  ASSERT_FALSE(csv.empty());
  // The schema is a contract with plot_report.py and with users' scripts: spelled out here, not copied.
  const std::vector<std::string> header{"mesh",
                                        "hierarchy",
                                        "bv",
                                        "annotation",
                                        "strategy",
                                        "label",
                                        "exact",
                                        "p_min",
                                        "budget",
                                        "distance",
                                        "queries",
                                        "truth_colliding_rate",
                                        "answer_colliding_rate",
                                        "mean_time_us",
                                        "median_time_us",
                                        "p99_time_us",
                                        "max_time_us",
                                        "fp_rate",
                                        "fn_rate",
                                        "inexact_rate",
                                        "budget_exhausted_rate",
                                        "bv_tests_per_query",
                                        "triangle_tests_per_query",
                                        "nodes_visited_per_query",
                                        "estimates_per_query",
                                        "in_summary",
                                        "model_bytes",
                                        "bytes_per_triangle",
                                        "distance_error",
                                        "width_median",
                                        "width_tenth_rate",
                                        "interval_misses",
                                        "machine",
                                        "compiler",
                                        "build_type",
                                        "git_commit"};
  EXPECT_EQ(csv[0], header);
  // 1 pair x 1 hierarchy x (exact + 2 p_min + 1 budget) x 3 distances.
  ASSERT_EQ(csv.size(), 1u + 4 * 3);
  auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  std::map<std::string, int> per_strategy;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    const auto& row = csv[i];
    ASSERT_EQ(row.size(), header.size()) << "row " << i;
    EXPECT_EQ(row[column("mesh")], "torus");
    EXPECT_EQ(row[column("queries")], "24");
    for (const char* rate : {"fp_rate", "fn_rate", "truth_colliding_rate", "answer_colliding_rate",
                             "inexact_rate", "budget_exhausted_rate"}) {
      const double v = std::stod(row[column(rate)]);
      EXPECT_GE(v, 0.0) << rate;
      EXPECT_LE(v, 1.0) << rate;
    }
    EXPECT_GT(std::stod(row[column("mean_time_us")]), 0.0);
    EXPECT_GE(std::stod(row[column("max_time_us")]), std::stod(row[column("mean_time_us")]));
    const std::string strategy = row[column("strategy")];
    ++per_strategy[strategy];
    // The label and exactness come from the strategy table.
    EXPECT_EQ(row[column("exact")], strategy == "exact" ? "1" : "0");
    EXPECT_EQ(row[column("label")].rfind(strategy, 0), 0u) << row[column("label")];
    if (strategy == "exact") {
      EXPECT_EQ(row[column("label")], "exact");
      EXPECT_EQ(row[column("p_min")], "");
      EXPECT_EQ(std::stod(row[column("fp_rate")]), 0.0);
      EXPECT_EQ(std::stod(row[column("fn_rate")]), 0.0);
    } else {
      EXPECT_NE(row[column("p_min")], "");
    }
    if (strategy == "time_critical") {
      EXPECT_EQ(row[column("budget")], "bv_tests=8");
      EXPECT_EQ(row[column("label")], "time_critical p_min=0.9 bv_tests=8");
      EXPECT_LE(std::stod(row[column("bv_tests_per_query")]), 8.0);
    }
    EXPECT_EQ(row[column("build_type")], run.environment.build_type);
    EXPECT_FALSE(row[column("git_commit")].empty());
  }
  EXPECT_EQ(per_strategy["exact"], 3);
  EXPECT_EQ(per_strategy["adb"], 6);
  EXPECT_EQ(per_strategy["time_critical"], 3);
  // The protocol's colliding fraction falls with distance for two tori.
  EXPECT_GE(run.truth.front().colliding, run.truth.back().colliding);

  // Calibration: 10 bins per ADB-type series, all answers accounted for.
  const auto cal = testing::read_csv(dir / "out" / "calibration.csv");
  ASSERT_EQ(cal.size(), 1u + 3 * 10);
  std::map<std::string, long> answers_per_series;
  for (std::size_t i = 1; i < cal.size(); ++i)
    answers_per_series[cal[i][2] + cal[i][3] + cal[i][4]] += std::stol(cal[i][8]);
  for (const auto& [series, n] : answers_per_series) EXPECT_EQ(n, 3 * 24) << series;

  const auto json = nlohmann::json::parse(testing::read_text(dir / "out" / "results.json"));
  EXPECT_EQ(json["rows"].size(), 12u);
  EXPECT_EQ(json["stats"]["trees_annotated"], 1);
  EXPECT_EQ(json["environment"]["build_type"], run.environment.build_type);
}

// Whether two runs binned their answers alike (an empty bin's mean is NaN in both).
bool same_bins(const std::vector<CalibrationBin>& a, const std::vector<CalibrationBin>& b) {
  auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].count != b[i].count || a[i].calibrated != b[i].calibrated ||
        !same(a[i].mean_probability, b[i].mean_probability) ||
        !same(a[i].collision_frequency, b[i].collision_frequency))
      return false;
  return true;
}

TEST_F(RunTest, CalibratedSeriesSitBesideTheRawOnesAndTheirMapsAreCached) {
  const std::string calibration = R"("calibration": {"training_seed": 9, "training_steps": 30})";
  const Scene raw_scene = adb_scene();
  const Scene calibrated_scene =
      scene(R"([{"bv": "aabb"}])",
            R"([{"type": "exact"}, {"type": "adb", "p_min": [0.5, 0.9]},
                     {"type": "time_critical", "p_min": 0.9, "budgets": [{"bv_tests": 8}]}])",
            R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5}, )" + calibration);
  const RunOutput raw = run_scene(raw_scene, options);
  const RunOutput first = run_scene(calibrated_scene, options);
  // The answers are the raw strategy's: the same rows, no extra ones.
  EXPECT_EQ(answers(first), answers(raw));
  EXPECT_EQ(first.stats.calibration_fitted, 3u);  // the three inexact series
  EXPECT_EQ(first.stats.calibration_cache_hits, 0u);
  EXPECT_EQ(cache_files("calibration", ".calib").size(), 3u);
  // Each raw series' ten bins, then its calibrated series' ten bins over the same answers.
  ASSERT_EQ(raw.calibration.size(), 30u);
  ASSERT_EQ(first.calibration.size(), 60u);
  for (std::size_t s = 0; s < 3; ++s) {
    std::size_t raw_count = 0, calibrated_count = 0;
    for (std::size_t b = 0; b < 10; ++b) {
      const CalibrationBin& r = first.calibration[20 * s + b];
      const CalibrationBin& c = first.calibration[20 * s + 10 + b];
      EXPECT_FALSE(r.calibrated);
      EXPECT_TRUE(c.calibrated);
      EXPECT_EQ(r.count, raw.calibration[10 * s + b].count);
      EXPECT_EQ(std::tie(c.mesh, c.hierarchy, c.strategy, c.p_min, c.budget),
                std::tie(r.mesh, r.hierarchy, r.strategy, r.p_min, r.budget));
      raw_count += r.count;
      calibrated_count += c.count;
    }
    EXPECT_EQ(raw_count, calibrated_count);
  }
  const auto summaries = calibration_summary(first.calibration, first.rows);
  ASSERT_EQ(summaries.size(), 6u);
  EXPECT_EQ(summaries[1].label, summaries[0].label + " calibrated");

  // A second run reads the maps back and bins exactly as the first did.
  const RunOutput second = run_scene(calibrated_scene, options);
  EXPECT_EQ(second.stats.calibration_fitted, 0u);
  EXPECT_EQ(second.stats.calibration_cache_hits, 3u);
  EXPECT_TRUE(same_bins(second.calibration, first.calibration));

  // A damaged map is refused by name and fitted again, never applied.
  const auto file = cache_files("calibration", ".calib").front();
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(20);
    f.put('\x7f');
  }
  messages.clear();
  const RunOutput third = run_scene(calibrated_scene, options);
  EXPECT_EQ(third.stats.calibration_fitted, 1u);
  EXPECT_EQ(third.stats.calibration_cache_hits, 2u);
  bool named = false;
  for (const auto& m : messages)
    named |= m.find("calibration cache: rejected " + file.filename().string()) == 0;
  EXPECT_TRUE(named);
  EXPECT_TRUE(same_bins(third.calibration, first.calibration));

  // calibration.csv marks the calibrated series.
  write_calibration_csv(first, dir / "out" / "calibration.csv");
  const auto csv = testing::read_csv(dir / "out" / "calibration.csv");
  ASSERT_EQ(csv.size(), 61u);
  EXPECT_EQ(csv[0][5], "calibrated");
  EXPECT_EQ(csv[1][5], "0");
  EXPECT_EQ(csv[11][5], "1");
}

TEST_F(RunTest, PoseFileWorkloadAndPairsOfDifferentObjects) {
  testing::write_obj(testing::make_random_soup(200, 0.1, 5), dir / "soup.obj");
  testing::write_text(dir / "poses.json", R"({"poses": [
      {"translation": [0, 0, 0], "group": 0}, {"translation": [0.3, 0, 0], "group": 0},
      {"translation": [5, 0, 0], "group": 5}]})");
  const Scene s = parse_scene(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "soup.obj", "scale": 0.5}],
      "pairs": [["torus", "soup"]], "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
      "workload": {"type": "poses", "file": "poses.json", "axis": "group"}, "report": {"cgal_sample": 3}})",
                              dir.path(), "p.json");
  const RunOutput run = run_scene(s, options);
  ASSERT_EQ(run.rows.size(), 2u);
  EXPECT_EQ(run.rows[0].mesh, "torus|soup");
  EXPECT_EQ(run.rows[0].queries, 2u);
  EXPECT_EQ(run.rows[1].truth_colliding_rate, 0.0);  // 5 apart: nothing touches
  EXPECT_EQ(run.stats.trees_built, 2u);
  EXPECT_EQ(run.stats.cgal_mismatches, 0u);

  // By default a pose file is filed by separation: the two poses at the origin and 0.3 share no bin with the
  // one 5 away (beyond 1.5: the open bin), and every pose is counted once.
  Scene by_separation = s;
  by_separation.workload.axis = WorkloadSpec::Axis::Separation;
  const RunOutput separated = run_scene(by_separation, options);
  ASSERT_GE(separated.rows.size(), 2u);
  std::size_t queries = 0;
  for (const ResultRow& r : separated.rows) queries += r.queries;
  EXPECT_EQ(queries, 3u);
  EXPECT_DOUBLE_EQ(separated.rows.back().distance, 1.55);
  EXPECT_EQ(separated.rows.back().queries, 1u);
  EXPECT_EQ(separated.rows.back().truth_colliding_rate, 0.0);
}

TEST_F(RunTest, MissingOptionalObjectIsSkippedWithAMessage) {
  const Scene s =
      parse_scene(R"({"objects": [{"mesh": "torus.obj"}, {"mesh": "absent.stl", "optional": true}],
      "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
      "workload": {"distances": [1.0], "steps": 4}})",
                  dir.path(), "o.json");
  const RunOutput run = run_scene(s, options);
  EXPECT_EQ(run.rows.size(), 1u);
  ASSERT_EQ(run.stats.skipped.size(), 1u);
  EXPECT_NE(run.stats.skipped[0].find("absent.stl"), std::string::npos);
}

TEST_F(RunTest, ReportReadmeStatesTheOperatingPoint) {
  const Scene s =
      scene(R"([{"bv": "aabb"}, {"bv": "dop24"}])",
            R"([{"type": "exact"}, {"type": "adb", "p_min": [0.5, 0.9], "hierarchies": ["aabb"]}])",
            R"("annotation": {"type": "adb", "grid": 2, "tau": 0.5})");
  const RunOutput run = run_scene(s, options);
  const auto points = operating_points(run);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_EQ(points[0].adb.hierarchy, "aabb");
  EXPECT_DOUBLE_EQ(points[0].adb.p_min, 0.9);
  EXPECT_EQ(points[0].baseline.hierarchy, "dop24");
  EXPECT_NEAR(points[0].speedup, points[0].baseline.mean_time_us / points[0].adb.mean_time_us, 1e-12);
  // Summaries weight distances by queries, over the rows inside the pair's band.
  std::size_t inside = 0;
  for (const ResultRow& r : run.rows) inside += r.in_summary && r.label == "adb p_min=0.9" ? r.queries : 0;
  EXPECT_EQ(points[0].adb.queries, inside);

  ReportOptions no_figures;
  no_figures.figures = false;
  const ReportFiles files = write_report(run, dir / "report", no_figures);
  const std::string readme = testing::read_text(files.readme);
  EXPECT_NE(readme.find("## Result at the operating point"), std::string::npos);
  EXPECT_NE(readme.find("`aabb` adb p_min=0.9: "), std::string::npos) << readme;
  EXPECT_NE(readme.find("against `dop24` exact: "), std::string::npos) << readme;
  for (const auto& f : report_figures()) EXPECT_NE(readme.find(f.file), std::string::npos) << f.file;
  EXPECT_TRUE(std::filesystem::is_regular_file(files.results_csv));
  EXPECT_TRUE(std::filesystem::is_regular_file(files.results_json));
}

TEST_F(RunTest, SavedTreesAnswerLikeTheMeshesTheyWereBuiltFrom) {
  const SceneObject torus = testing::object_from(dir / "torus.obj");
  const HierarchySpec aabb = testing::hierarchy_of("aabb");
  const DensitySpec annotation{"adb", {{"grid", 2}, {"tau", 0.5}}};
  const BuildOutcome built = build_tree_file(torus, aabb, annotation, dir / "torus.tree", 2);
  EXPECT_EQ(built.file_bytes, std::filesystem::file_size(dir / "torus.tree"));
  EXPECT_GT(built.model.annotate_seconds, 0.0);
  const SavedTreeInfo info = peek_saved_tree(dir / "torus.tree");
  EXPECT_EQ(info.bv, "aabb");
  EXPECT_EQ(info.density, "adb");
  EXPECT_EQ(info.annotation, "adb grid=2 tau=0.5");
  EXPECT_EQ(info.triangles, built.model.triangles);
  EXPECT_FALSE(is_saved_tree(dir / "torus.obj"));

  QueryRequest request;
  request.hierarchy = aabb;
  request.density = annotation;
  request.strategy.strategy = "adb";
  request.strategy.values = {{"p_min", 0.9}};
  options.cache_dir.clear();
  for (int step = 0; step < 40; step += 7) {
    const RigidTransform pose = protocol_pose(1.3, step, 40);
    const QueryOutcome from_trees =
        run_query_on_trees(dir / "torus.tree", dir / "torus.tree", request.strategy, pose);
    const QueryOutcome from_meshes = run_query(torus, torus, request, pose, options);
    ASSERT_EQ(from_trees.answers.size(), 1u);
    ASSERT_EQ(from_meshes.answers.size(), 1u);
    const Result& t = from_trees.answers[0].result;
    const Result& m = from_meshes.answers[0].result;
    EXPECT_EQ(t.collides, m.collides) << step;
    EXPECT_EQ(t.probability, m.probability) << step;
    EXPECT_EQ(t.counters.bv_tests, m.counters.bv_tests) << step;
  }
  StrategyVariant exact;
  EXPECT_THROW(run_query_on_trees(dir / "torus.tree", dir / "torus.tree", exact, RigidTransform{}),
               std::invalid_argument);
  // Trees of another volume or density cannot be paired; the error describes both.
  build_tree_file(torus, testing::hierarchy_of("obb"), annotation, dir / "torus_obb.tree", 2);
  build_tree_file(torus, aabb, DensitySpec{"adb", {{"grid", 3}, {"tau", 0.5}}}, dir / "torus_g3.tree", 2);
  for (const char* other : {"torus_obb.tree", "torus_g3.tree"}) {
    try {
      run_query_on_trees(dir / "torus.tree", dir / other, request.strategy, RigidTransform{});
      ADD_FAILURE() << other << " was paired with an AABB grid-2 tree";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("adb grid=2 tau=0.5"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(peek_saved_tree(dir / "torus.obj"), std::runtime_error);
}

// Meshes keep their files' units unless normalised; a saved tree records which (and the normalisation), and
// a query refuses to mix a normalised tree with a raw one, naming both files.
TEST_F(RunTest, SavedTreesRecordTheirUnits) {
  testing::write_obj(testing::make_torus(3.0, 1.0, 24, 12), dir / "big.obj");  // 8 x 8 x 2, centred at 0
  SceneObject big = testing::object_from(dir / "big.obj");
  const HierarchySpec aabb = testing::hierarchy_of("aabb");
  const DensitySpec annotation{"adb", {{"grid", 2}, {"tau", 0.25}}};
  build_tree_file(big, aabb, annotation, dir / "raw.tree", 1);
  big.normalize = true;
  const BuildOutcome normalised = build_tree_file(big, aabb, annotation, dir / "normalised.tree", 1);
  EXPECT_TRUE(normalised.model.units.normalized);
  const SavedTreeInfo raw_info = peek_saved_tree(dir / "raw.tree");
  const SavedTreeInfo info = peek_saved_tree(dir / "normalised.tree");
  EXPECT_EQ(raw_info.units, TreeUnits{});
  ASSERT_TRUE(info.units.normalized);
  EXPECT_NEAR(info.units.scale, 2.0 / 8.0, 1e-12);
  EXPECT_LT(info.units.centre.norm(), 1e-12);
  EXPECT_EQ(info.units, normalised.model.units);

  // At x = 5 the raw torus (radius 4) overlaps its copy; normalised (radius 1) it is far from it.
  StrategyVariant adb{"adb", {{"p_min", 0.9}}, {}};
  const RigidTransform pose = RigidTransform::checked(Mat3::Identity(), Vec3(5, 0, 0));
  EXPECT_TRUE(run_query_on_trees(dir / "raw.tree", dir / "raw.tree", adb, pose).answers[0].result.collides);
  const QueryOutcome n = run_query_on_trees(dir / "normalised.tree", dir / "normalised.tree", adb, pose);
  EXPECT_FALSE(n.answers[0].result.collides);
  EXPECT_EQ(n.model_a.units, info.units);
  for (const auto& [a, b] :
       {std::pair("normalised.tree", "raw.tree"), std::pair("raw.tree", "normalised.tree")}) {
    try {
      run_query_on_trees(dir / a, dir / b, adb, pose);
      ADD_FAILURE() << a << " and " << b << " were queried together";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find((dir / "normalised.tree").string() + " is normalised: scale 0.25"),
                std::string::npos)
          << what;
      EXPECT_NE(what.find((dir / "raw.tree").string() + " is in its mesh file's units"), std::string::npos)
          << what;
    }
  }
}

// The tree cache keys trees by the normalisation too: a normalised tree is never served for a raw object.
TEST_F(RunTest, TheTreeCacheKeepsNormalisedAndRawTreesApart) {
  const auto with_normalize = [&](bool normalize) {
    return parse_scene(std::string(R"({"objects": [{"mesh": "torus.obj", "normalize": )") +
                           (normalize ? "true" : "false") +
                           R"(}], "hierarchies": [{"bv": "aabb"}], "strategies": [{"type": "exact"}],
                            "workload": {"distances": [1.0], "steps": 8}, "report": {"cgal_sample": 0}})",
                       dir.path(), "t.json");
  };
  const RunOutput raw = run_scene(with_normalize(false), options);
  EXPECT_EQ(raw.stats.trees_built, 1u);
  const RunOutput normalised = run_scene(with_normalize(true), options);
  EXPECT_EQ(normalised.stats.tree_cache_hits, 0u);
  EXPECT_EQ(normalised.stats.trees_built, 1u);
  EXPECT_TRUE(normalised.models.at(0).units.normalized);
  EXPECT_FALSE(raw.models.at(0).units.normalized);
  EXPECT_TRUE(std::any_of(messages.begin(), messages.end(),
                          [](const std::string& m) { return m.rfind("torus: normalised: scale", 0) == 0; }));
  const RunOutput again = run_scene(with_normalize(true), options);
  EXPECT_EQ(again.stats.tree_cache_hits, 1u);
  EXPECT_EQ(again.stats.trees_built, 0u);
  EXPECT_TRUE(again.models.at(0).units.normalized);
}

// Several poses in one call, and warm repetitions: every answer is the one a single query gives.
TEST_F(RunTest, QueriesAnswerEachPoseAndTimeWarmRepetitions) {
  const SceneObject torus = testing::object_from(dir / "torus.obj");
  QueryRequest request;
  request.hierarchy = testing::hierarchy_of("aabb");
  request.strategy.strategy = "exact";
  request.repeat = 5;
  options.cache_dir.clear();
  std::vector<RigidTransform> poses;
  for (int step = 0; step < 40; step += 5) poses.push_back(protocol_pose(0.9, step, 40));
  const QueryOutcome batch = run_query(torus, torus, request, poses, options);
  ASSERT_EQ(batch.answers.size(), poses.size());
  request.repeat = 0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const QueryOutcome single = run_query(torus, torus, request, poses[k], options);
    EXPECT_EQ(batch.answers[k].result.collides, single.answers[0].result.collides) << k;
    EXPECT_EQ(batch.answers[k].result.counters.bv_tests, single.answers[0].result.counters.bv_tests) << k;
    EXPECT_EQ(batch.answers[k].warm_micros.size(), 5u);
    for (double t : batch.answers[k].warm_micros) EXPECT_GE(t, 0.0);
    EXPECT_TRUE(single.answers[0].warm_micros.empty());
  }
  EXPECT_THROW(run_query(torus, torus, request, std::span<const RigidTransform>(), options),
               std::invalid_argument);
}

TEST_F(RunTest, PlotScriptDrawsAllFiveFigures) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") != 0 &&
      std::system("python3 -c 'import matplotlib' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "no Python with matplotlib";
  const RunOutput run = run_scene(adb_scene(), options);
  const ReportFiles files = write_report(run, dir / "report");
  EXPECT_EQ(files.plot_error, "");
  ASSERT_EQ(files.figures.size(), 5u);
  for (const auto& f : files.figures) EXPECT_GT(std::filesystem::file_size(f), 10'000u) << f;
}

}  // namespace
}  // namespace bvhlab
