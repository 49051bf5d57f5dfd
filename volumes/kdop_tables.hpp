// What a k-DOP derives once per direction set (volumes/kdop.hpp): the unit normals, the prototype polytope's
// vertices with the plane triples that span their normal cones (Zachmann's re-alignment, described there),
// the search of the extremal vertex in a direction, and the volume of a box clipped by a DOP's planes.
#pragma once

#include "geometry.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#if defined(__SSE2__) && !defined(BVHLAB_KDOP_SCALAR)
#define BVHLAB_KDOP_SSE2 1
#include <emmintrin.h>
#else
#define BVHLAB_KDOP_SSE2 0
#endif

namespace bvhlab {

namespace dop_detail {

using RawDirection = std::array<int, 3>;

/// Plane normals of a DOP: axis m in [0, k/2) is `directions[m]` normalised; plane m + k/2 is its negation.
/// The first three axes must be x, y, z (bounding box, magnitude bound for the slack).
template <std::size_t Axes>
struct DirectionSet {
  std::array<RawDirection, Axes> raw;
};

/// Everything derived once per direction set: unit normals and the prototype polytope's vertices with the
/// plane triples that span their normal cones.
template <std::size_t Axes>
struct Tables {
  static constexpr std::size_t kPlanes = 2 * Axes;
  struct Triple {
    std::array<std::uint8_t, 3> planes;
    Mat3 inverse_transpose;  // M^-T: lambda = M^-T v
  };
  struct Vertex {
    Vec3 position;
    std::vector<Triple> triples;
  };
  std::array<Vec3, Axes> axes;        // unit directions
  std::array<Vec3, kPlanes> normals;  // axes, then their negations
  std::vector<Vertex> vertices;       // prototype: n_m . x <= 1 for every m
  /// The first half of the vertices' x, y and z side by side (vertex i + half is vertex i's antipode), padded
  /// to an even count with a copy of the last: the search of the extremal vertex takes two at a time.
  std::vector<double> xs, ys, zs;
  std::size_t half = 0;
  double max_lambda_sum = 0;  // largest sum of lambda over the chosen triples (= prototype radius)
  /// The walk's edges (find_edges), where every vertex is simple (three planes meet there, as on the 24-DOP):
  /// across[x][k] is the vertex that shares vertex x's planes but its k-th. Empty where some vertex is not.
  std::vector<std::array<std::uint8_t, 3>> across;
  /// Where the walk starts for a direction in each bin (direction_bin): the vertex extremal at the bin's
  /// centroid. From there it takes 0.09 steps on average for the 24-DOP (1.3 from an octant's corner).
  std::array<std::uint8_t, 64> bin_start{};

  /// Plane m's opposite: the same axis, the other side. The prototype is symmetric, so the triple realign
  /// finds for -v is the opposite planes of the one for v, with the same coefficients.
  static constexpr std::size_t opposite(std::size_t m) { return m < Axes ? m + Axes : m - Axes; }

  /// Derives the tables of `set` (out of line: the shipped sets are compiled once, below).
  explicit Tables(const DirectionSet<Axes>& set);

