// The bounding-volume models bvhlab ships, listed once. The CLI, scenes and benchmarks offer exactly these
// (engine/registry.hpp), and the typed volume tests run over them (tests/support/volume_lists.hpp).
#pragma once

#include "aabb.hpp"
#include "dop24.hpp"
#include "kdop.hpp"
#include "obb.hpp"
#include "restricted_box.hpp"
#include "rss.hpp"
#include "sphere.hpp"
#include "type_list.hpp"

namespace bvhlab {

/// Every shipped model, in the order tools list them. A new model is added here, and nowhere else.
using ShippedVolumes =
    TypeList<Aabb, Dop<6>, Dop<14>, Dop<18>, Dop24, Dop<26>, Obb, Sphere, Rss, RestrictedBox>;

/// What the sanitizer builds register and test (BVHLAB_LEAN_VOLUMES: engine/registry.hpp, the typed traversal
/// tests, the robustness suite's helpers): one k-DOP stands for its family, the same template with other
/// direction tables, so that a sanitized build compiles four ninths fewer of the runner's instantiations.
using LeanVolumes = TypeList<Aabb, Dop24, Obb, Sphere, RestrictedBox>;

}  // namespace bvhlab
