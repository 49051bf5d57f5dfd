#include "contact_geometry.hpp"

#include "../bvh/triangle_contact.hpp"

namespace bvhlab {

namespace {

std::vector<std::uint32_t> inverse(const std::vector<std::uint32_t>& ids) {
  std::vector<std::uint32_t> position(ids.size());
  for (std::uint32_t k = 0; k < ids.size(); ++k) position[ids[k]] = k;
  return position;
}

std::array<double, 3> array_of(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace

ContactGeometryMaker::ContactGeometryMaker(const std::vector<TrianglePoints>& triangles_a,
                                           const std::vector<std::uint32_t>& ids_a,
                                           const std::vector<TrianglePoints>& triangles_b,
                                           const std::vector<std::uint32_t>& ids_b)
    : triangles_a_(&triangles_a),
      triangles_b_(&triangles_b),
      position_a_(inverse(ids_a)),
      position_b_(inverse(ids_b)) {}

std::optional<ContactGeometry> ContactGeometryMaker::of(const TrianglePair& pair,
                                                        const RigidTransform& b_to_a) const {
  const TrianglePoints& a = (*triangles_a_)[position_a_.at(pair.a)];
  const TrianglePoints& b = (*triangles_b_)[position_b_.at(pair.b)];
  const TrianglePoints moved = {b_to_a.apply(b[0]), b_to_a.apply(b[1]), b_to_a.apply(b[2])};
  const std::optional<TriangleContact> contact = triangle_contact(a, moved);
  if (!contact) return std::nullopt;
  ContactGeometry out;
  out.triangles = pair;
  out.from = array_of(contact->from);
  out.to = array_of(contact->to);
  out.point = array_of(0.5 * (contact->from + contact->to));
  out.normal = array_of(contact->normal);
  out.coplanar = contact->coplanar;
  return out;
}

void ContactGeometryMaker::operator()(const RigidTransform& b_to_a, Result& result) const {
  result.contact_geometry.clear();
  const auto add = [&](const TrianglePair& pair) {
    if (std::optional<ContactGeometry> g = of(pair, b_to_a)) result.contact_geometry.push_back(*g);
  };
  if (!result.contacts.empty()) {
    result.contact_geometry.reserve(result.contacts.size());
    for (const TrianglePair& pair : result.contacts) add(pair);
  } else if (result.witness) {
    add(*result.witness);
  }
}

}  // namespace bvhlab
