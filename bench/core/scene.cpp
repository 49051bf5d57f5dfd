#include "bench/core/scene.hpp"

#include "adb/update.hpp"

#include "bench/core/scene_json.hpp"
#include "bench/core/scene_workload.hpp"

#include "engine/mesh_catalog.hpp"
#include "engine/policies.hpp"
#include "traversal/strategy_names.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

namespace bvhlab {

using namespace scene_json;

namespace {

/// Runs f; a std::invalid_argument it throws becomes a SceneError at `node`.
template <class F>
auto checked(const Node& node, F&& f) {
  try {
    return f();
  } catch (const std::invalid_argument& e) {
    node.fail(e.what());
  }
}

/// One value of parameter p, checked against its range.
double read_parameter(const Node& node, const ParamSpec& p) {
  const double v = node.number();
  if (const std::string problem = p.problem(v); !problem.empty())
    node.fail(std::string(p.name) + " " + problem);
  return v;
}

/// A sweep parameter takes a number or a non-empty list of distinct numbers; any other takes one number.
std::vector<double> read_values(const Node& node, const ParamSpec& p) {
  if (!p.sweep || !node.value().is_array()) return {read_parameter(node, p)};
  std::vector<double> out;
  for (std::size_t k = 0, m = node.array_size(); k < m; ++k) {
    const double v = read_parameter(node.child(k), p);
    if (std::find(out.begin(), out.end(), v) != out.end())
      node.child(k).fail(std::string(p.name) + " " + parameter_text(v) + " is in the list already");
    out.push_back(v);
  }
  return out;
}

/// The series one strategy entry may sweep (its lists' sizes multiplied, times its budgets): far more than a
/// study plots, and a bound on what expanding and checking them costs.
constexpr double kMaxSeries = 1000;

/// The hierarchies a strategy entry names; false when every one of them was optional and left out.
template <class Skipped>
bool parse_strategy_hierarchies(const Node& s, const Scene& scene, StrategySpec& spec, Skipped&& skipped) {
  if (!s.has("hierarchies")) return true;
  const Node hs = s.child("hierarchies");
  std::vector<std::string> names;
  for (const auto& h : scene.hierarchies) names.push_back(h.name);
  for (std::size_t k = 0, m = hs.array_size(); k < m; ++k) {
    if (skipped(hs.child(k).string())) continue;
    const std::string name = hs.child(k).choice(names);
    if (const HierarchySpec& h = *scene.hierarchy(name); h.is_fcl()) {
      if (std::string refusal = fcl_refusal(spec, h.bv); !refusal.empty()) hs.child(k).fail(refusal);
    } else if (std::string refusal = strategy_info(spec.name).volume_refusal(h.bv); !refusal.empty()) {
      hs.child(k).fail(refusal);
    } else if (std::string no_layout = spec.wide ? strategy_info(spec.name).wide_walk_refusal(h.bv) : "";
               !no_layout.empty()) {
      hs.child(k).fail(no_layout);
    }
    spec.hierarchies.push_back(name);
  }
  return !spec.hierarchies.empty();
}

/// A strategy that needs a density must find one it accepts on every hierarchy it runs on.
void check_densities(const Node& s, const Scene& scene, const StrategySpec& spec, const StrategyInfo& info) {
  for (const HierarchySpec& h : scene.hierarchies) {
    const std::string& density = scene.density_of(h).name;
    if (!scene.applies(spec, h) || info.accepts(density)) continue;
    std::string usable;
    for (const std::string& d : info.densities) usable += (usable.empty() ? "\"" : ", \"") + d + "\"";
    const std::string whose = h.density ? "hierarchy \"" + h.name + "\"'s" : "the scene's";
    s.child("type").fail("\"" + spec.name + "\" needs a density it can estimate from (" + usable + "), " +
                         whose + " is \"" + density +
                         "\"; add \"annotation\": {\"type\": \"adb\", \"grid\": 2, \"tau\": 0.25}");
  }
}

/// One entry of "strategies", checked against the strategy table; nullopt when it has nowhere to run.
template <class Skipped>
std::optional<StrategySpec> parse_strategy(const Node& s, const Scene& scene, Skipped&& skipped) {
  StrategySpec spec;
  spec.name = s.child("type").choice(strategy_names());
  const StrategyInfo& info = strategy_info(spec.name);
  std::vector<std::string> fields{"type", "hierarchies"};
  for (const ParamSpec& p : info.parameters) fields.emplace_back(p.name);
  if (info.budget != BudgetUse::None) fields.emplace_back("budgets");
  fields.emplace_back("coherent");  // refused below, by name, for a strategy that does not run coherent
  fields.emplace_back("wide");      // likewise for a strategy without a wide walk
  s.expect_object(fields);
  for (const ParamSpec& p : info.parameters)
    if (s.has(std::string(p.name)))
      spec.values[std::string(p.name)] = read_values(s.child(std::string(p.name)), p);
  if (info.budget == BudgetUse::Required || s.has("budgets"))
    spec.budgets = parse_budgets(s.child("budgets"));
  if (s.has("coherent")) {
    spec.coherent = s.child("coherent").boolean();
    if (spec.coherent && !info.coherent) s.child("coherent").fail(info.coherent_refusal());
  }
  if (s.has("wide")) {
    spec.wide = s.child("wide").boolean();
    if (spec.wide && !info.wide) s.child("wide").fail(info.wide_refusal());
    if (spec.wide && spec.coherent)
      s.child("wide").fail(
          "a coherent query walks the binary trees; give \"coherent\" or \"wide\", not both");
  }
  double series = std::max<double>(1, static_cast<double>(spec.budgets.size()));
  for (const auto& [name, values] : spec.values) series *= static_cast<double>(values.size());
  if (series > kMaxSeries)
    s.fail("sweeps " + number_text(series) + " series; a strategy entry sweeps at most " +
           number_text(kMaxSeries) + " (split it, or take fewer values)");
  if (!parse_strategy_hierarchies(s, scene, spec, skipped)) return std::nullopt;
  if (info.needs_density) check_densities(s, scene, spec, info);
  if (std::none_of(scene.hierarchies.begin(), scene.hierarchies.end(),
                   [&](const HierarchySpec& h) { return scene.applies(spec, h); }))
    s.fail("\"" + spec.name +
           "\" applies to no hierarchy of the scene (FCL hierarchies run \"exact\", and fcl_obbrss "
           "\"distance\", not coherent or wide; a wide strategy runs on the volumes with a wide layout)");
  checked(s, [&] {
    for (const StrategyVariant& v : expand(spec)) check_strategy_options(v);
    return 0;
  });
  return spec;
}

/// "report": what the summary singles out, checked against what the scene runs.
template <class Skipped>
void parse_report(const Node& root, Scene& scene, Skipped&& skipped) {
  ReportSpec& report = scene.report;
  std::vector<std::string> hierarchy_names;
  for (const auto& h : scene.hierarchies) hierarchy_names.push_back(h.name);
  // The operating point: an inexact strategy swept over p_min (the ADB trade-off curve).
  std::vector<double> operating_p_min;
  for (const auto& s : scene.strategies) {
    const StrategyInfo& info = strategy_info(s.name);
    const ParamSpec* p_min = info.parameter("p_min");
    if (info.exact || !p_min || !p_min->sweep) continue;
    if (report.operating_strategy.empty()) report.operating_strategy = s.name;
    if (s.name != report.operating_strategy) continue;
    for (const StrategyVariant& v : expand(s)) operating_p_min.push_back(v.value_or("p_min", -1));
  }
  std::vector<std::string> operated;
  for (const auto& h : scene.hierarchies)
    for (const auto& s : scene.strategies)
      if (s.name == report.operating_strategy && scene.applies(s, h) &&
          std::find(operated.begin(), operated.end(), h.name) == operated.end())
        operated.push_back(h.name);
  if (root.has("report")) {
    const Node r = root.child("report");
    r.expect_object({"quality_distances", "cgal_sample", "operating_point", "baseline"});
    if (r.has("quality_distances")) {
      const auto q = r.child("quality_distances").numbers(2, 0, 1e6);
      if (q[0] > q[1]) r.child("quality_distances").fail("expected [min, max] with min <= max");
      report.quality_min = q[0];
      report.quality_max = q[1];
      report.quality_given = true;
    }
    if (r.has("cgal_sample"))
      report.cgal_sample = static_cast<int>(r.child("cgal_sample").integer(0, 1'000'000));
    if (r.has("operating_point")) {
      const Node op = r.child("operating_point");
      op.expect_object({"hierarchy", "p_min"});
      if (operated.empty())
        op.fail(
            "an operating point needs an inexact strategy swept over p_min (such as \"adb\") on some "
            "hierarchy");
      if (op.has("hierarchy") && !skipped(op.child("hierarchy").string()))
        report.operating_hierarchy = op.child("hierarchy").choice(operated);
      if (op.has("p_min")) {
        report.operating_p_min = op.child("p_min").number(0, 1);
        if (std::find(operating_p_min.begin(), operating_p_min.end(), report.operating_p_min) ==
            operating_p_min.end())
          op.child("p_min").fail("no \"" + report.operating_strategy + "\" strategy runs this p_min");
      }
    }
    if (r.has("baseline")) {
      const Node b = r.child("baseline");
      b.expect_object({"hierarchy", "strategy"});
      if (b.has("hierarchy") && !skipped(b.child("hierarchy").string()))
        report.baseline_hierarchy = b.child("hierarchy").choice(hierarchy_names);
      if (b.has("strategy")) {
        std::vector<std::string> exact;
        for (const StrategyInfo& info : strategy_table())
          if (info.exact) exact.push_back(info.name);
        report.baseline_strategy = b.child("strategy").choice(exact);
      }
    }
  }
  if (report.operating_hierarchy.empty() && !operated.empty()) report.operating_hierarchy = operated.front();
  if (report.operating_p_min < 0 && !operating_p_min.empty()) {
    std::sort(operating_p_min.begin(), operating_p_min.end());
    report.operating_p_min = operating_p_min.back();
    for (double p : operating_p_min)
      if (p <= 0.9) report.operating_p_min = p;
  }
  if (report.baseline_hierarchy.empty()) {
    report.baseline_hierarchy = scene.hierarchies.front().name;
    for (const auto& h : scene.hierarchies)
      if (h.bv == "dop24") {
        report.baseline_hierarchy = h.name;
        break;
      }
  }
}

std::filesystem::path resolve_mesh(const std::string& mesh, const std::filesystem::path& base_dir) {
  const std::filesystem::path written(mesh);
  const std::filesystem::path relative = written.is_absolute() ? written : base_dir / written;
  if (std::filesystem::is_regular_file(relative))
    return std::filesystem::absolute(relative).lexically_normal();
  if (auto found = find_mesh(written.filename().string())) return *found;
  return {};
}

bool fcl_available() {
#ifdef BVHLAB_HAVE_FCL
  return true;
#else
  return false;
#endif
}

}  // namespace

std::vector<std::string> hierarchy_bv_names() {
  std::vector<std::string> names = volume_names();
  names.emplace_back("fcl_obb");
  names.emplace_back("fcl_obbrss");
  return names;
}

const SceneObject* Scene::object(std::string_view name) const {
  for (const auto& o : objects)
    if (o.name == name) return &o;
  return nullptr;
}

const HierarchySpec* Scene::hierarchy(std::string_view name) const {
  for (const auto& h : hierarchies)
    if (h.name == name) return &h;
  return nullptr;
}

std::string fcl_refusal(const StrategySpec& s, std::string_view fcl_bv) {
  const bool runs =
      !s.coherent && !s.wide &&
      (s.name == kExactStrategyName || (s.name == kDistanceStrategyName && fcl_bv == "fcl_obbrss"));
  if (runs) return "";
  return "\"" + s.name + "\"" + (s.coherent ? " coherent" : "") + (s.wide ? " wide" : "") +
         " does not run on " + std::string(fcl_bv) +
         ": FCL hierarchies run \"exact\", and fcl_obbrss \"distance\", not coherent or wide";
}

bool Scene::applies(const StrategySpec& s, const HierarchySpec& h) const {
  if (!s.hierarchies.empty() &&
      std::find(s.hierarchies.begin(), s.hierarchies.end(), h.name) == s.hierarchies.end())
    return false;
  if (h.is_fcl()) return fcl_refusal(s, h.bv).empty();
  if (s.wide && !strategy_info(s.name).wide_walk_refusal(h.bv).empty()) return false;  // e.g. rss
  return strategy_info(s.name).volume_refusal(h.bv).empty();  // e.g. distance on a volume without a bound
}

const DensitySpec& Scene::density_of(const HierarchySpec& h) const {
  return h.density ? *h.density : density;
}

bool Scene::needs_density(const HierarchySpec& h) const {
  const bool strategy_needs = std::any_of(strategies.begin(), strategies.end(), [&](const StrategySpec& s) {
    return strategy_info(s.name).needs_density && applies(s, h);
  });
  return strategy_needs || (world && std::any_of(world->frame_budgets.begin(), world->frame_budgets.end(),
                                                 [&](const FrameBudgetSpec& f) { return f.applies_to(h); }));
}

namespace {

void parse_objects(const Node& root, const std::filesystem::path& base_dir, Scene& scene) {
  const Node objects = root.child("objects");
  for (std::size_t i = 0, n = objects.array_size(); i < n; ++i) {
    const Node o = objects.child(i);
    o.expect_object({"mesh", "name", "optional", "normalize", "scale", "placement"});
    SceneObject obj;
    obj.mesh = o.child("mesh").string();
    if (obj.mesh.empty()) o.child("mesh").fail("expected a mesh path or catalog name; got \"\"");
    obj.name = o.has("name") ? o.child("name").string() : std::filesystem::path(obj.mesh).stem().string();
    if (obj.name.empty()) o.child("name").fail("expected a non-empty name");
    if (scene.object(obj.name))
      (o.has("name") ? o.child("name") : o.child("mesh"))
          .fail("duplicate object name \"" + obj.name + "\" (give each object its own \"name\")");
    if (o.has("optional")) obj.optional = o.child("optional").boolean();
    if (o.has("normalize")) obj.normalize = o.child("normalize").boolean();
    if (o.has("scale")) {
      obj.scale = o.child("scale").number(0, 1e12);
      if (!(obj.scale > 0)) o.child("scale").fail("expected a positive number; " + o.child("scale").got());
    }
    if (o.has("placement")) obj.placement = parse_transform(o.child("placement"));
    obj.path = resolve_mesh(obj.mesh, base_dir);
    if (obj.path.empty() && !obj.optional)
      o.child("mesh").fail(
          "mesh \"" + obj.mesh + "\" not found relative to " + base_dir.string() +
          " nor in the mesh catalog (bundled meshes/ or the fetched-mesh cache; fetch it with "
          "meshes/fetch.sh, or mark the object \"optional\": true)");
    scene.objects.push_back(std::move(obj));
  }
}

/// "pairs", or each object with a copy of itself.
void parse_pairs(const Node& root, Scene& scene) {
  if (!root.has("pairs")) {
    for (const auto& o : scene.objects) scene.pairs.push_back({o.name, o.name});
    return;
  }
  const Node pairs = root.child("pairs");
  for (std::size_t i = 0, n = pairs.array_size(); i < n; ++i) {
    const Node p = pairs.child(i);
    if (!p.value().is_array() || p.value().size() != 2)
      p.fail("expected [\"object A\", \"object B\"]; " + p.got());
    ScenePair pair{p.child(std::size_t{0}).string(), p.child(1).string()};
    for (std::size_t k = 0; k < 2; ++k) {
      const std::string& nm = k ? pair.b : pair.a;
      if (!scene.object(nm)) {
        std::vector<std::string> names;
        for (const auto& o : scene.objects) names.push_back(o.name);
        p.child(k).fail("no object named \"" + nm + "\"; expected one of " + join(names));
      }
    }
    scene.pairs.push_back(pair);
  }
}

/// An "annotation" object: a registered density and its parameters.
DensitySpec parse_density_spec(const Node& a) {
  if (!a.value().is_object()) a.fail("expected an object; " + a.got());
  DensitySpec density;
  density.name = a.child("type").choice(density_names());
  const DensityInfo& info = density_info(density.name);
  std::vector<std::string> fields{"type"};
  for (const ParamSpec& p : info.parameters) fields.emplace_back(p.name);
  a.expect_object(fields);
  ParamValues given;
  for (const ParamSpec& p : info.parameters)
    if (a.has(std::string(p.name)))
      given[std::string(p.name)] = read_parameter(a.child(std::string(p.name)), p);
  return checked(a, [&] { return density_spec(density.name, given); });
}

/// One entry of "hierarchies"; nullopt (with a note in the scene) for an optional one this build lacks.
std::optional<HierarchySpec> parse_hierarchy(const Node& h, const std::vector<std::string>& bv_names,
                                             Scene& scene) {
  h.expect_object({"bv", "name", "split", "max_leaf_triangles", "optional", "annotation"});
  HierarchySpec spec;
  const bool optional = h.has("optional") && h.child("optional").boolean();
  const std::string bv = h.child("bv").string();
  const bool known = std::find(bv_names.begin(), bv_names.end(), bv) != bv_names.end();
  const bool missing_fcl = bv.rfind("fcl_", 0) == 0 && !fcl_available();
  if (optional && (!known || missing_fcl)) {
    scene.notes.push_back("hierarchy " + (h.has("name") ? h.child("name").string() : bv) + " skipped: " +
                          (missing_fcl ? "this build has no FCL (BVHLAB_WITH_FCL=OFF)"
                                       : "\"" + bv + "\" is not a registered bounding volume"));
    return std::nullopt;
  }
  spec.bv = h.child("bv").choice(bv_names);
  if (missing_fcl)
    h.child("bv").fail("\"" + spec.bv + "\" needs a build with FCL (configure with -DBVHLAB_WITH_FCL=ON)");
  spec.name = h.has("name") ? h.child("name").string() : spec.bv;
  if (spec.name.empty()) h.child("name").fail("expected a non-empty name");
  if (scene.hierarchy(spec.name))
    (h.has("name") ? h.child("name") : h.child("bv"))
        .fail("duplicate hierarchy name \"" + spec.name + "\" (give each hierarchy its own \"name\")");
  if (h.has("split")) {
    if (spec.is_fcl()) h.child("split").fail("FCL builds its own hierarchy; \"split\" does not apply");
    spec.build.split = split_method_from_string(h.child("split").choice({"sah", "median"}));
  }
  if (h.has("max_leaf_triangles")) {
    if (spec.is_fcl())
      h.child("max_leaf_triangles").fail("FCL builds its own hierarchy; this does not apply");
    spec.build.max_leaf_triangles = static_cast<std::uint32_t>(h.child("max_leaf_triangles").integer(1, 255));
  }
  if (h.has("annotation")) {
    if (spec.is_fcl()) h.child("annotation").fail("FCL hierarchies run \"exact\" only; no density applies");
    spec.density = parse_density_spec(h.child("annotation"));
  }
  return spec;
}

void parse_hierarchies(const Node& root, Scene& scene) {
  const std::vector<std::string> bv_names = hierarchy_bv_names();
  const Node hierarchies = root.child("hierarchies");
  for (std::size_t i = 0, n = hierarchies.array_size(); i < n; ++i)
    if (std::optional<HierarchySpec> spec = parse_hierarchy(hierarchies.child(i), bv_names, scene))
      scene.hierarchies.push_back(std::move(*spec));
  if (scene.hierarchies.empty()) hierarchies.fail("no hierarchy is available in this build");
}

/// The scene's density ("annotation").
void parse_density(const Node& root, Scene& scene) {
  if (root.has("annotation")) scene.density = parse_density_spec(root.child("annotation"));
}

/// A density set where no strategy needs it would cost annotation time for nothing: refused, for the
/// scene's (used by the hierarchies without their own) and for each hierarchy's own.
void check_densities_needed(const Node& root, const Scene& scene) {
  const Node hierarchies = root.child("hierarchies");
  for (std::size_t i = 0, n = hierarchies.array_size(); i < n; ++i) {
    const Node h = hierarchies.child(i);
    if (!h.has("annotation")) continue;
    const HierarchySpec* spec =
        scene.hierarchy(h.has("name") ? h.child("name").string() : h.child("bv").string());
    if (spec && spec->density && spec->density->name != NoDensity::name() && !scene.needs_density(*spec))
      h.child("annotation").fail("a density is set but no strategy on this hierarchy needs it");
  }
  if (scene.density.name != NoDensity::name() &&
      std::none_of(scene.hierarchies.begin(), scene.hierarchies.end(),
                   [&](const HierarchySpec& h) { return !h.density && scene.needs_density(h); }))
    root.child("annotation")
        .fail("a density is set but no strategy needs it (annotating would cost time for nothing)");
}

/// Whether the hierarchy of this name was optional and left out (a name may still be referred to).
bool hierarchy_skipped(const Scene& scene, const std::string& name) {
  return std::any_of(scene.notes.begin(), scene.notes.end(), [&](const std::string& note) {
    return note.rfind("hierarchy " + name + " skipped", 0) == 0;
  });
}

void parse_strategies(const Node& root, Scene& scene) {
  auto skipped = [&](const std::string& name) { return hierarchy_skipped(scene, name); };
  const Node strategies = root.child("strategies");
  for (std::size_t i = 0, n = strategies.array_size(); i < n; ++i) {
    const Node s = strategies.child(i);
    if (!s.value().is_object()) s.fail("expected an object; " + s.got());
    std::optional<StrategySpec> spec = parse_strategy(s, scene, skipped);
    if (!spec) {  // every hierarchy it names was optional and left out
      scene.notes.push_back("strategy /strategies/" + std::to_string(i) + " (" + s.child("type").string() +
                            ") skipped: none of its hierarchies is available");
      continue;
    }
    scene.strategies.push_back(std::move(*spec));
  }
}

}  // namespace

Scene parse_scene(std::string_view json_text, const std::filesystem::path& base_dir,
                  std::string_view source_name) {
  const std::string source(source_name);
  const json document = parse_json(json_text, source);
  const Node root(document, "", source);
  root.expect_object({"name", "description", "objects", "pairs", "hierarchies", "annotation", "strategies",
                      "workload", "report", "calibration", "timing", "world", "deform", "points"});
  Scene scene;
  scene.name = root.has("name") ? root.child("name").string() : "scene";
  parse_objects(root, base_dir, scene);
  // A points scene runs its own series on its clouds' trees: pairs and "points" only.
  if (root.has("points")) {
    for (const char* field : {"world", "deform", "hierarchies", "annotation", "strategies", "workload",
                              "report", "calibration", "timing"})
      if (root.has(field))
        root.child(field).fail("does not apply to a points scene (its series and poses are in \"points\")");
    parse_pairs(root, scene);
    parse_points(root, scene, fcl_available());
    return scene;
  }
  if (root.has("world") && root.has("deform"))
    root.child("deform").fail("a scene is a world or a deform scene");
  // A world or deform scene names its own motion: no pairs, workload or report.
  if (root.has("world") || root.has("deform")) {
    const char* kind = root.has("world") ? "world" : "deform";
    parse_hierarchies(root, scene);
    parse_density(root, scene);
    parse_strategies(root, scene);
    for (const char* field : {"report", "calibration", "timing"})
      if (root.has(field)) root.child(field).fail(std::string("does not apply to a ") + kind + " scene");
    if (root.has("world"))
      parse_world(root, base_dir, scene);
    else
      parse_deform(root, base_dir, scene);
    check_densities_needed(root, scene);
    return scene;
  }
  parse_pairs(root, scene);
  parse_hierarchies(root, scene);
  parse_density(root, scene);
  parse_strategies(root, scene);
  check_densities_needed(root, scene);
  parse_workload(root, base_dir, scene.workload);
  parse_calibration(root, scene);
  parse_report(root, scene, [&](const std::string& name) { return hierarchy_skipped(scene, name); });
  check_quality_band(root, scene);
  parse_timing(root, scene);
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  const std::string text = read_text(file, "scene");
  Scene scene = parse_scene(text, std::filesystem::absolute(file).parent_path(), file.string());
  scene.file = file;
  if (scene.name == "scene") scene.name = file.stem().string();
  return scene;
}

}  // namespace bvhlab
