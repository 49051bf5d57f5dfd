#include "bench/run_scene.hpp"

#include "bench/experiment.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>

namespace bvhlab {

namespace {

RunOptions run_options(const SceneRunRequest& request) {
  RunOptions options;
  try {
    options.per_pose = parse_per_pose(request.per_pose);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("per_pose: ") + e.what());
  }
  options.cache_dir = request.cache_dir;
  options.threads = request.threads;
  options.log = request.log ? request.log : [](const std::string&) {};
  return options;
}

std::string run(const Scene& scene, const SceneRunRequest& request) {
  const RunOptions options = run_options(request);
  const auto experiment = make_experiment(scene);
  if (const auto option = experiment->refused_option(options, false))
    throw std::invalid_argument(*option + ": does not apply to a " + std::string(experiment->kind()) +
                                " scene");
  experiment->run(options);
  return experiment->document().dump();
}

}  // namespace

std::string run_scene_file(const std::filesystem::path& file, const SceneRunRequest& request) {
  return run(load_scene(file), request);
}

std::string run_scene_text(std::string_view json_text, const std::filesystem::path& base_dir,
                           const SceneRunRequest& request) {
  return run(parse_scene(json_text, base_dir, "<dict>"), request);
}

}  // namespace bvhlab