  /// A vertex of the prototype that is extremal in direction v (largest v . x): of the first pair (i, i +
  /// half) with the largest |v . x_i|, the one on v's side. Per axis and query, in make_context: a scan of
  /// every vertex there was a fifth of a 24-DOP query on jeep1 (about 100 BV tests a query).
  [[nodiscard]] std::size_t extremal_vertex(const Vec3& v) const {
#if BVHLAB_KDOP_SSE2
    const __m128d vx = _mm_set1_pd(v[0]), vy = _mm_set1_pd(v[1]), vz = _mm_set1_pd(v[2]);
    const __m128d sign = _mm_set1_pd(-0.0);
    __m128d best = _mm_set1_pd(-1), best_index = _mm_setzero_pd(), index = _mm_set_pd(1, 0);
    for (std::size_t i = 0; i < xs.size(); i += 2) {
      const __m128d value = _mm_andnot_pd(  // |v . x|, the sums in the scalar reference's order
          sign,
          _mm_add_pd(_mm_add_pd(_mm_mul_pd(vx, _mm_loadu_pd(&xs[i])), _mm_mul_pd(vy, _mm_loadu_pd(&ys[i]))),
                     _mm_mul_pd(vz, _mm_loadu_pd(&zs[i]))));
      const __m128d greater = _mm_cmpgt_pd(value, best);  // strictly: each lane keeps its first maximum
      best = _mm_or_pd(_mm_and_pd(greater, value), _mm_andnot_pd(greater, best));
      best_index = _mm_or_pd(_mm_and_pd(greater, index), _mm_andnot_pd(greater, best_index));
      index = _mm_add_pd(index, _mm_set1_pd(2));
    }
    const double best_even = _mm_cvtsd_f64(best), best_odd = _mm_cvtsd_f64(_mm_unpackhi_pd(best, best));
    const double index_even = _mm_cvtsd_f64(best_index);
    const double index_odd = _mm_cvtsd_f64(_mm_unpackhi_pd(best_index, best_index));
    const bool odd = best_odd > best_even || (best_odd == best_even && index_odd < index_even);
    return on_side_of(v, static_cast<std::size_t>(odd ? index_odd : index_even));
#else
    return extremal_vertex_scalar(v);
#endif
  }
  /// The reference: one pair at a time, the same products and sums (tests/volumes/test_dop.cpp).
  [[nodiscard]] std::size_t extremal_vertex_scalar(const Vec3& v) const {
    std::size_t best_index = 0;
    double best = -1;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const double value = std::abs(along(v, i));
      if (value > best) {
        best = value;
        best_index = i;
      }
    }
    return on_side_of(v, best_index);
  }

  /// The triple at the prototype's extremal vertex in direction v, and its (non-negative) coefficients.
  void realign(const Vec3& v, std::array<std::uint8_t, 3>& planes,
               std::array<double, 3>& coefficients) const {
    if (walk(v, planes, coefficients)) return;
    realign_by_scan(v, planes, coefficients);
  }
  /// realign by extremal_vertex's scan of every vertex: the reference the walk must agree with.
  void realign_by_scan(const Vec3& v, std::array<std::uint8_t, 3>& planes,
                       std::array<double, 3>& coefficients) const {
    const Vertex* best = &vertices[extremal_vertex(v)];
    double best_min = -std::numeric_limits<double>::infinity();
    for (const Triple& t : best->triples) {
      const Vec3 lambda = t.inverse_transpose * v;
      if (lambda.minCoeff() > best_min) {
        best_min = lambda.minCoeff();
        planes = t.planes;
        // Rounding may leave a coefficient a hair below zero when v lies on a cone boundary; the bound
        // error that causes is a few ulps of the offsets, inside the overlap slack.
        coefficients = {lambda[0], lambda[1], lambda[2]};
      }
    }
  }

  /// realign's shortcut, the simplex method on the prototype: from bin_start of v's bin, across the plane
  /// of the most negative coefficient, until every coefficient is at least kCertain |v|_1. Then v lies so
  /// deep inside that vertex's normal cone that every other vertex is farther from v's maximum than
  /// extremal_vertex's rounding by orders of magnitude (find_edges checks the prototype's share of that
  /// margin), so the scan finds the same vertex and realign_by_scan the same bits. False where the prototype
  /// has vertices that are not simple, or v lies near a cone's boundary: the caller scans.
  bool walk(const Vec3& v, std::array<std::uint8_t, 3>& planes, std::array<double, 3>& coefficients) const {
    if (across.empty()) return false;
    const double certain = kCertain * (std::abs(v[0]) + std::abs(v[1]) + std::abs(v[2]));
    std::size_t at = bin_start[direction_bin(v)];
    for (std::size_t step = 0; step < vertices.size(); ++step) {
      const Triple& t = vertices[at].triples[0];
      const Vec3 lambda = t.inverse_transpose * v;
      Eigen::Index k;
      const double smallest = lambda.minCoeff(&k);
      if (smallest >= certain) {
        planes = t.planes;
        coefficients = {lambda[0], lambda[1], lambda[2]};
        return true;
      }
      if (!(smallest < 0)) return false;  // on or near a boundary (or NaN): the scan settles ties
      at = across[at][k];
    }
    return false;
  }

