// Operations that refuse, each with one message naming what is missing: a volume and a density that do not
// combine (typed_tree.hpp), and what an engine leaves out (the demo's, engine/CMakeLists.txt: the generated
// file that instantiates left_out_ops). Internal to engine/.
#pragma once

#include "adb/saved_tree.hpp"
#include "engine/registry.hpp"
#include "engine/tree_model.hpp"

#include <stdexcept>
#include <string>

namespace bvhlab::engine_detail {

/// Every operation throws std::invalid_argument(Message::text()); loading a saved tree, SavedTreeError
/// naming the file.
template <class Message>
const PairOps& refusing_ops() {
  static const PairOps ops{
      [](const Mesh&, const MeshUnits&, const DensitySpec&, const BuildOptions&) -> ModelPtr {
        throw std::invalid_argument(Message::text());
      },
      [](const UnitCloud&, const DensitySpec&, const BuildOptions&) -> ModelPtr {
        throw std::invalid_argument(Message::text());
      },
      [](std::span<const std::byte>, const std::string& source, const Mesh*, const MeshUnits&) -> ModelPtr {
        throw SavedTreeError("saved tree '" + source + "': " + Message::text());
      },
      [](const TreeModel&, const DensitySpec&, const AnnotationContext&, AnnotateStats*) -> ModelPtr {
        throw std::invalid_argument(Message::text());
      }};
  return ops;
}

/// A density that cannot annotate a volume's trees.
template <class BV, class D>
struct CannotAnnotate {
  static std::string text() {
    return "density " + std::string(D::name()) + " cannot annotate " + std::string(BV::name()) + " trees";
  }
};

/// A combination this engine leaves out, and the program that has it; kVolumeCompiled: the engine has the
/// volume (with other densities), so the density is what is missing.
template <class BV, class D, bool kVolumeCompiled>
struct NotCompiled {
  static std::string text() {
    return (kVolumeCompiled
                ? "density " + std::string(D::name()) + " on " + std::string(BV::name()) + " trees"
                : "bounding volume " + std::string(BV::name())) +
           " is not compiled into this program (the demo's, which has what bench/scenes/demo.json uses); the "
           "full CLI, build/<preset>/bench/bvhlab, has it: `make build`";
  }
};

template <std::size_t V, std::size_t D, bool kVolumeCompiled>
const PairOps& left_out_ops() {
  if constexpr (V < type_list_size(RegisteredVolumes{}) && D < type_list_size(RegisteredDensities{}))
    return refusing_ops<
        NotCompiled<TypeAt<V, RegisteredVolumes>, TypeAt<D, RegisteredDensities>, kVolumeCompiled>>();
  else
    throw std::logic_error("engine slot beyond the registered volumes and densities");
}

}  // namespace bvhlab::engine_detail
