// Tree<BV, Density>: a hierarchy plus a per-node density annotation stored beside the nodes
// (adb/concept.hpp). A tree without density pays nothing: NoDensity's storage is an empty member.
#pragma once

#include "../bvh/bvh.hpp"
#include "concept.hpp"

#include <stdexcept>
#include <type_traits>

namespace bvhlab {

/// No annotation: no preprocessing, zero bytes per node, nothing saved.
struct NoDensity {
  struct Params {
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct Storage {};

  static constexpr std::string_view name() { return "none"; }
  static constexpr std::uint32_t version() { return 1; }
  static std::span<const ParamSpec> parameters() { return {}; }
  static Params make_params(const ParamValues&) { return {}; }
  template <TreeVolume BV>
  static Storage annotate(const Bvh<BV>&, const Params&, const AnnotationContext&, AnnotateStats*) {
    return {};
  }
  static std::string describe(const Storage&) { return "none"; }
  static std::vector<std::byte> encode(const Storage&) { return {}; }
  static Storage decode(std::span<const std::byte> bytes, std::size_t) {
    if (!bytes.empty())
      throw std::invalid_argument("density 'none' stores no bytes, found " + std::to_string(bytes.size()));
    return {};
  }
  static std::size_t memory_bytes(const Storage&) { return 0; }
};
static_assert(std::is_empty_v<NoDensity::Storage> && Density<NoDensity>);

template <TreeVolume BV, Density D = NoDensity>
struct Tree {
  using Volume = BV;
  using DensityType = D;
  Bvh<BV> bvh;
  [[no_unique_address]] typename D::Storage density;
};

/// True when Tree<BV, NoDensity> is exactly as large as the bare Bvh<BV> (checked per BV where used).
template <TreeVolume BV>
inline constexpr bool no_density_is_free = sizeof(Tree<BV, NoDensity>) == sizeof(Bvh<BV>);

/// Annotates a built tree (which must still hold its polygons) with density D.
template <class D, TreeVolume BV>
requires DensityFor<D, BV> Tree<BV, D> annotate_tree(Bvh<BV> bvh, const typename D::Params& params,
                                                     const AnnotationContext& context = {},
                                                     AnnotateStats* stats = nullptr) {
  typename D::Storage storage = D::annotate(bvh, params, context, stats);
  return Tree<BV, D>{std::move(bvh), std::move(storage)};
}

}  // namespace bvhlab
