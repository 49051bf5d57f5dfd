// What the demo's CLI (bench/bvhlab-demo) has instead of the world, deform and points runners: it runs pairs
// scenes such as bench/scenes/demo.json, and refuses any other kind of scene by name while parsing it.
// Leaving the other kinds out saves the demo about 80 s of compiling (tests/README.md, "Build and CI times").
#include "bench/core/scene_json.hpp"
#include "bench/deform/deform.hpp"
#include "bench/points/points.hpp"
#include "bench/world/world.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

namespace bvhlab {

namespace {

[[noreturn]] void refuse(const scene_json::Node& root, const char* kind) {
  root.child(kind).fail(std::string("a ") + kind +
                        " scene is not run by this program (the demo's, which runs pairs scenes); the full "
                        "CLI, build/<preset>/bench/bvhlab, runs it: `make build`");
}

/// Parsing refuses every other kind first, so nothing below is ever called.
[[noreturn]] void unreachable(const char* what) {
  throw std::logic_error(std::string(what) + " in the demo's CLI, which parses no such scene");
}

}  // namespace

namespace scene_json {
void parse_world(const Node& root, const std::filesystem::path&, Scene&) {
  refuse(root, "world");
}
void parse_deform(const Node& root, const std::filesystem::path&, Scene&) {
  refuse(root, "deform");
}
void parse_points(const Node& root, Scene&, bool) {
  refuse(root, "points");
}
}  // namespace scene_json

WorldOutput run_world(const Scene&, const RunOptions&) {
  unreachable("run_world");
}
nlohmann::json world_document(const WorldOutput&) {
  unreachable("world_document");
}
ReportFolder world_report_folder(const WorldOutput&) {
  unreachable("world_report_folder");
}
std::string world_readme(const WorldOutput&, const std::vector<std::string>&) {
  unreachable("world_readme");
}
DeformOutput run_deform(const Scene&, const RunOptions&) {
  unreachable("run_deform");
}
nlohmann::json deform_document(const DeformOutput&) {
  unreachable("deform_document");
}
std::string deform_readme(const DeformOutput&, const std::vector<std::string>&) {
  unreachable("deform_readme");
}
ReportFolder deform_report_folder(const DeformOutput&) {
  unreachable("deform_report_folder");
}
PointsOutput run_points(const Scene&, bool) {
  unreachable("run_points");
}
nlohmann::json points_document(const PointsOutput&) {
  unreachable("points_document");
}
std::string points_text(const PointsOutput&) {
  unreachable("points_text");
}
ReportFolder points_report_folder(const PointsOutput&) {
  unreachable("points_report_folder");
}

}  // namespace bvhlab
