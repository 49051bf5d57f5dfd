// The scene runner as a pipeline: parse (bench/core/scene.cpp, before this) -> plan (plan.cpp) -> prepare
// (prepare.cpp) -> measure (measure.cpp) -> aggregate (aggregate.cpp) -> write (write.cpp, after this).
#include "bench/run.hpp"

#include "bench/pairs/advice.hpp"
#include "bench/pairs/aggregate.hpp"
#include "bench/pairs/measure.hpp"
#include "bench/pairs/plan.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/pairs/summary_band.hpp"
#include "engine/policies.hpp"

#include <fmt/format.h>

#include <sys/utsname.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <thread>

#ifndef BVHLAB_BUILD_TYPE
#define BVHLAB_BUILD_TYPE "unknown"
#endif

namespace bvhlab {
namespace {

std::string run_command(const std::string& command) {
  std::string out;
  if (FILE* pipe = popen(command.c_str(), "r")) {
    char buf[256];
    while (std::fgets(buf, sizeof buf, pipe)) out += buf;
    pclose(pipe);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

LogFn log_of(const RunOptions& options) {
  return options.log ? options.log : LogFn([](const std::string& m) { std::cerr << m << '\n'; });
}

unsigned threads_of(unsigned requested) {
  return requested ? requested : std::max(1u, std::thread::hardware_concurrency());
}

/// A run's output before anything ran: the scene and where it runs.
RunOutput start_output(const Scene& scene) {
  RunOutput output;
  output.scene_name = scene.name;
  output.scene_file = scene.file;
  output.scene = scene;
  output.environment = detect_environment();
  return output;
}

/// The right tool for each strategy the pair runs, once per strategy and pair.
void advise(const PreparedPair& pair, const RunPlan& plan, RunOutput& output, const LogFn& log) {
  for (const PlannedHierarchy& h : plan.hierarchies)
    for (const StrategyVariant& v : h.variants) {
      const std::string advice = size_advice(v.strategy, pair.label, pair.a->mesh, pair.b->mesh);
      if (!advice.empty() &&
          std::find(output.advice.begin(), output.advice.end(), advice) == output.advice.end()) {
        output.advice.push_back(advice);
        log("note: " + advice);
      }
    }
}

/// The slice's truth and rows.
void add_slice(Aggregation& aggregation, const PreparedPair& pair, const RunPlan& plan,
               const PoseSlice& slice, const Truth& truth, const PairRecords& records, const SeriesMaps& maps,
               RunOutput& output) {
  output.truth.push_back(summarize_truth(pair.label, slice, truth));
  aggregation.add_slice(pair, plan, slice, truth, records, output, maps);
}

/// Summary distances given on a separation axis must hold some of the pair's bins: checked before any query
/// is timed, since the bins depend on the objects' sizes.
void check_separation_band(const Scene& scene, const std::string& label,
                           const std::vector<PoseSlice>& slices) {
  const ReportSpec& report = scene.report;
  if (!report.quality_given) return;
  for (const PoseSlice& slice : slices)
    if (slice.distance >= report.quality_min - 1e-12 && slice.distance <= report.quality_max + 1e-12) return;
  std::string held;
  for (const PoseSlice& slice : slices)
    held += (held.empty() ? "" : ", ") + fmt::format("{:g}", slice.distance);
  throw SceneError((scene.file.empty() ? scene.name : scene.file.filename().string()) +
                   ": /report/quality_distances: no pose of " + label + " has a separation in [" +
                   fmt::format("{:g}", report.quality_min) + ", " + fmt::format("{:g}", report.quality_max) +
                   "]; its separation bins are " + held);
}

/// The pair's slices of the workload: its groups, or its separation bins (checked against the summary
/// distances the scene gives, before any tree is built for the pair).
std::vector<PoseSlice> slices_of(const Scene& scene, const std::string& label, const Mesh& a, const Mesh& b) {
  const WorkloadSpec& workload = scene.workload;
  std::vector<PoseSlice> slices;
  if (workload.axis == WorkloadSpec::Axis::Separation) {
    slices = separation_slices(workload, a, b);
    check_separation_band(scene, label, slices);
  } else {
    for (std::size_t g = 0; g < workload.groups.size(); ++g) slices.push_back(group_slice(workload, g));
  }
  return slices;
}

}  // namespace

PerPose parse_per_pose(std::string_view text) {
  for (PerPose mode : {PerPose::none, PerPose::all, PerPose::wrong})
    if (text == per_pose_name(mode)) return mode;
  throw std::invalid_argument("expected one of none, all, wrong; got \"" + std::string(text) + "\"");
}

const char* per_pose_name(PerPose mode) {
  switch (mode) {
    case PerPose::all:
      return "all";
    case PerPose::wrong:
      return "wrong";
    case PerPose::none:
      break;
  }
  return "none";
}

Environment detect_environment() {
  Environment env;
  std::string cpu;
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  utsname host{};
  std::string os =
      uname(&host) == 0 ? std::string(host.sysname) + " " + host.release + " " + host.machine : "";
  env.machine = (cpu.empty() ? std::string("unknown CPU") : cpu) + ", " +
                std::to_string(std::thread::hardware_concurrency()) + " threads, " + os;
#if defined(__clang__)
  env.compiler = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  env.compiler = std::string("gcc ") + __VERSION__;
#else
  env.compiler = "unknown";
#endif
  env.build_type = BVHLAB_BUILD_TYPE;
#ifdef BVHLAB_SOURCE_DIR
  env.git_commit = run_command("git -C '" + std::string(BVHLAB_SOURCE_DIR) +
                               "' describe --always --dirty --abbrev=12 2>/dev/null");
#endif
  if (env.git_commit.empty()) env.git_commit = "unknown";
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  env.timestamp = stamp;
  return env;
}

RunOutput run_scene(const Scene& scene, const RunOptions& options) {
  if (scene.world || scene.deform || scene.points)  // the other kinds run through make_experiment
    throw std::invalid_argument("run_scene: scene " + scene.name + " is not a pairs scene (make_experiment)");
  const auto wall_start = Clock::now();
  RunOutput output = start_output(scene);
  RunStats& stats = output.stats;
  const LogFn log = log_of(options);
  const unsigned threads = threads_of(options.threads);
  Preparation preparation(options.cache_dir, stats, log, threads);
  stats.clock_overhead_us = clock_overhead_us();
  const RunPlan plan = plan_run(scene);  // what runs where, and on which trees
  for (const auto* skipped : {&scene.notes, &plan.skipped})
    for (const std::string& why : *skipped) {
      stats.skipped.push_back(why);
      log(why);
    }

  Measurement measurement(scene, plan, options, stats, log, threads);
  Aggregation aggregation(stats.clock_overhead_us, options.per_pose);
  output.per_pose = options.per_pose;
  // Every pair is prepared, its truth known and its slices checked before any query is timed; then the
  // timing passes sweep the whole workload, so each pose's samples lie a whole pass apart.
  std::vector<PreparedPair> pairs;
  std::vector<Truth> truths;
  std::vector<SeriesMaps> maps;
  std::vector<std::vector<PoseSlice>> slices;
  for (const ScenePair* scene_pair : plan.pairs) {
    slices.push_back(slices_of(scene, scene_pair->label(),
                               preparation.object(*scene.object(scene_pair->a)).mesh,
                               preparation.object(*scene.object(scene_pair->b)).mesh));
    pairs.push_back(preparation.pair(scene, *scene_pair, plan));
    truths.push_back(measurement.ground_truth(pairs.back(), preparation));
    maps.push_back(measurement.calibration_maps(pairs.back(), preparation));
    advise(pairs.back(), plan, output, log);
  }
  const std::vector<PairRecords> records = measurement.time_workload(pairs);
  for (std::size_t p = 0; p < pairs.size(); ++p)
    for (const PoseSlice& slice : slices[p])
      add_slice(aggregation, pairs[p], plan, slice, truths[p], records[p], maps[p], output);

  const std::vector<SummaryBand> bands = summary_bands(output);
  for (ResultRow& row : output.rows)
    if (const SummaryBand* band = band_of(bands, row.mesh)) row.in_summary = band->contains(row.distance);
  output.calibration = aggregation.calibration();
  output.models = preparation.models();
  preparation.count_cache(stats);
  stats.wall_seconds = seconds_since(wall_start);
  return output;
}

QueryOutcome run_query(const SceneObject& a, const SceneObject& b, const QueryRequest& request,
                       std::span<const RigidTransform> poses, const RunOptions& options) {
  if (poses.empty()) throw std::invalid_argument("query: no pose given");
  if (request.repeat < 0) throw std::invalid_argument("query: a negative repeat count");
  QueryOutcome outcome;
  Scene scene;  // a one-hierarchy, one-strategy scene, so the plan decides the density as for a run
  scene.hierarchies = {request.hierarchy};
  scene.density = request.density;
  StrategySpec strategy;
  strategy.name = request.strategy.strategy;
  strategy.coherent = request.strategy.coherent;
  scene.strategies = {strategy};
  const StrategyInfo& info = strategy_info(strategy.name);
  if (std::string refusal = info.refusal(request.density.name); !refusal.empty())
    throw std::invalid_argument(refusal);
  if (request.hierarchy.is_fcl())
    if (std::string refusal = fcl_refusal(strategy, request.hierarchy.bv); !refusal.empty())
      throw std::invalid_argument(refusal);
  Preparation preparation(options.cache_dir, outcome.stats, log_of(options), threads_of(options.threads));
  const ObjectData object_a = load_object(a);
  const ObjectData object_b = &a == &b ? ObjectData{} : load_object(b);
  const ObjectData& ob = &a == &b ? object_a : object_b;
  for (const ObjectData* object : {&object_a, &object_b})
    for (const std::string& warning : object->warnings)
      outcome.warnings.push_back(object->spec->name + ": " + warning);
  const PlannedHierarchy planned{
      &scene.hierarchies.front(),
      scene.needs_density(scene.hierarchies.front()) ? scene.density : DensitySpec{},
      {request.strategy}};
  auto hierarchy = preparation.hierarchy(planned, object_a, ob);
  if (std::string advice =
          size_advice(request.strategy.strategy, a.name + "|" + b.name, object_a.mesh, ob.mesh);
      !advice.empty())
    outcome.advice.push_back(std::move(advice));
  if (const auto [tree_a, tree_b] = hierarchy->trees(); tree_a) {
    outcome.answers = answer_prepared(*tree_a->prepare(*tree_b, request.strategy), poses, request.repeat);
  } else {  // an FCL pair
    const double overhead = request.repeat ? clock_overhead_us() : 0;
    outcome.answers = answer_poses(
        poses, request.repeat, overhead,
        [&](const RigidTransform& p) { return hierarchy->query(request.strategy, p); },
        [&](std::span<const RigidTransform> all, std::vector<QueryRecord>& records) {
          hierarchy->run(request.strategy, all, 0, records);
        });
  }
  const auto models = preparation.models();
  outcome.model_a = hierarchy->model;
  outcome.model_b = models.back();
  return outcome;
}

}  // namespace bvhlab
