// Exact ground truth from CGAL: exact predicates (Epick) on B's triangles after the rigid transform,
// which is applied in double exactly as the library's traversals apply it (RigidTransform::apply).
#pragma once

#include "bvh/mesh.hpp"
#include "traversal/result.hpp"

#include <memory>
#include <vector>

namespace bvhlab {

/// Owns a CGAL AABB tree over A's triangles (a triangle soup, so non-manifold meshes are fine).
/// Degenerate triangles (collinear or coincident vertices) are checked by brute force as segments or
/// points, since CGAL's triangle predicates require non-degenerate triangles.
class CgalGroundTruth {
 public:
  CgalGroundTruth(const Mesh& a, const Mesh& b);
  ~CgalGroundTruth();
  CgalGroundTruth(CgalGroundTruth&&) noexcept;
  CgalGroundTruth& operator=(CgalGroundTruth&&) noexcept;

  /// Whether any triangle of A touches any triangle of B placed by `b_to_a`.
  [[nodiscard]] bool collides(const RigidTransform& b_to_a) const;
  /// Every intersecting pair (indices into the source meshes), sorted.
  [[nodiscard]] std::vector<TrianglePair> all_contacts(const RigidTransform& b_to_a) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bvhlab
