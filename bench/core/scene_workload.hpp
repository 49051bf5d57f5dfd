// Internal to the scene parser: the sections that make its poses (bench/core/scene_workload.cpp), which
// parse_scene (scene.cpp) reads after the strategies and before the report.
#pragma once

#include "bench/core/scene_json.hpp"

#include <filesystem>

namespace bvhlab::scene_json {

/// "workload": the protocol (the default), random poses in a box, or a pose file, read now; fills the
/// workload's pose groups and its identity (what the ground-truth cache is keyed by).
void parse_workload(const Node& root, const std::filesystem::path& base_dir, WorkloadSpec& workload);

/// "calibration": the held-out training poses, drawn like the workload's (which must be parsed first) from
/// another seed, none equal to a workload pose.
void parse_calibration(const Node& root, Scene& scene);

}  // namespace bvhlab::scene_json
