#include "bvh/triangle_distance.hpp"

#include "bvh/local_frame.hpp"
#include "bvh/triangle_intersection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace bvhlab {
namespace {

using local_frame::accurate_cross;
using local_frame::Frame;

// Below this squared length (local coordinates, pair size ~1) a normal is no plane: the triangle or the edge
// pair is then within 1e-70 of the vertex-edge candidates, which stand for it.
constexpr double kTinySquared = 1e-280;

// A segment [a, b] with b - a and its squared length, computed once for the many points measured against it.
struct Segment {
  Vec3 a, b, d;
  double squared;
  Segment(const Vec3& from, const Vec3& to) : a(from), b(to), d(to - from), squared(d.squaredNorm()) {}
};

// A triangle with its edges and its normal. `flat` (collinear, repeated vertices, or a sliver narrower than
// 1e-70): no plane, its edges are the point set.
struct DistanceFace {
  TrianglePoints v;
  std::array<Segment, 3> edges;  ///< edges[k] from v[k] to v[k + 1]
  Vec3 normal, unit = Vec3::Zero();
  bool flat;

  explicit DistanceFace(const TrianglePoints& t)
      : v(t),
        edges{Segment(t[0], t[1]), Segment(t[1], t[2]), Segment(t[2], t[0])},
        normal(accurate_cross(t[1] - t[0], t[2] - t[0])) {
    const double squared = normal.squaredNorm();
    flat = !(squared > kTinySquared);
    if (!flat) unit = normal / std::sqrt(squared);
  }

  // Signed distance of x above the plane when x's foot lies in the closed face. A foot on the boundary is an
  // edge's business: rounding either way there changes the distance only to second order.
  [[nodiscard]] std::optional<double> height_over(const Vec3& x) const {
    if (flat) return std::nullopt;
    for (int k = 0; k < 3; ++k)
      if (edges[k].d.cross(x - v[k]).dot(normal) < 0) return std::nullopt;
    return (x - v[0]).dot(unit);
  }
};

// |v|, also where the squares of its components underflow (a gap of 1e-300 between unit triangles).
double length(const Vec3& v) {
  const double squared = v.squaredNorm();
  if (squared >= 0x1p-1000) return std::sqrt(squared);
  const double largest = v.cwiseAbs().maxCoeff();
  return largest > 0 ? largest * (v / largest).norm() : 0.0;
}

// The point of the segment nearest x; a zero-length segment is its endpoint.
Vec3 nearest_on_segment(const Vec3& x, const Segment& e) {
  if (!(e.squared > 0)) return e.a;
  const double t = std::clamp((x - e.a).dot(e.d) / e.squared, 0.0, 1.0);
  return t < 1 ? Vec3(e.a + t * e.d) : e.b;
}

double distance_to_face(const DistanceFace& f, const Vec3& x) {
  double d = std::numeric_limits<double>::infinity();
  for (const Segment& e : f.edges) d = std::min(d, length(x - nearest_on_segment(x, e)));
  if (const auto height = f.height_over(x)) d = std::min(d, std::abs(*height));
  return d;
}

struct Pair {
  double distance = std::numeric_limits<double>::infinity();
  Vec3 on_p = Vec3::Zero(), on_q = Vec3::Zero();
};

void keep_nearer(Pair& best, const Vec3& on_p, const Vec3& on_q) {
  const Vec3 gap = on_p - on_q;
  if (gap.squaredNorm() >= best.distance * best.distance) return;  // most candidates: no square root
  const double d = length(gap);
  if (d < best.distance) best = {d, on_p, on_q};
}

// Segments [a0, a1] and [b0, b1] where the nearest points are interior to both: the common perpendicular of
// the lines. Its parameter s is ill-conditioned for nearly parallel edges (a plain cross product is no worse
// here), but sliding both points along the edges together barely changes their distance, and the two
// projections that follow remove the rest. Parallel or tiny edges have an endpoint among their nearest
// points: the vertex-edge candidates.
void edge_edge(Pair& best, const Segment& a, const Segment& b) {
  const Vec3 n = a.d.cross(b.d);
  const double squared = n.squaredNorm();
  if (!(squared > kTinySquared)) return;
  const double s = std::clamp((b.a - a.a).cross(b.d).dot(n) / squared, 0.0, 1.0);
  const Vec3 on_b = nearest_on_segment(a.a + s * a.d, b);
  keep_nearer(best, nearest_on_segment(on_b, a), on_b);
}

// The minimum over the features that can hold the nearest pair of disjoint triangles: vertex-edge (18),
// edge-edge interiors (9) and vertex-face interiors (6). Exact arithmetic would make it the distance.
Pair nearest_features(const DistanceFace& p, const DistanceFace& q) {
  Pair best;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      keep_nearer(best, p.v[i], nearest_on_segment(p.v[i], q.edges[j]));
      keep_nearer(best, nearest_on_segment(q.v[j], p.edges[i]), q.v[j]);
      edge_edge(best, p.edges[i], q.edges[j]);
    }
    if (const auto height = q.height_over(p.v[i]); height && std::abs(*height) < best.distance)
      best = {std::abs(*height), p.v[i], p.v[i] - *height * q.unit};
    if (const auto height = p.height_over(q.v[i]); height && std::abs(*height) < best.distance)
      best = {std::abs(*height), q.v[i] - *height * p.unit, q.v[i]};
  }
  return best;
}