 private:
  static constexpr double kTolerance = 1e-9;  // of a point on a plane of the prototype (offsets 1)
  /// The walk's margin: coefficients of a unit direction at least this far from 0. Rounding moves
  /// extremal_vertex's numbers by about 1e-15; the margin puts the nearest rival 1e-12 or more below.
  static constexpr double kCertain = 1e-9;

  /// The 3x3 matrix of planes i, j, l's normals in m; false where they are (nearly) dependent.
  bool independent(std::size_t i, std::size_t j, std::size_t l, Mat3& m) const;
  /// The prototype's vertices: every independent triple's common point that satisfies all planes.
  void find_vertices();
  /// Every independent triple of the planes through vertex v, with the matrix that gives its coefficients.
  void find_triples(Vertex& v) const;
  /// The largest v . x over the vertices is the largest |v . x| over one of each antipodal pair (the
  /// prototype is symmetric about the origin): orders the vertices so that vertex i + half is vertex i's
  /// antipode, and keeps the first half's coordinates side by side. Their antipodes agree to about 1e-16
  /// (each is solved from its own three planes), far inside the tolerance the triples are chosen with.
  void pair_antipodes();

  /// The walk's edges and bin starts, where every vertex is simple. A vertex x of planes T is v's unique
  /// maximum by at least min(lambda) * sum over T of (1 - n_k . y) against any other vertex y; the
  /// prototype's smallest such sum, times kCertain, must dwarf the scan's rounding, or there is no walk.
  void find_edges();
  /// The walk's 64 bins: the signs of v's components, then the order of their magnitudes.
  static std::size_t direction_bin(const Vec3& v) {
    const double a = std::abs(v[0]), b = std::abs(v[1]), c = std::abs(v[2]);
    const std::size_t signs = (v[0] < 0) | (v[1] < 0) << 1 | (v[2] < 0) << 2;
    return signs * 8 + ((a < b) | (a < c) << 1 | (b < c) << 2);
  }

  [[nodiscard]] double along(const Vec3& v, std::size_t i) const {
    return (v[0] * xs[i] + v[1] * ys[i]) + v[2] * zs[i];
  }
  /// Vertex i of the first half, or its antipode where v points away from it.
  [[nodiscard]] std::size_t on_side_of(const Vec3& v, std::size_t i) const {
    return along(v, i) < 0 ? i + half : i;
  }
};

// The tables' derivation (the constructor and its steps), run once per direction set.

template <std::size_t Axes>
Tables<Axes>::Tables(const DirectionSet<Axes>& set) {
  for (std::size_t a = 0; a < Axes; ++a) {
    axes[a] = Vec3(set.raw[a][0], set.raw[a][1], set.raw[a][2]).normalized();
    normals[a] = axes[a];
    normals[a + Axes] = -axes[a];
  }
  find_vertices();
  for (Vertex& v : vertices) find_triples(v);
  // The prototype's circumradius bounds sum(lambda) for unit directions: sum(lambda) is the support of the
  // prototype in direction v, attained at the chosen vertex.
  for (const Vertex& v : vertices) max_lambda_sum = std::max(max_lambda_sum, v.position.norm());
  pair_antipodes();
  find_edges();
}

template <std::size_t Axes>
bool Tables<Axes>::independent(std::size_t i, std::size_t j, std::size_t l, Mat3& m) const {
  m.row(0) = normals[i];
  m.row(1) = normals[j];
  m.row(2) = normals[l];
  return std::abs(m.determinant()) > 1e-6;
}

template <std::size_t Axes>
void Tables<Axes>::find_vertices() {
  for (std::size_t i = 0; i < kPlanes; ++i)
    for (std::size_t j = i + 1; j < kPlanes; ++j)
      for (std::size_t l = j + 1; l < kPlanes; ++l) {
        Mat3 m;
        if (!independent(i, j, l, m)) continue;
        const Vec3 x = m.inverse() * Vec3::Ones();
        bool feasible = true;
        for (const Vec3& n : normals) feasible = feasible && n.dot(x) <= 1 + kTolerance;
        if (!feasible) continue;
        const bool known = std::any_of(vertices.begin(), vertices.end(),
                                       [&](const Vertex& v) { return (v.position - x).norm() < 1e-7; });
        if (!known) vertices.push_back({x, {}});
      }
}

template <std::size_t Axes>
void Tables<Axes>::find_triples(Vertex& v) const {
  std::vector<std::uint8_t> active;
  for (std::size_t m = 0; m < kPlanes; ++m)
    if (normals[m].dot(v.position) >= 1 - kTolerance) active.push_back(static_cast<std::uint8_t>(m));
  for (std::size_t i = 0; i < active.size(); ++i)
    for (std::size_t j = i + 1; j < active.size(); ++j)
      for (std::size_t l = j + 1; l < active.size(); ++l) {
        Mat3 m;
        if (!independent(active[i], active[j], active[l], m)) continue;
        v.triples.push_back({{active[i], active[j], active[l]}, m.inverse().transpose()});
      }
}

template <std::size_t Axes>
void Tables<Axes>::pair_antipodes() {
  std::vector<Vertex> first, second;
  std::vector<bool> paired(vertices.size(), false);
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    if (paired[i]) continue;
    std::size_t j = i + 1;
    while (j < vertices.size() && (paired[j] || (vertices[i].position + vertices[j].position).norm() > 1e-7))
      ++j;
    if (j == vertices.size()) throw std::logic_error("k-DOP prototype: a vertex without its antipode");
    paired[i] = paired[j] = true;
    first.push_back(vertices[i]);
    second.push_back(vertices[j]);
  }
  half = first.size();
  vertices = std::move(first);
  vertices.insert(vertices.end(), second.begin(), second.end());
  for (std::size_t i = 0; i < half + half % 2; ++i) {
    const Vec3& x = vertices[std::min(i, half - 1)].position;
    xs.push_back(x[0]);
    ys.push_back(x[1]);
    zs.push_back(x[2]);
  }
}

