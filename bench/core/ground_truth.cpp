#include "bench/core/ground_truth.hpp"

#include "bvh/triangle_intersection.hpp"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>

namespace bvhlab {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangles = std::vector<K::Triangle_3>;
using Primitive = CGAL::AABB_triangle_primitive<K, Triangles::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 point(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}
bool degenerate(const TrianglePoints& t) {
  return CGAL::collinear(point(t[0]), point(t[1]), point(t[2]));
}
}  // namespace

struct CgalGroundTruth::Impl {
  Mesh a, b;
  Triangles a_regular;                       // non-degenerate triangles of A, for the tree
  std::vector<std::uint32_t> a_regular_ids;  // their indices in A
  std::vector<std::uint32_t> a_degenerate;   // indices of A's degenerate triangles
  std::vector<bool> b_degenerate;
  bool any_b_degenerate = false;
  Tree tree;
  Box a_regular_box;  // of a_regular's corners: a moved triangle of B whose box misses it cannot touch them

  TrianglePoints moved_b(std::size_t j, const RigidTransform& pose) const {
    const auto t = b.triangle(j);
    return {pose.apply(t[0]), pose.apply(t[1]), pose.apply(t[2])};
  }

  // Calls visit(i, j) for every intersecting pair; stops early when visit returns false.
  template <class Visit>
  void for_each_contact(const RigidTransform& pose, Visit&& visit) const {
    for (std::size_t j = 0; j < b.triangles.size(); ++j) {
      const TrianglePoints q = moved_b(j, pose);
      const auto ju = static_cast<std::uint32_t>(j);
      if (!b_degenerate[j] && !a_regular.empty()) {
        const K::Triangle_3 query(point(q[0]), point(q[1]), point(q[2]));
        std::vector<Tree::Primitive_id> hits;
        tree.all_intersected_primitives(query, std::back_inserter(hits));
        for (auto it : hits)
          if (!visit(a_regular_ids[static_cast<std::size_t>(it - a_regular.begin())], ju)) return;
      } else if (b_degenerate[j]) {
        for (std::size_t i = 0; i < a.triangles.size(); ++i)
          if (triangles_intersect_exact(a.triangle(i), q) && !visit(static_cast<std::uint32_t>(i), ju))
            return;
        continue;
      }
      for (std::uint32_t i : a_degenerate)
        if (triangles_intersect_exact(a.triangle(i), q) && !visit(i, ju)) return;
    }
  }
};

CgalGroundTruth::CgalGroundTruth(const Mesh& a, const Mesh& b) : impl_(std::make_unique<Impl>()) {
  impl_->a = a;
  impl_->b = b;
  for (std::size_t i = 0; i < a.triangles.size(); ++i) {
    const auto t = a.triangle(i);
    if (degenerate(t)) {
      impl_->a_degenerate.push_back(static_cast<std::uint32_t>(i));
    } else {
      impl_->a_regular.emplace_back(point(t[0]), point(t[1]), point(t[2]));
      impl_->a_regular_ids.push_back(static_cast<std::uint32_t>(i));
    }
  }
  impl_->b_degenerate.resize(b.triangles.size());
  for (std::size_t j = 0; j < b.triangles.size(); ++j) {
    impl_->b_degenerate[j] = degenerate(b.triangle(j));
    impl_->any_b_degenerate = impl_->any_b_degenerate || impl_->b_degenerate[j];
  }
  for (std::uint32_t i : impl_->a_regular_ids)
    for (const Vec3& corner : a.triangle(i)) impl_->a_regular_box.extend(corner);
  impl_->tree.insert(impl_->a_regular.begin(), impl_->a_regular.end());
  impl_->tree.build();
}

CgalGroundTruth::~CgalGroundTruth() = default;
CgalGroundTruth::CgalGroundTruth(CgalGroundTruth&&) noexcept = default;
CgalGroundTruth& CgalGroundTruth::operator=(CgalGroundTruth&&) noexcept = default;

bool CgalGroundTruth::collides(const RigidTransform& b_to_a) const {
  const Impl& m = *impl_;
  if (m.a_degenerate.empty() && !m.any_b_degenerate) {  // the common case: CGAL's tree answers alone
    // B's vertices moved once (the same doubles moved_b gives), and a triangle whose box misses A's box
    // left out before CGAL is asked: the box holds the exact corners, so this drops no contact.
    std::vector<Vec3> moved(m.b.vertices.size());
    for (std::size_t v = 0; v < moved.size(); ++v) moved[v] = b_to_a.apply(m.b.vertices[v]);
    for (const TriangleIndices& t : m.b.triangles) {
      const TrianglePoints q{moved[t[0]], moved[t[1]], moved[t[2]]};
      Box box;
      for (const Vec3& corner : q) box.extend(corner);
      if (!box.overlaps(m.a_regular_box)) continue;
      if (m.tree.do_intersect(K::Triangle_3(point(q[0]), point(q[1]), point(q[2])))) return true;
    }
    return false;
  }
  bool any = false;
  m.for_each_contact(b_to_a, [&](std::uint32_t, std::uint32_t) {
    any = true;
    return false;
  });
  return any;
}

std::vector<TrianglePair> CgalGroundTruth::all_contacts(const RigidTransform& b_to_a) const {
  std::vector<TrianglePair> out;
  impl_->for_each_contact(b_to_a, [&](std::uint32_t i, std::uint32_t j) {
    out.push_back({i, j});
    return true;
  });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace bvhlab
