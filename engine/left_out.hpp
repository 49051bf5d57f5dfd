// The operations of a volume and density an engine leaves out (bvhlab_add_engine's DEMO,
// engine/CMakeLists.txt: the demo's engine has only what bench/scenes/demo.json uses): each refuses, naming
// what is missing and the program that has it. Included only by the generated file that instantiates them.
// Internal to engine/.
#pragma once

#include "adb/saved_tree.hpp"
#include "engine/registry.hpp"
#include "engine/tree_model.hpp"

#include <stdexcept>
#include <string>

namespace bvhlab::engine_detail {

template <class BV, class D>
std::invalid_argument not_compiled() {
  // Density 0 (none) is in every engine: with it, the volume is there and the density is what is missing.
  const bool volume_compiled = slot_compiled(type_index<BV>(RegisteredVolumes{}), 0);
  const std::string what =
      volume_compiled ? "density " + std::string(D::name()) + " on " + std::string(BV::name()) + " trees"
                      : "bounding volume " + std::string(BV::name());
  return std::invalid_argument(what +
                               " is not compiled into this program (the demo's, which has what "
                               "bench/scenes/demo.json uses); the full CLI, build/<preset>/bench/bvhlab, has "
                               "it: `make build`");
}

template <class BV, class D>
const PairOps& refusing_ops() {
  static const PairOps ops{
      [](const Mesh&, const MeshUnits&, const DensitySpec&, const BuildOptions&) -> ModelPtr {
        throw not_compiled<BV, D>();
      },
      [](const UnitCloud&, const DensitySpec&, const BuildOptions&) -> ModelPtr {
        throw not_compiled<BV, D>();
      },
      [](std::span<const std::byte>, const std::string& source, const Mesh*, const MeshUnits&) -> ModelPtr {
        throw SavedTreeError("saved tree '" + source + "': " + not_compiled<BV, D>().what());
      },
      [](const TreeModel&, const DensitySpec&, const AnnotationContext&, AnnotateStats*) -> ModelPtr {
        throw not_compiled<BV, D>();
      }};
  return ops;
}

template <std::size_t V, std::size_t D>
const PairOps& left_out_ops() {
  if constexpr (V < type_list_size(RegisteredVolumes{}) && D < type_list_size(RegisteredDensities{}))
    return refusing_ops<TypeAt<V, RegisteredVolumes>, TypeAt<D, RegisteredDensities>>();
  else
    throw std::logic_error("engine slot beyond the registered volumes and densities");
}

}  // namespace bvhlab::engine_detail