template <std::size_t Axes>
void Tables<Axes>::find_edges() {
  const auto simple = [](const Vertex& v) { return v.triples.size() == 1; };
  if (vertices.size() > 255 || !std::all_of(vertices.begin(), vertices.end(), simple)) return;
  std::vector<std::array<std::uint8_t, 3>> edges(vertices.size());
  double smallest_sum = std::numeric_limits<double>::infinity();
  for (std::size_t x = 0; x < vertices.size(); ++x) {
    const auto& own = vertices[x].triples[0].planes;
    for (int k = 0; k < 3; ++k) {
      int found = 0;
      for (std::size_t y = 0; y < vertices.size(); ++y) {
        const auto& other = vertices[y].triples[0].planes;
        const auto holds = [&](std::uint8_t p) {
          return std::find(other.begin(), other.end(), p) != other.end();
        };
        if (y == x || !holds(own[(k + 1) % 3]) || !holds(own[(k + 2) % 3])) continue;
        edges[x][k] = static_cast<std::uint8_t>(y);
        ++found;
      }
      if (found != 1) return;
    }
    for (std::size_t y = 0; y < vertices.size(); ++y) {
      if (y == x) continue;
      double sum = 0;
      for (const std::uint8_t p : own) sum += 1 - normals[p].dot(vertices[y].position);
      smallest_sum = std::min(smallest_sum, sum);
    }
  }
  if (!(kCertain * smallest_sum > 1e-12)) return;
  // A bin is a triangle of the sphere with corners x, (x + y) / sqrt 2 and (x + y + z) / sqrt 3, the
  // components in the bin's order of magnitude and with its signs: its centroid's magnitudes by rank.
  const double by_rank[3] = {1 + std::sqrt(0.5) + std::sqrt(1 / 3.0), std::sqrt(0.5) + std::sqrt(1 / 3.0),
                             std::sqrt(1 / 3.0)};
  for (int signs = 0; signs < 8; ++signs)
    for (int order = 0; order < 8; ++order) {
      // |v0| < |v1|, |v0| < |v2|, |v1| < |v2|, as direction_bin packs them
      const bool a_b = order & 1, a_c = order & 2, b_c = order & 4;
      const int rank[3] = {a_b + a_c, !a_b + b_c, !a_c + !b_c};         // how many components are larger
      if ((1 << rank[0] | 1 << rank[1] | 1 << rank[2]) != 7) continue;  // no real direction has this order
      Vec3 centroid;
      for (int i = 0; i < 3; ++i) centroid[i] = (signs >> i & 1 ? -1 : 1) * by_rank[rank[i]];
      bin_start[signs * 8 + order] = static_cast<std::uint8_t>(extremal_vertex_scalar(centroid));
    }
  across = std::move(edges);
}

