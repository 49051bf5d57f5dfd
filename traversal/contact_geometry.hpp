// The contact geometry of the triangle pairs a query's result names: computed after the traversal, from the
// two trees' triangles, so that the traversal's hot loop pays nothing for it (FCL's enable_contact does the
// same job inside its leaf test).
#pragma once

#include "../volumes/geometry.hpp"
#include "result.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace bvhlab {

/// Made once for two trees (it inverts their triangle orders), then used for any pose. It refers to the
/// trees' triangle arrays, which must outlive it.
class ContactGeometryMaker {
 public:
  /// `triangles_*` in tree order, `ids_*` their source-mesh indices (Bvh::triangles(), triangle_ids()).
  ContactGeometryMaker(const std::vector<TrianglePoints>& triangles_a,
                       const std::vector<std::uint32_t>& ids_a,
                       const std::vector<TrianglePoints>& triangles_b,
                       const std::vector<std::uint32_t>& ids_b);

  /// Fills result.contact_geometry with B placed by `b_to_a`: one entry per contact, or for the witness when
  /// the result lists no contacts, each only if its triangles intersect (the tolerance strategy's witness
  /// may lie apart, within the tolerance: it gets none).
  void operator()(const RigidTransform& b_to_a, Result& result) const;

  /// The geometry of one pair (source-mesh indices), or nullopt when its triangles do not intersect.
  [[nodiscard]] std::optional<ContactGeometry> of(const TrianglePair& pair,
                                                  const RigidTransform& b_to_a) const;

 private:
  const std::vector<TrianglePoints>* triangles_a_;
  const std::vector<TrianglePoints>* triangles_b_;
  std::vector<std::uint32_t> position_a_, position_b_;  ///< source-mesh index -> tree order
};

}  // namespace bvhlab
