// The sphere's construction, merging and containment, compiled once (volumes/CMakeLists.txt).
#include "sphere.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace bvhlab {

Sphere Sphere::fit(std::span<const Vec3> points) {
  if (std::any_of(points.begin(), points.end(), [](const Vec3& p) { return !p.allFinite(); }))
    throw std::invalid_argument("sphere::fit: a point has a NaN or infinite coordinate");
  if (points.empty()) return {};
  Box box;
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& p : points) {
    box.extend(p);
    centroid += p;
  }
  centroid /= double(points.size());
  Sphere best = around(points, box.center(), 0);
  for (const Sphere& candidate : {around(points, centroid, 0), around(points, ritter_center(points), 0)})
    if (candidate.radius < best.radius) best = candidate;
  return best;
}

Sphere Sphere::merge(const Sphere& a, const Sphere& b) {
  if (a.empty()) return b;
  if (b.empty()) return a;
  const Vec3 ca = to_vec(a.center), cb = to_vec(b.center);
  // Inputs are widened by their own centre rounding bound: under the GCC 12 folding (see rounded()) the
  // centres read here may be the unrounded ones.
  const double ra = a.radius + 0x1p-24 * ca.norm(), rb = b.radius + 0x1p-24 * cb.norm();
  const double gap = (cb - ca).norm() * (1 + 4 * std::numeric_limits<double>::epsilon());
  if (gap + rb <= a.radius) return a;
  if (gap + ra <= b.radius) return b;
  // The smallest sphere around both: its diameter spans the two far ends along the centre line.
  const double radius = (gap + ra + rb) / 2;
  const Vec3 center = gap > 0 ? Vec3(ca + (cb - ca) * ((radius - ra) / gap)) : ca;
  return rounded(center,
                 radius + 8 * std::numeric_limits<double>::epsilon() * std::max(ca.norm(), cb.norm()));
}

bool Sphere::contains(const Vec3& p) const {
  return !empty() && distance(to_vec(center), p) <= radius;
}

double Sphere::distance(const Vec3& c, const Vec3& p) {
  return (p - c).norm();
}

Sphere Sphere::around(std::span<const Vec3> points, const Vec3& center, double margin) {
  double r = 0;
  for (const Vec3& p : points) r = std::max(r, distance(center, p));
  return rounded(center, r + margin);
}

Sphere Sphere::rounded(const Vec3& center, double radius) {
  Sphere out;
  out.center = {float(center.x()), float(center.y()), float(center.z())};
  const double moved = 0x1p-24 * center.norm() + 1e-44;
  out.radius = float_up((radius + moved) * (1 + 8 * std::numeric_limits<double>::epsilon()));
  return out;
}

Vec3 Sphere::ritter_center(std::span<const Vec3> points) {
  auto farthest = [&](const Vec3& from) {
    const Vec3* best = &points[0];
    for (const Vec3& p : points)
      if ((p - from).squaredNorm() > (*best - from).squaredNorm()) best = &p;
    return *best;
  };
  const Vec3 y = farthest(points[0]), z = farthest(y);
  Vec3 center = (y + z) / 2;
  double radius = (z - y).norm() / 2;
  for (const Vec3& p : points) {
    const double d = (p - center).norm();
    if (d > radius) {
      const double grown = (radius + d) / 2;
      center += (p - center) * ((grown - radius) / d);
      radius = grown;
    }
  }
  return center;
}

}  // namespace bvhlab
