// The one entry through which a front end other than the CLI (the Python module) runs a scene: it parses the
// scene, refuses options its kind cannot honour before any work, runs it and returns what results.json
// holds. Nothing else of bench/ is meant for them; trees, queries and the registries are in engine/.
#pragma once

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace bvhlab {

/// A refused scene or pose file. what() starts with the file, then the JSON pointer of the bad field:
/// "demo.json: /hierarchies/1/bv: expected one of aabb, fcl_obb, fcl_obbrss; got \"abb\"".
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SceneRunRequest {
  std::filesystem::path cache_dir;              ///< trees and ground truth on disk; empty: none
  unsigned threads = 0;                         ///< preprocessing threads; 0: every core
  std::string per_pose = "none";                ///< "none", "all" or "wrong" (`bvhlab run --per-pose`)
  std::function<void(const std::string&)> log;  ///< the runner's messages; empty: none
};

/// Runs the scene file and returns its results as JSON text (keyed like its CSV files' columns). Throws
/// before any work: SceneError naming the scene's field at fault, std::invalid_argument naming the option.
std::string run_scene_file(const std::filesystem::path& file, const SceneRunRequest& request);

/// The same for a scene given as JSON text, its relative paths taken from `base_dir`.
std::string run_scene_text(std::string_view json_text, const std::filesystem::path& base_dir,
                           const SceneRunRequest& request);

}  // namespace bvhlab