// The shipped sets' derivations are compiled once, in volumes/kdop_tables.cpp, not in every file that uses
// a k-DOP; another set derives its own where it is used.
extern template struct Tables<3>;   // 6-DOP
extern template struct Tables<7>;   // 14-DOP
extern template struct Tables<9>;   // 18-DOP
extern template struct Tables<12>;  // 24-DOP
extern template struct Tables<13>;  // 26-DOP

/// The convex polytope clipped_box_volume cuts down: its faces as point lists, in two buffers that swap at
/// every cut. Fixed sizes, no allocation: a face gains at most one vertex per cut, so it never has more than
/// 4 + kPlanes vertices, and there are at most kPlanes faces.
template <std::size_t Axes>
class BoxClip {
 public:
  static constexpr std::size_t kPlanes = 2 * Axes;

  /// The box [lo, hi]: for each axis a and side, the face's four corners in cyclic order, on plane a (the
  /// upper side) or a + Axes (the lower).
  void start(const Vec3& lo, const Vec3& hi) {
    current_ = 0;
    point_count_ = face_count_ = 0;
    for (std::size_t a = 0; a < 3; ++a)
      for (int side = 0; side < 2; ++side) {
        const std::size_t b = (a + 1) % 3, c = (a + 2) % 3;
        const double uv[4][2] = {{lo[b], lo[c]}, {hi[b], lo[c]}, {hi[b], hi[c]}, {lo[b], hi[c]}};
        faces_[0][face_count_++] = {side == 0 ? a : a + Axes, point_count_, 4};
        for (const auto& corner : uv) {
          Vec3& x = points_[0][point_count_++];
          x[a] = side == 0 ? hi[a] : lo[a];
          x[b] = corner[0];
          x[c] = corner[1];
        }
      }
  }

