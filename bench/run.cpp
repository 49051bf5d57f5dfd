// The scene runner as a pipeline: parse (bench/core/scene.cpp, before this) -> plan (plan.cpp) -> prepare
// (prepare.cpp) -> measure (measure.cpp) -> aggregate (aggregate.cpp) -> write (write.cpp, after this).
#include "bench/run.hpp"

#include "bench/aggregate.hpp"
#include "bench/core/policies.hpp"
#include "bench/measure.hpp"
#include "bench/plan.hpp"
#include "bench/prepare.hpp"
#include "traversal/strategies.hpp"

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
  if (scene.points)  // its series are its own (bench/points.hpp); Python and `bvhlab query` do not run them
                     // yet
    throw std::invalid_argument("scene " + scene.name + " is a points scene: run it with `bvhlab report`");
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
  for (const ScenePair* scene_pair : plan.pairs) {
    const PreparedPair pair = preparation.pair(scene, *scene_pair, plan);
    const Truth truth = measurement.ground_truth(pair, preparation);
    const SeriesMaps maps = measurement.calibration_maps(pair, preparation);
    for (const TruthSummary& summary : summarize_truth(pair.label, scene.workload, truth))
      output.truth.push_back(summary);
    for (std::size_t g = 0; g < scene.workload.groups.size(); ++g)
      aggregation.add_group(pair, plan, g, truth[g], measurement.time_group(pair, g), output, maps);
  }

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
  scene.strategies = {strategy};
  const StrategyInfo& info = strategy_info(strategy.name);
  if (info.needs_density && !info.accepts(request.density.name))
    throw std::invalid_argument("strategy " + strategy.name + " does not run on trees with density '" +
                                request.density.name + "'");
  if (request.hierarchy.is_fcl() && strategy.name != ExactStrategy::name())
    throw std::invalid_argument("FCL hierarchies answer exact first-contact queries only");
  Preparation preparation(options.cache_dir, outcome.stats, log_of(options), threads_of(options.threads));
  const ObjectData object_a = load_object(a);
  const ObjectData object_b = &a == &b ? ObjectData{} : load_object(b);
  const ObjectData& ob = &a == &b ? object_a : object_b;
  const PlannedHierarchy planned{
      &scene.hierarchies.front(),
      scene.needs_density(scene.hierarchies.front()) ? scene.density : DensitySpec{},
      {request.strategy}};
  auto hierarchy = preparation.hierarchy(planned, object_a, ob);
  const double overhead = request.repeat ? clock_overhead_us() : 0;
  for (const RigidTransform& pose : poses)
    outcome.answers.push_back(answer_pose(
        pose, request.repeat, overhead,
        [&](const RigidTransform& p) { return hierarchy->query(request.strategy, p); },
        [&](const std::vector<RigidTransform>& copies, std::vector<QueryRecord>& records) {
          hierarchy->run(request.strategy, copies, 0, records);
        }));
  const auto models = preparation.models();
  outcome.model_a = hierarchy->model;
  outcome.model_b = models.back();
  return outcome;
}

}  // namespace bvhlab
