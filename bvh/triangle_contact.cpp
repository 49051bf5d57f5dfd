#include "bvh/triangle_contact.hpp"

#include "bvh/local_frame.hpp"
#include "bvh/triangle_distance.hpp"
#include "bvh/triangle_intersection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace bvhlab {
namespace {

using local_frame::accurate_cross;
using local_frame::exponent_above;
using local_frame::Frame;
using local_frame::times_power_of_two;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Rounding allowance in local coordinates (the pair spans [1/2, 1)): a vertex this close to a clipping plane
// or to the reference plane counts as on it. A side value or a height carries a few eps of rounding (the
// translation, three clips, the products); 64 eps leaves a margin of ten, so that shared vertices and edges
// stay in. Such a vertex is kept where it lies, or dropped onto the plane: the contact moves by up to about
// 1e-14 of the pair's size. Edges are still cut where the side value or height is 0.
constexpr double kSlack = 64 * kEps;

// A triangle scaled to unit size whose normal is shorter than 1e-140 has no plane: a segment or a point.
constexpr double kFlatSquared = 1e-280;

// Unit normals this close to parallel (sine) are one plane for `coplanar`: rounding tilts a well-shaped
// face's normal by a few eps, a sliver's by more; transversal planes, even at 1e-6 rad, are not coplanar.
constexpr double kParallel = 1e-12;

// Below this |n_p - n_q| (same orientation, nearly parallel) the difference's direction is rounding
// (up to 1e-10 rad of it): n_p, which is perpendicular to the segment too, stands for it.
constexpr double kSameOrientation = 1e-6;

// v scaled by a power of two to a largest component in [1/2, 1): its cross products neither underflow
// nor overflow, whatever the triangle's size in the pair.
Vec3 unit_scale(const Vec3& v) {
  return times_power_of_two(v, -exponent_above(v.cwiseAbs().maxCoeff()));
}

// A triangle with its unit normal; `flat` ones (segments, points) have none. Fatness, |normal| over the
// squared longest edge, picks the prism to clip against.
struct ContactFace {
  TrianglePoints v;
  Vec3 unit = Vec3::Zero();
  double fatness = 0;
  bool flat = true;

