// Internal to the report's sources (report.cpp, report_readme.cpp): the number formatting both use, and
// whether a scene is in the protocol's normalised units (the README's workload and the figures' axis say so).
#pragma once

#include "bench/core/scene.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace bvhlab::report_detail {

/// One number through printf's `format`.
inline std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

/// Whether every object is in the protocol's normalised units (normalised, not scaled).
inline bool normalised_units(const Scene& scene) {
  return std::all_of(scene.objects.begin(), scene.objects.end(),
                     [](const SceneObject& o) { return o.normalize && o.scale == 1; });
}

}  // namespace bvhlab::report_detail
