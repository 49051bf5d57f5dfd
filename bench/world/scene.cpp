// The "world" section of a scene: many instances of the scene's objects, their motion over frames, the broad
// phases that find candidate pairs and the budgets shared across a frame (format: bench/scenes/README.md).
#include "bench/core/scene_json.hpp"
#include "bench/world/motion.hpp"
#include "engine/content_hash.hpp"
#include "engine/policies.hpp"
#include "traversal/broad_phase/registry.hpp"
#include "traversal/frame_budget.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace bvhlab::scene_json {

namespace {

constexpr long long kMaxInstances = 100000;
constexpr long long kMaxWorldFrames = 1000000;

std::vector<std::string> frame_schedule_names() {
  std::vector<std::string> names;
  for (const FramePolicy& policy : frame_policies()) names.emplace_back(policy.name);
  return names;
}

std::vector<std::string> frame_order_names() {
  std::vector<std::string> names;
  for (FrameOrder order : frame_orders()) names.emplace_back(frame_order_name(order));
  return names;
}

std::vector<std::string> object_names(const Scene& scene) {
  std::vector<std::string> names;
  for (const auto& o : scene.objects) names.push_back(o.name);
  return names;
}

/// The instances read so far: their names, and the copies of each object (which number the next copy).
struct InstanceIndex {
  std::set<std::string, std::less<>> names;
  std::map<std::string, std::size_t, std::less<>> copies;
};

/// One "instances" entry: {"object": NAME, "count": N} (named NAME#k, placed at random) or {"object": NAME,
/// "name": ..., "placement": {...}} (one copy where it says). Returns the placements given (nullopt: random).
std::vector<std::optional<RigidTransform>> parse_instance(const Node& entry, const Scene& scene,
                                                          std::vector<WorldInstance>& out,
                                                          InstanceIndex& index) {
  entry.expect_object({"object", "count", "name", "placement"});
  const std::string object = entry.child("object").string();
  if (!scene.object(object))
    entry.child("object").fail("no object named \"" + object + "\"; expected one of " +
                               join(object_names(scene)));
  const long long count = entry.has("count") ? entry.child("count").integer(1, kMaxInstances) : 1;
  if (count > 1 && (entry.has("name") || entry.has("placement")))
    entry.child("count").fail("\"name\" and \"placement\" describe one instance; give \"count\": 1");
  if (out.size() + static_cast<std::size_t>(count) > static_cast<std::size_t>(kMaxInstances))
    entry.fail("more than " + std::to_string(kMaxInstances) + " instances");
  std::vector<std::optional<RigidTransform>> placements;
  for (long long k = 0; k < count; ++k) {
    WorldInstance instance{object + "#" + std::to_string(index.copies[object]++), object};
    if (entry.has("name")) instance.name = entry.child("name").string();
    if (!index.names.insert(instance.name).second)
      entry.fail("duplicate instance name \"" + instance.name + "\"");
    out.push_back(instance);
    placements.push_back(entry.has("placement")
                             ? std::optional<RigidTransform>(parse_transform(entry.child("placement"), {}))
                             : std::nullopt);
  }
  return placements;
}

Box parse_region(const Node& node) {
  node.expect_object({"min", "max"});
  const auto lo = node.child("min").numbers(3, -1e12, 1e12), hi = node.child("max").numbers(3, -1e12, 1e12);
  Box region{Vec3(lo[0], lo[1], lo[2]), Vec3(hi[0], hi[1], hi[2])};
  if (!(region.min.array() < region.max.array()).all())
    node.fail("expected \"min\" below \"max\" on every axis");
  return region;
}

/// {"frames": [{"INSTANCE": pose, ...}, ...]}: every instance in every frame, no other names.
std::vector<std::vector<RigidTransform>> read_frame_file(const std::filesystem::path& file,
                                                         const std::vector<WorldInstance>& instances) {
  const std::string source = file.string();
  const json document = parse_json(read_text(file, "frame"), source);
  const Node frames = Node(document, "", source).expect_object({"frames"}).child("frames");
  std::map<std::string, std::size_t, std::less<>> index;
  for (std::size_t i = 0; i < instances.size(); ++i) index.emplace(instances[i].name, i);
  std::vector<std::vector<RigidTransform>> poses;
  for (std::size_t f = 0, n = frames.array_size(); f < n; ++f) {
    const Node frame = frames.child(f);
    if (!frame.value().is_object())
      frame.fail("expected an object of poses by instance name; " + frame.got());
    std::vector<std::optional<RigidTransform>> given(instances.size());
    for (const auto& [name, _] : frame.value().items()) {
      const auto it = index.find(name);
      if (it == index.end()) frame.child(name).fail("no instance named \"" + name + "\"");
      given[it->second] = parse_transform(frame.child(name), {});
    }
    std::vector<RigidTransform> row;
    for (std::size_t i = 0; i < instances.size(); ++i) {
      if (!given[i]) frame.fail("no pose for instance \"" + instances[i].name + "\"");
      row.push_back(*given[i]);
    }
    poses.push_back(std::move(row));
  }
  return poses;
}

void parse_motion(const Node& m, const std::filesystem::path& base_dir, WorldSpec& world,
                  const std::vector<std::optional<RigidTransform>>& placements) {
  const std::string type = m.child("type").choice({"random_walk", "frame_file"});
  if (type == "frame_file") {
    m.expect_object({"type", "file"});
    if (std::any_of(placements.begin(), placements.end(), [](auto& p) { return p.has_value(); }))
      m.child("type").fail("a frame file gives every pose: leave out the instances' \"placement\"");
    world.frame_file = base_dir / m.child("file").string();
    try {
      world.poses = read_frame_file(world.frame_file, world.instances);
    } catch (const SceneError& e) {
      m.child("file").fail(e.what());
    }
    world.frames = static_cast<int>(world.poses.size());
    world.identity = "frames:" + std::to_string(hash_file(world.frame_file));
    return;
  }
  m.expect_object({"type", "frames", "seed", "step", "turn_deg"});
  world.frames = static_cast<int>(m.child("frames").integer(1, kMaxWorldFrames));
  world.seed = m.has("seed") ? static_cast<std::uint64_t>(m.child("seed").integer(0, 1LL << 53)) : 0;
  world.step = m.has("step") ? m.child("step").number(0, 1e12) : 0;
  world.turn_deg = m.has("turn_deg") ? m.child("turn_deg").number(0, 180) : 0;
  if (static_cast<double>(world.frames) * static_cast<double>(world.instances.size()) > limits::kPoses.max)
    m.child("frames").fail("frames x instances is above " + number_text(limits::kPoses.max) + " poses");
  world.poses = random_walk(placements, world.region, world.seed, world.frames, world.step, world.turn_deg);
  world.identity = "walk:" + std::to_string(world.seed) + ":" + std::to_string(world.frames) + ":" +
                   number_text(world.step) + ":" + number_text(world.turn_deg);
}

std::vector<std::string> parse_names(const Node& node, const std::vector<std::string>& known) {
  std::vector<std::string> names;
  for (std::size_t k = 0, n = node.array_size(); k < n; ++k) {
    names.push_back(node.child(k).choice(known));
    if (std::count(names.begin(), names.end(), names.back()) > 1) node.child(k).fail("named twice");
  }
  return names;
}

FrameBudgetSpec parse_frame_budget(const Node& node, const Scene& scene) {
  node.expect_object({"schedules", "budgets", "p_min", "confirm_levels", "order", "memory", "hierarchies"});
  FrameBudgetSpec spec;
  spec.schedules = parse_names(node.child("schedules"), frame_schedule_names());
  spec.budgets = parse_budgets(node.child("budgets"));
  if (node.has("p_min")) {
    spec.p_min = node.child("p_min").number(0, 1);
    if (!(spec.p_min > 0)) node.child("p_min").fail("expected a number in (0, 1]; got 0");
  }
  if (node.has("confirm_levels"))
    spec.confirm_levels = static_cast<int>(node.child("confirm_levels").integer(0, 255));
  if (node.has("order")) spec.order = node.child("order").choice(frame_order_names());
  if (node.has("memory")) spec.memory = node.child("memory").boolean();
  std::vector<std::string> hierarchy_names;
  for (const auto& h : scene.hierarchies) hierarchy_names.push_back(h.name);
  auto probability = [&](const HierarchySpec& h) {
    return !h.is_fcl() && strategy_info("adb").accepts(scene.density_of(h).name);
  };
  if (node.has("hierarchies")) {
    spec.hierarchies = parse_names(node.child("hierarchies"), hierarchy_names);
    for (std::size_t k = 0; k < spec.hierarchies.size(); ++k)
      if (!probability(*scene.hierarchy(spec.hierarchies[k])))
        node.child("hierarchies")
            .child(k)
            .fail("hierarchy \"" + spec.hierarchies[k] + "\" carries no probability density (give it an " +
                  "\"annotation\" such as {\"type\": \"adb\"})");
  } else {
    for (const auto& h : scene.hierarchies)
      if (probability(h)) spec.hierarchies.push_back(h.name);
    if (spec.hierarchies.empty())
      node.fail(
          "no hierarchy carries a probability density (give one an \"annotation\" such as "
          "{\"type\": \"adb\"})");
  }
  return spec;
}

/// Instances of an optional object whose mesh is missing leave the world (with their poses), with a note.
void drop_missing_objects(const Node& w, Scene& scene, WorldSpec& world) {
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < world.instances.size(); ++i) {
    if (!scene.object(world.instances[i].object)->path.empty()) {
      kept.push_back(i);
      continue;
    }
    const std::string note =
        "instances of " + world.instances[i].object + " skipped: optional mesh not found";
    if (std::find(scene.notes.begin(), scene.notes.end(), note) == scene.notes.end())
      scene.notes.push_back(note);
  }
  if (kept.empty()) w.child("instances").fail("no instance is left: every object's mesh is missing");
  if (kept.size() == world.instances.size()) return;
  std::vector<WorldInstance> instances;
  for (std::size_t i : kept) instances.push_back(world.instances[i]);
  world.instances = std::move(instances);
  for (auto& frame : world.poses) {
    std::vector<RigidTransform> row;
    for (std::size_t i : kept) row.push_back(frame[i]);
    frame = std::move(row);
  }
}

}  // namespace

