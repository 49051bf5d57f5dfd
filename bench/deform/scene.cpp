// The "deform" section of a scene: one object deforming over frames (a procedural deformation or one mesh
// file per frame) against a rigid object, B's poses, the refit and the density updates (format:
// bench/scenes/README.md).
#include "adb/update.hpp"
#include "bench/core/scene_json.hpp"
#include "bvh/deform.hpp"
#include "engine/protocol.hpp"

#include <algorithm>

namespace bvhlab::scene_json {

namespace {

constexpr long long kMaxDeformFrames = 100000;
constexpr long long kMaxSteps = 100000;

const SceneObject& named_object(const Node& node, const Scene& scene) {
  const std::string name = node.string();
  const SceneObject* object = scene.object(name);
  if (!object) node.fail("no object named \"" + name + "\"");
  if (object->path.empty())
    node.fail("the mesh of \"" + name + "\" (" + object->mesh +
              ") is not available: fetch it (meshes/fetch.sh) or name another object");
  return *object;
}

std::vector<PoseGroup> parse_poses(const Node& node) {
  node.expect_object({"distances", "steps"});
  std::vector<PoseGroup> groups;
  const int steps = static_cast<int>(node.child("steps").integer(1, kMaxSteps));
  const Node distances = node.child("distances");
  const std::size_t n = distances.array_size();
  check_pose_count(node, static_cast<double>(n) * steps,
                   std::to_string(n) + " distances of " + std::to_string(steps) + " steps");
  for (std::size_t k = 0; k < n; ++k) {
    const double d = distances.child(k).number(limits::kDistance.min, limits::kDistance.max);
    groups.push_back({d, protocol_poses(d, steps)});
  }
  return groups;
}

DensityUpdateSpec parse_density_update(const Node& node) {
  if (!node.value().is_object()) node.fail("expected an object; " + node.got());
  DensityUpdateSpec spec;
  spec.name = node.child("type").choice(density_update_names());
  ParamValues given;
  for (const auto& [key, value] : node.value().items()) {
    if (key == "type") continue;
    given[key] = node.child(key).number();
  }
  try {
    spec.values = with_density_update(spec.name, [&]<class U>(std::type_identity<U>) {
      return resolve_parameters(U::parameters(), given, U::name());
    });
  } catch (const std::invalid_argument& e) {
    node.fail(e.what());
  }
  return spec;
}

void parse_frames(const Node& d, const std::filesystem::path& base_dir, DeformSpec& deform) {
  if (d.has("deformation") == d.has("frame_files"))
    d.fail("expected either \"deformation\" (with \"frames\") or \"frame_files\"");
  if (d.has("frame_files")) {
    if (d.has("frames")) d.child("frames").fail("frame files give the frames; leave it out");
    const Node files = d.child("frame_files");
    for (std::size_t k = 0, n = files.array_size(); k < n; ++k) {
      const std::filesystem::path file = base_dir / files.child(k).string();
      if (!std::filesystem::is_regular_file(file)) files.child(k).fail("no such file: " + file.string());
      deform.frame_files.push_back(file);
    }
    deform.frames = static_cast<int>(deform.frame_files.size());
    return;
  }
  deform.deformation = d.child("deformation").string();
  try {
    (void)parse_deformation(deform.deformation);
  } catch (const std::invalid_argument& e) {
    d.child("deformation").fail(e.what());
  }
  deform.frames = static_cast<int>(d.child("frames").integer(1, kMaxDeformFrames));
}

}  // namespace

void parse_deform(const Node& root, const std::filesystem::path& base_dir, Scene& scene) {
  for (const char* field : {"pairs", "workload"})
    if (root.has(field))
      root.child(field).fail("does not apply to a deform scene (B's poses are \"deform\"/\"poses\")");
  const Node d = root.child("deform");
  d.expect_object({"object", "other", "deformation", "frame_files", "frames", "poses", "refit",
                   "rebuild_degradation", "density_updates"});
  DeformSpec deform;
  deform.object = named_object(d.child("object"), scene).name;
  deform.other = d.has("other") ? named_object(d.child("other"), scene).name : deform.object;
  parse_frames(d, base_dir, deform);
  deform.poses = parse_poses(d.child("poses"));
  if (d.has("refit")) deform.refit_by_fit = d.child("refit").choice({"merge", "fit"}) == "fit";
  if (d.has("rebuild_degradation"))
    deform.rebuild_degradation = d.child("rebuild_degradation").number(1, 1e6);
  if (d.has("density_updates")) {
    const Node updates = d.child("density_updates");
    for (std::size_t k = 0, n = updates.array_size(); k < n; ++k)
      deform.density_updates.push_back(parse_density_update(updates.child(k)));
  } else {
    for (const std::string& name : density_update_names())
      deform.density_updates.push_back({name, with_density_update(name, []<class U>(std::type_identity<U>) {
                                          return resolve_parameters(U::parameters(), {}, U::name());
                                        })});
  }
  for (const HierarchySpec& h : scene.hierarchies)
    if (scene.needs_density(h) && scene.density_of(h).name != AdbDensity::name())
      root.child("hierarchies")
          .fail("hierarchy \"" + h.name + "\": a deform scene updates the density \"adb\" only (got \"" +
                scene.density_of(h).name + "\")");
  scene.deform = std::move(deform);
}

}  // namespace bvhlab::scene_json
