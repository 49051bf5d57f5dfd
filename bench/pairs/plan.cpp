#include "bench/pairs/plan.hpp"

#include "engine/policies.hpp"

#include <algorithm>

namespace bvhlab {

std::size_t RunPlan::trees_to_annotate_per_object() const {
  return static_cast<std::size_t>(std::count_if(hierarchies.begin(), hierarchies.end(), [](const auto& h) {
    return h.density.name != NoDensity::name();
  }));
}

RunPlan plan_run(const Scene& scene) {
  RunPlan plan;
  for (const ScenePair& pair : scene.pairs) {
    bool usable = true;
    for (const std::string& name : {pair.a, pair.b}) {
      const SceneObject& spec = *scene.object(name);
      if (!spec.path.empty()) continue;
      usable = false;
      const std::string why =
          "object " + spec.name + " skipped: mesh \"" + spec.mesh +
          "\" not found (bundled meshes/ or the mesh cache; fetch it with meshes/fetch.sh)";
      if (std::find(plan.skipped.begin(), plan.skipped.end(), why) == plan.skipped.end())
        plan.skipped.push_back(why);
    }
    if (usable) plan.pairs.push_back(&pair);
  }
  for (const HierarchySpec& h : scene.hierarchies) {
    PlannedHierarchy planned{&h, scene.needs_density(h) ? scene.density_of(h) : DensitySpec{}, {}};
    for (const StrategySpec& s : scene.strategies)
      if (scene.applies(s, h))
        for (const StrategyVariant& v : expand(s)) planned.variants.push_back(v);
    if (!planned.variants.empty()) plan.hierarchies.push_back(std::move(planned));
  }
  std::size_t poses = 0;
  for (const auto& group : scene.workload.groups) poses += group.poses.size();
  for (const auto& h : plan.hierarchies) plan.total_queries += h.variants.size() * poses;
  plan.total_queries *= plan.pairs.size();
  return plan;
}

}  // namespace bvhlab