// Where edge e meets the face's plane, when its ends are on opposite sides or one is on it.
std::optional<Vec3> plane_crossing(const DistanceFace& f, const Segment& e) {
  if (f.flat) return std::nullopt;
  const double da = (e.a - f.v[0]).dot(f.normal), db = (e.b - f.v[0]).dot(f.normal);
  if (da == db || (da > 0 && db > 0) || (da < 0 && db < 0)) return std::nullopt;
  return e.a + (da / (da - db)) * e.d;  // |da| <= |da - db|: the ratio is in [0, 1]
}

// A point of both triangles, known to intersect: where an edge of one crosses the other's plane (the ends of
// a transversal intersection), or the midpoint of the nearest feature pair (a vertex in the other triangle,
// coplanar edges crossing, touching features). Whichever is nearest to both triangles after rounding wins, so
// the fallback is the nearest feature pair itself.
Vec3 common_point(const DistanceFace& p, const DistanceFace& q, const Pair& nearest) {
  Vec3 best = Vec3::Zero();
  double residual = std::numeric_limits<double>::infinity();
  const auto consider = [&](const Vec3& x) {
    const double r = std::max(distance_to_face(p, x), distance_to_face(q, x));
    if (r < residual) {
      residual = r;
      best = x;
    }
  };
  consider((nearest.on_p + nearest.on_q) / 2);
  for (int k = 0; k < 3 && residual > 0; ++k) {
    if (const auto x = plane_crossing(q, p.edges[k])) consider(*x);
    if (const auto x = plane_crossing(p, q.edges[k])) consider(*x);
  }
  return best;
}

}  // namespace

TriangleDistance triangle_distance(const TrianglePoints& p, const TrianglePoints& q) {
  local_frame::require_finite(p, "triangle_distance", "P");
  local_frame::require_finite(q, "triangle_distance", "Q");
  const bool touching = triangles_intersect(p, q);
  Frame frame;
  const auto local = frame.enter(p, q);
  const DistanceFace fp(local[0]), fq(local[1]);
  const Pair nearest = nearest_features(fp, fq);
  if (touching) {
    const Vec3 x = frame.world(common_point(fp, fq, nearest));
    return {0.0, x, x};
  }
  // Disjoint triangles are never at distance 0, even where the gap is below what doubles resolve.
  const double distance =
      std::max(frame.world_length(nearest.distance), std::numeric_limits<double>::denorm_min());
  return {distance, frame.world(nearest.on_p), frame.world(nearest.on_q)};
}

}  // namespace bvhlab