  /// Keeps the part with n . x <= offset (plane `plane`), points within `tol` counting as on it. Returns
  /// false when nothing is left.
  bool cut(const Vec3& n, double offset, std::size_t plane, double tol) {
    double farthest = -std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < point_count_; ++k) {
      distance_[k] = n.dot(points_[current_][k]) - offset;
      farthest = std::max(farthest, distance_[k]);
    }
    if (farthest <= tol) return true;  // the plane does not cut
    clip_faces(tol);
    if (cap_count_ >= 3 && next_count_ + cap_count_ <= kMaxPoints && next_face_count_ < kPlanes)
      close_cut(n, plane);
    current_ = 1 - current_;
    point_count_ = next_count_;
    face_count_ = next_face_count_;
    return face_count_ != 0;
  }

  /// sum over the faces of offset_m * area_m / 3 (divergence theorem).
  double volume(const std::array<Vec3, kPlanes>& normals, const std::array<double, kPlanes>& offsets) const {
    double volume = 0;
    for (std::size_t f = 0; f < face_count_; ++f) {
      const Face& face = faces_[current_][f];
      const Vec3* p = points_[current_].data() + face.begin;
      Vec3 twice_area = Vec3::Zero();
      for (std::size_t k = 1; k + 1 < face.count; ++k) twice_area += (p[k] - p[0]).cross(p[k + 1] - p[0]);
      volume += offsets[face.plane] * std::abs(normals[face.plane].dot(twice_area)) / 6;
    }
    return volume;
  }

 private:
  static constexpr std::size_t kMaxPoints = kPlanes * (kPlanes + 4);
  struct Face {
    std::size_t plane, begin, count;
  };

  /// Each face clipped into the other buffer (faces left with fewer than 3 points dropped); the points on
  /// the cut collected in cap_.
  void clip_faces(double tol) {
    const Vec3* points = points_[current_].data();
    Vec3* next = points_[1 - current_].data();
    next_count_ = next_face_count_ = cap_count_ = 0;
    for (std::size_t f = 0; f < face_count_; ++f) {
      const Face& face = faces_[current_][f];
      const std::size_t begin = next_count_;
      for (std::size_t k = 0; k < face.count; ++k) {
        const std::size_t i = face.begin + k, j = face.begin + (k + 1 == face.count ? 0 : k + 1);
        const double dp = distance_[i], dq = distance_[j];
        if (dp <= tol) {
          next[next_count_++] = points[i];
          if (dp >= -tol) cap_[cap_count_++] = points[i];
        }
        if ((dp < -tol && dq > tol) || (dp > tol && dq < -tol)) {
          const Vec3 x = points[i] + (points[j] - points[i]) * (dp / (dp - dq));
          next[next_count_++] = x;
          cap_[cap_count_++] = x;
        }
      }
      if (next_count_ - begin >= 3)
        faces_[1 - current_][next_face_count_++] = {face.plane, begin, next_count_ - begin};
      else
        next_count_ = begin;
    }
  }

  /// The cut face: its points lie on a convex polygon; ordered by (pseudo-)angle about their mean.
  void close_cut(const Vec3& n, std::size_t plane) {
    const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
    Vec3 mean = Vec3::Zero();
    for (std::size_t k = 0; k < cap_count_; ++k) mean += cap_[k];
    mean /= double(cap_count_);
    for (std::size_t k = 0; k < cap_count_; ++k) {
      const double u = e1.dot(cap_[k] - mean), v = e2.dot(cap_[k] - mean);
      // Monotone in the angle, without atan2: position on the unit diamond's perimeter, in [0, 4).
      const double r = std::abs(u) + std::abs(v);
      const double p = r > 0 ? v / r : 0;
      order_[k] = {u >= 0 ? (v >= 0 ? p : 4 + p) : 2 - p, k};
    }
    std::sort(order_.begin(), order_.begin() + cap_count_);
    faces_[1 - current_][next_face_count_++] = {plane, next_count_, cap_count_};
    Vec3* next = points_[1 - current_].data();
    for (std::size_t k = 0; k < cap_count_; ++k) next[next_count_++] = cap_[order_[k].second];
  }

  std::array<Vec3, kMaxPoints> points_[2], cap_;
  std::array<double, kMaxPoints> distance_;
  std::array<std::pair<double, std::size_t>, kMaxPoints> order_;
  std::array<Face, kPlanes> faces_[2];
  int current_ = 0;
  std::size_t point_count_ = 0, face_count_ = 0, next_count_ = 0, next_face_count_ = 0, cap_count_ = 0;
};

/// Lebesgue measure of {x : n_m . x <= d_m for all m}, where planes a and a + Axes (a < 3) are the
/// bounding box's. Clips the box by the other planes one at a time (each face polygon clipped, the cut
/// closed by a new face), then sums d_m * area(face m) / 3. Bvh computes it for every node at build time,
/// so it works in a per-thread BoxClip: no allocation.
template <std::size_t Axes>
double clipped_box_volume(const std::array<Vec3, 2 * Axes>& normals,
                          const std::array<double, 2 * Axes>& world_offsets, const Box& world_box) {
  constexpr std::size_t kPlanes = 2 * Axes;
  thread_local BoxClip<Axes> clip;
  // Work about the box's centre: sum d_m * area_m cancels badly for a small polytope far from the origin.
  const Vec3 center = world_box.center();
  std::array<double, kPlanes> offsets;
  for (std::size_t m = 0; m < kPlanes; ++m) offsets[m] = world_offsets[m] - normals[m].dot(center);
  const double tol = 1e-12 * (world_box.extent().maxCoeff() + world_box.min.cwiseAbs().maxCoeff() +
                              world_box.max.cwiseAbs().maxCoeff());
  clip.start(world_box.min - center, world_box.max - center);
  for (std::size_t m = 3; m < kPlanes; ++m) {
    if (m >= Axes && m < Axes + 3) continue;  // the box's own planes
    if (!clip.cut(normals[m], offsets[m], m, tol)) return 0;
  }
  return clip.volume(normals, offsets);
}

inline bool all_finite(std::span<const Vec3> points) {
  return std::all_of(points.begin(), points.end(), [](const Vec3& p) { return p.allFinite(); });
}

}  // namespace dop_detail

}  // namespace bvhlab