  explicit ContactFace(const TrianglePoints& t) : v(t) {
    const int exponent =
        -exponent_above(std::max({(t[1] - t[0]).cwiseAbs().maxCoeff(), (t[2] - t[0]).cwiseAbs().maxCoeff(),
                                  (t[2] - t[1]).cwiseAbs().maxCoeff()}));
    const Vec3 u = times_power_of_two(t[1] - t[0], exponent), w = times_power_of_two(t[2] - t[0], exponent);
    const Vec3 normal = accurate_cross(u, w);
    const double squared = normal.squaredNorm();
    if (!(squared > kFlatSquared)) return;
    flat = false;
    unit = normal / std::sqrt(squared);
    fatness = std::sqrt(squared) / std::max({u.squaredNorm(), w.squaredNorm(), (w - u).squaredNorm()});
  }
};

// A few points without allocation. A clip adds at most one vertex per run of dropped ones, at most half the
// polygon's count: 3, 4, 6, 9 after the three clips. Points on the plane: vertices and one per edge.
template <int N>
struct Points {
  std::array<Vec3, N> v;
  int size = 0;
  void push(const Vec3& x) { v[size++] = x; }
  [[nodiscard]] const Vec3& next(int i) const { return v[(i + 1) % size]; }
};
using Polygon = Points<9>;

// The part of `in` where m . (x - base) >= 0 (one Sutherland–Hodgman step, m unit). Vertices within kSlack
// outside stay, so rounding cannot drop a shared vertex or edge; an edge is cut where its side value is 0,
// and only where it leaves that band.
Polygon clip(const Polygon& in, const Vec3& m, const Vec3& base) {
  std::array<double, 9> side;
  for (int i = 0; i < in.size; ++i) side[i] = m.dot(in.v[i] - base);
  Polygon out;
  for (int i = 0; i < in.size; ++i) {
    const double a = side[i], b = side[(i + 1) % in.size];
    if (a >= -kSlack) out.push(in.v[i]);
    // |a| <= |a - b| for opposite signs, also rounded: the new point stays on the edge.
    if ((a > 0 && b < -kSlack) || (a < -kSlack && b > 0))
      out.push(in.v[i] + (a / (a - b)) * (in.next(i) - in.v[i]));
  }
  return out;
}

// t within the prism over reference face r (the inward half-spaces through its edges, containing its normal).
Polygon inside_prism(const ContactFace& r, const TrianglePoints& t) {
  Polygon c;
  for (const Vec3& x : t) c.push(x);
  for (int k = 0; k < 3 && c.size > 0; ++k) {
    const Vec3 inward = r.unit.cross(unit_scale(r.v[(k + 1) % 3] - r.v[k]));
    c = clip(c, inward.normalized(), r.v[k]);
  }
  return c;
}

// The part of polygon c on r's plane: its vertices within kSlack of the plane, dropped onto it, and the zero
// crossings of its edges with an end beyond the slack on the other side.
struct Section {
  Points<18> points;
  bool all_on_plane = true;
};
Section on_plane(const Polygon& c, const ContactFace& r) {
  std::array<double, 9> height;
  for (int i = 0; i < c.size; ++i) height[i] = r.unit.dot(c.v[i] - r.v[0]);
  Section s;
  for (int i = 0; i < c.size; ++i) {
    const double a = height[i], b = height[(i + 1) % c.size];
    if (std::abs(a) <= kSlack)
      s.points.push(c.v[i] - a * r.unit);
    else
      s.all_on_plane = false;
    if ((a > 0 && b < 0) || (a < 0 && b > 0))
      if (std::max(std::abs(a), std::abs(b)) > kSlack)
        s.points.push(c.v[i] + (a / (a - b)) * (c.next(i) - c.v[i]));
  }
  return s;
}

// The contact's ends: the points lie on one segment (or fill the coplanar polygon), whose extremes are
// the pair farthest apart.
template <int N>
std::pair<Vec3, Vec3> farthest_pair(const Points<N>& s) {
  std::pair<Vec3, Vec3> best = {s.v[0], s.v[0]};
  double longest = -1;
  for (int i = 0; i < s.size; ++i)
    for (int j = i + 1; j < s.size; ++j)
      if (const double d = (s.v[i] - s.v[j]).squaredNorm(); d > longest) {
        longest = d;
        best = {s.v[i], s.v[j]};
      }
  return best;
}

// Two flat triangles meet in a segment only along a common line: A's extent within B's, when A's ends lie
// within kSlack of B's line. Otherwise they meet in a point, which the caller's fallback finds.
std::optional<std::pair<Vec3, Vec3>> collinear_overlap(const TrianglePoints& a, const TrianglePoints& b) {
  const Points<3> va{a, 3}, vb{b, 3};
  const auto [a0, a1] = farthest_pair(va);
  const auto [b0, b1] = farthest_pair(vb);
  const double length = (b1 - b0).norm();
  if (!(length > kSlack)) return std::nullopt;
  const Vec3 u = (b1 - b0) / length;
  const double t0 = u.dot(a0 - b0), t1 = u.dot(a1 - b0);
  if ((a0 - b0 - t0 * u).norm() > kSlack || (a1 - b0 - t1 * u).norm() > kSlack) return std::nullopt;
  const double lo = std::max(std::min(t0, t1), 0.0), hi = std::min(std::max(t0, t1), length);
  if (lo > hi) return std::nullopt;
  return std::pair<Vec3, Vec3>{b0 + lo * u, b0 + hi * u};
}

struct LocalContact {
  std::pair<Vec3, Vec3> ends;
  bool coplanar = false;
};

// P ∩ Q in local coordinates, or nullopt where rounding lost a contact the exact test saw (the caller falls
// back to a common point). The fatter triangle gives the prism: a sliver's side planes meet at a needle-sharp
// corner, where a vertex kept within the slack of two of them can lie far beyond the corner.
std::optional<LocalContact> local_contact(const ContactFace& p, const ContactFace& q) {
  if (p.flat && q.flat) {
    const auto overlap = collinear_overlap(p.v, q.v);
    if (!overlap) return std::nullopt;
    return LocalContact{*overlap, false};
  }
  const bool q_reference = q.fatness >= p.fatness;
  const ContactFace& reference = q_reference ? q : p;
  const Polygon c = inside_prism(reference, q_reference ? p.v : q.v);
  if (c.size == 0) return std::nullopt;
  const Section s = on_plane(c, reference);
  if (s.points.size == 0) return std::nullopt;  // C beyond the slack on one side: rounding hid the contact
  const bool parallel = !p.flat && !q.flat && p.unit.cross(q.unit).norm() <= kParallel;
  return LocalContact{farthest_pair(s.points), s.all_on_plane && parallel};
}

Vec3 contact_normal(const ContactFace& p, const ContactFace& q) {
  if (p.flat) return q.flat ? Vec3::Zero() : Vec3(-q.unit);
  if (q.flat) return p.unit;
  const Vec3 difference = p.unit - q.unit;
  const double length = difference.norm();
  return length > kSameOrientation ? Vec3(difference / length) : p.unit;
}

}  // namespace

std::optional<TriangleContact> triangle_contact(const TrianglePoints& p, const TrianglePoints& q) {
  local_frame::require_finite(p, "triangle_contact", "P");
  local_frame::require_finite(q, "triangle_contact", "Q");
  if (!triangles_intersect(p, q)) return std::nullopt;
  Frame frame;
  const auto local = frame.enter(p, q);
  const ContactFace fp(local[0]), fq(local[1]);
  const Vec3 normal = contact_normal(fp, fq);
  if (const auto c = local_contact(fp, fq))
    return TriangleContact{frame.world(c->ends.first), frame.world(c->ends.second), normal, c->coplanar};
  const Vec3 common = triangle_distance(p, q).on_p;  // distance 0: on_p == on_q lies on both
  return TriangleContact{common, common, normal, false};
}

}  // namespace bvhlab