void parse_world(const Node& root, const std::filesystem::path& base_dir, Scene& scene) {
  for (const char* field : {"pairs", "workload"})
    if (root.has(field))
      root.child(field).fail("does not apply to a world scene (its instances move by \"world\"/\"motion\")");
  for (const auto& h : scene.hierarchies)
    if (h.is_fcl())
      root.child("hierarchies")
          .fail("hierarchy \"" + h.name + "\": FCL models do not run in a world scene (bench_broad_phase " +
                "compares FCL's broad-phase managers)");
  const Node w = root.child("world");
  w.expect_object({"instances", "region", "motion", "broad_phases", "frame_budgets", "scaling"});
  WorldSpec world;
  std::vector<std::optional<RigidTransform>> placements;
  const Node instances = w.child("instances");
  InstanceIndex index;
  for (std::size_t k = 0, n = instances.array_size(); k < n; ++k) {
    auto more = parse_instance(instances.child(k), scene, world.instances, index);
    placements.insert(placements.end(), more.begin(), more.end());
  }
  const bool walk = w.child("motion").child("type").choice({"random_walk", "frame_file"}) == "random_walk";
  if (walk)
    world.region = parse_region(w.child("region"));
  else if (w.has("region"))
    w.child("region").fail("does not apply to a frame file (it gives every pose)");
  parse_motion(w.child("motion"), base_dir, world, placements);
  drop_missing_objects(w, scene, world);
  world.broad_phases =
      w.has("broad_phases") ? parse_names(w.child("broad_phases"), broad_phase_names()) : broad_phase_names();
  if (w.has("frame_budgets")) {
    const Node budgets = w.child("frame_budgets");
    for (std::size_t k = 0, n = budgets.array_size(); k < n; ++k)
      world.frame_budgets.push_back(parse_frame_budget(budgets.child(k), scene));
  }
  if (w.has("scaling")) {
    if (!walk) w.child("scaling").fail("needs the random walk (its region and steps set the density)");
    const Node counts = w.child("scaling");
    for (std::size_t k = 0, n = counts.array_size(); k < n; ++k)
      world.scaling.push_back(static_cast<int>(counts.child(k).integer(2, kMaxInstances)));
  }
  scene.world = std::move(world);
}

}  // namespace bvhlab::scene_json
