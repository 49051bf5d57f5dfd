// The plan stage of the bench pipeline (parse -> plan -> prepare -> measure -> aggregate -> write): from a
// parsed scene, what to load, build, annotate and run. "Only what the scene needs" is decided here, once,
// and tested on the plan (tests/bench/test_plan.cpp); the runner follows it.
#pragma once

#include "bench/core/scene.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace bvhlab {

/// One hierarchy of the scene that some strategy runs on.
struct PlannedHierarchy {
  const HierarchySpec* hierarchy = nullptr;
  /// What its trees carry: the scene's density when a strategy on it needs one, else none (built bare).
  DensitySpec density;
  std::vector<StrategyVariant> variants;  ///< every series it runs, in scene order
};

struct RunPlan {
  std::vector<const ScenePair*> pairs;  ///< the pairs whose meshes were found
  /// Objects left out (an optional object whose mesh is missing), with the reason, once each.
  std::vector<std::string> skipped;
  std::vector<PlannedHierarchy> hierarchies;  ///< in scene order; hierarchies nothing runs on are left out
  std::size_t total_queries = 0;              ///< timed queries the run will make
  [[nodiscard]] std::size_t trees_to_annotate_per_object() const;
};

/// The plan of a parsed scene. `scene` must outlive it.
RunPlan plan_run(const Scene& scene);

}  // namespace bvhlab
