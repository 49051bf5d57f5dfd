// k-DOPs (discrete orientation polytopes): the intersection of k/2 slabs along fixed directions.
// Dop<6>, Dop<14>, Dop<18>, Dop<26> use the classic direction sets; volumes/dop24.hpp adds Zachmann's 24-DOP.
//
// Overlap under a relative rotation (Zachmann's re-alignment). B's DOP is not a DOP in A's frame, so for each
// of A's k plane normals u the support of B in direction u is bounded from above instead of recomputed:
// with v = R^T u (u in B's frame) and any three of B's planes i, j, l whose normals n_i, n_j, n_l are
// independent and span a cone containing v, i.e. v = lambda_i n_i + lambda_j n_j + lambda_l n_l with
// lambda >= 0, every point x of B satisfies
//     v . x = sum lambda_m (n_m . x) <= sum lambda_m d_m,
// because n_m . x <= d_m on B and lambda_m >= 0. (This is LP duality: the bound is the maximum of v over the
// cone of those three half-spaces, attained at their common vertex.) It holds for *any* such triple, so it is
// always conservative; it is tight when the triple is the one meeting at B's extremal vertex in direction v.
// B's actual vertex structure varies from node to node, so the triple is the one meeting at the extremal
// vertex of the *prototype* DOP (all offsets equal), found once per query in make_context. Vertices where
// more than three prototype planes meet (corners of the 14- and 26-DOP) are split into all independent
// triples of their planes; by the conic Caratheodory theorem some triple's cone contains v, and the one with
// the largest smallest lambda is taken. lambda = M^-T v for the 3x3 matrix M of the triple's normals, so the
// stored coefficients are c = (u^T R) M^-1, three multiply-adds per direction at test time, plus u . t for
// the translation. Only A's k/2 axes are tested (both ends of each); that is a subset of the separating
// axes, so it is conservative too.
//
// Storage: the k offsets d_m = max over the volume of n_m . x as floats rounded upwards (unit normals; the
// lower end of axis a is stored negated as d_{a + k/2}). Arithmetic is in double with a rounding slack as in
// aabb.hpp, scaled by the magnitudes involved.
#pragma once

#include "concept.hpp"
#include "kdop_tables.hpp"
#include "storage.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace bvhlab {

/// A DOP over the direction set `Set` (a struct with `static constexpr DirectionSet<n> set`, `name` and
/// `split_along_directions`). Plain data: k floats.
template <class Set>
struct KDop {
  static constexpr std::size_t kAxes = Set::set.raw.size();
  static constexpr std::size_t kPlanes = 2 * kAxes;
  static_assert(Set::set.raw[0] == dop_detail::RawDirection{1, 0, 0} &&
                    Set::set.raw[1] == dop_detail::RawDirection{0, 1, 0} &&
                    Set::set.raw[2] == dop_detail::RawDirection{0, 0, 1},
                "a DOP's first three axes must be x, y, z");
  static_assert(kPlanes <= 255, "plane indices are stored as bytes");

  /// offsets[m] >= n_m . x for every point x of the volume; default: empty (hi < lo on every axis).
  std::array<float, kPlanes> offsets = filled(-1.0f);

  /// Two of A's axes side by side, lane l holding axis 2j + l of pair j: the layout overlap() reads two axes
  /// at a time from. With an odd number of axes the last pair's lane 1 is unused: overlap() tests that
  /// axis alone.
  struct AxisPair {
    alignas(16) std::array<std::array<double, 2>, 3> coefficients;  // [k][lane]
    alignas(16) std::array<double, 2> shift;                        // n_a . t
    std::array<std::array<std::uint8_t, 2>, 3> upper;               // B's planes bounding n_a, [k][lane]
    std::array<std::array<std::uint8_t, 2>, 3> lower;               // the same for -n_a
  };

  struct PairContext {
    // Per plane m of A (direction n_m, on axis a = m mod k/2): B's support in n_m is at most
    //   sum_k coefficient(a, k) * b.offsets[plane(m, k)] + shift(m),
    // with shift(m) = +n_a . t for m = a < k/2 and -n_a . t for m = a + k/2. A plane and its opposite share
    // their coefficients (Tables::opposite), so they are kept once per axis.
    std::array<AxisPair, (kAxes + 1) / 2> pairs;
    double slack_per_a_scale;  // rounding slack per unit of A's coordinate magnitude
    double slack_per_b_scale;
    double slack_translation;

    [[nodiscard]] double coefficient(std::size_t axis, int k) const {
      return pairs[axis / 2].coefficients[k][axis % 2];
    }
    [[nodiscard]] std::uint8_t plane(std::size_t m, int k) const {
      const std::size_t axis = m % kAxes;
      const AxisPair& p = pairs[axis / 2];
      return m < kAxes ? p.upper[k][axis % 2] : p.lower[k][axis % 2];
    }
    [[nodiscard]] double shift(std::size_t m) const {
      const std::size_t axis = m % kAxes;
      const double s = pairs[axis / 2].shift[axis % 2];
      return m < kAxes ? s : -s;
    }
  };

  static constexpr std::string_view name() { return Set::name; }

  static const dop_detail::Tables<kAxes>& tables() {
    static const dop_detail::Tables<kAxes> instance(Set::set);
    return instance;
  }

  /// The unit axis directions (the builder's split directions when Set asks for it).
  static std::span<const Vec3> split_directions() requires(Set::split_along_directions) {
    return std::span<const Vec3>(tables().axes);
  }

  static KDop fit(std::span<const Vec3> points) {
    if (!dop_detail::all_finite(points))
      throw std::invalid_argument(std::string(name()) + "::fit: a point has a NaN or infinite coordinate");
    if (points.empty()) return {};
    const auto& axes = tables().axes;
    std::array<double, kAxes> hi, lo;
    hi.fill(-std::numeric_limits<double>::infinity());
    lo.fill(std::numeric_limits<double>::infinity());
    for (const Vec3& p : points)
      for (std::size_t a = 0; a < kAxes; ++a) {
        const double s = project(axes[a], p);
        hi[a] = std::max(hi[a], s);
        lo[a] = std::min(lo[a], s);
      }
    KDop out;
    for (std::size_t a = 0; a < kAxes; ++a) {
      out.offsets[a] = float_up(hi[a]);
      out.offsets[a + kAxes] = float_up(-lo[a]);
    }
    return out;
  }

  static KDop merge(const KDop& a, const KDop& b) {
    if (a.empty()) return b;
    if (b.empty()) return a;
    KDop out;
    for (std::size_t m = 0; m < kPlanes; ++m) out.offsets[m] = std::max(a.offsets[m], b.offsets[m]);
    return out;
  }

  static PairContext make_context(const RigidTransform& pose) {
    const auto& t = tables();
    PairContext c{};
    double max_coefficient_sum = 0;
    // Plane m + k/2 is plane m's opposite: its triple and coefficients follow from m's (Tables::opposite),
    // one vertex search per axis instead of per plane.
    for (std::size_t m = 0; m < kAxes; ++m) {
      const Vec3 v = pose.rotation.transpose() * t.normals[m];
      std::array<std::uint8_t, 3> planes{};
      std::array<double, 3> coefficients{};
      t.realign(v, planes, coefficients);
      const double shift = t.axes[m].dot(pose.translation);
      AxisPair& p = c.pairs[m / 2];
      const std::size_t lane = m % 2;
      for (int k = 0; k < 3; ++k) {
        p.coefficients[k][lane] = coefficients[k];
        p.upper[k][lane] = planes[k];
        p.lower[k][lane] = static_cast<std::uint8_t>(t.opposite(planes[k]));
      }
      p.shift[lane] = shift;
      max_coefficient_sum =
          std::max(max_coefficient_sum,
                   std::abs(coefficients[0]) + std::abs(coefficients[1]) + std::abs(coefficients[2]));
    }
    // Offsets of a fitted or merged DOP are at most sqrt(3) times its largest x/y/z offset in magnitude
    // (each is a support value of points inside that box); errors of the few products and sums below, and
    // of c itself (from R and M^-1), stay far inside 512 ulps of those magnitudes.
    constexpr double kUlps = 512 * std::numeric_limits<double>::epsilon();
    c.slack_per_a_scale = kUlps * std::numbers::sqrt3 * 2;
    c.slack_per_b_scale = kUlps * std::numbers::sqrt3 * (max_coefficient_sum + 1);
    c.slack_translation = kUlps * pose.translation.norm();
    return c;
  }

  /// Two axes at a time in the vector unit where there is one (SSE2, every x86-64), else overlap_scalar.
  /// The same numbers compared in the same order, so both answer alike (tests/volumes/test_dop.cpp).
  static bool overlap(const KDop& a, const KDop& b, const PairContext& c) {
#if BVHLAB_KDOP_SSE2
    for (std::size_t j = 0; j < kAxes / 2; ++j) {
      const __m128d o = pair_overlap(a, b, c.pairs[j], j);
      if (_mm_movemask_pd(_mm_cmplt_pd(o, _mm_setzero_pd())) != 0 && separated(a, b, c, smaller_lane(o)))
        return false;
    }
    if constexpr (kAxes % 2 == 1) {
      const double o = axis_overlap(a, b, c, kAxes - 1);
      if (o < 0 && separated(a, b, c, o)) return false;
    }
    return true;
#else
    return overlap_scalar(a, b, c);
#endif
  }

  /// The reference test, one axis at a time. Stops at the first separating axis, and works out the slack
  /// only for an axis whose intervals are apart: pairs that overlap, which test every axis, never need it.
  static bool overlap_scalar(const KDop& a, const KDop& b, const PairContext& c) {
    for (std::size_t m = 0; m < kAxes; ++m) {
      const double o = axis_overlap(a, b, c, m);
      if (o < 0 && separated(a, b, c, o)) return false;
    }
    return true;
  }

  /// DistanceVolume: the widest gap between A's interval and B's (conservative) interval on A's unit axes,
  /// less overlap()'s slack. Projection onto a unit axis does not increase distances, so a gap there is a
  /// lower bound on the distance. 0 exactly where overlap() is true (the same two numbers compared).
  /// The largest gap over the axes, or, where larger, the Euclidean length of the gaps on the three
  /// coordinate axes (orthogonal, so they bound the distance together): unlike a single gap, which stays
  /// short by the cosine to the nearest axis at every depth, it closes in on the distance as the DOPs shrink.
  static double distance_lower_bound(const KDop& a, const KDop& b, const PairContext& c) {
    const double s = slack(a, b, c);
    double largest = 0, squared = 0;
    for (std::size_t m = 0; m < kAxes; ++m) {
      const double gap = std::max(0.0, -axis_overlap(a, b, c, m) - s);
      largest = std::max(largest, gap);
      if (m < 3) squared += gap * gap;
    }
    return std::max(largest, std::sqrt(squared) * (1 - 4 * std::numeric_limits<double>::epsilon()));
  }

  [[nodiscard]] bool empty() const {
    return offsets[0] + offsets[kAxes] < 0;
  }

  /// For loaders of raw node bytes: a stored node has finite offsets and no empty slab.
  [[nodiscard]] bool valid() const {
    for (std::size_t a = 0; a < kAxes; ++a)
      if (!(std::isfinite(offsets[a]) && std::isfinite(offsets[a + kAxes]) &&
            double(offsets[a]) + double(offsets[a + kAxes]) >= 0))
        return false;
    return true;
  }

  [[nodiscard]] Scalar volume() const {
    if (empty()) return 0;
    std::array<double, kPlanes> d;
    for (std::size_t m = 0; m < kPlanes; ++m) d[m] = offsets[m];
    const Box box = bounding_box();
    // Clamped: a flat DOP's faces cancel to round-off, and a DOP is inside its bounding box.
    return std::clamp(dop_detail::clipped_box_volume<kAxes>(tables().normals, d, box), 0.0, box.volume());
  }

  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    return {Vec3(-offsets[kAxes], -offsets[kAxes + 1], -offsets[kAxes + 2]),
            Vec3(offsets[0], offsets[1], offsets[2])};
  }

  [[nodiscard]] bool contains(const Vec3& p) const {
    if (empty()) return false;
    const auto& axes = tables().axes;
    for (std::size_t a = 0; a < kAxes; ++a) {
      const double s = project(axes[a], p);
      if (s > offsets[a] || -s > offsets[a + kAxes]) return false;
    }
    return true;
  }

 private:
  // The signed overlap on A's axis m (axes 0 to 2 are the coordinate axes).
  [[gnu::always_inline]] static double axis_overlap(const KDop& a, const KDop& b, const PairContext& c,
                                                    std::size_t m) {
    const AxisPair& p = c.pairs[m / 2];
    const std::size_t l = m % 2;
    const float* d = b.offsets.data();
    const double b_upper = p.coefficients[0][l] * double(d[p.upper[0][l]]) +
                           p.coefficients[1][l] * double(d[p.upper[1][l]]) +
                           p.coefficients[2][l] * double(d[p.upper[2][l]]) + p.shift[l];
    const double b_neg_lower = p.coefficients[0][l] * double(d[p.lower[0][l]]) +
                               p.coefficients[1][l] * double(d[p.lower[1][l]]) +
                               p.coefficients[2][l] * double(d[p.lower[2][l]]) - p.shift[l];
    // B's interval [-b_neg_lower, b_upper] against A's [-a.offsets[m + k/2], a.offsets[m]].
    return std::min(b_upper + double(a.offsets[m + kAxes]), b_neg_lower + double(a.offsets[m]));
  }
#if BVHLAB_KDOP_SSE2
  // axis_overlap of axes 2j and 2j + 1, one per lane, the same operations in the same order.
  [[gnu::always_inline]] static __m128d pair_overlap(const KDop& a, const KDop& b, const AxisPair& p,
                                                     std::size_t j) {
    const float* d = b.offsets.data();
    const auto gather = [d](const std::array<std::uint8_t, 2>& planes) {
      return _mm_set_pd(double(d[planes[1]]), double(d[planes[0]]));
    };
    const auto two_floats = [](const float* x) {  // x[0], x[1] as doubles; an unaligned 8-byte load
      return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(x))));
    };
    const __m128d c0 = _mm_load_pd(p.coefficients[0].data()), c1 = _mm_load_pd(p.coefficients[1].data()),
                  c2 = _mm_load_pd(p.coefficients[2].data()), shift = _mm_load_pd(p.shift.data());
    __m128d upper = _mm_mul_pd(c0, gather(p.upper[0]));
    upper = _mm_add_pd(upper, _mm_mul_pd(c1, gather(p.upper[1])));
    upper = _mm_add_pd(upper, _mm_mul_pd(c2, gather(p.upper[2])));
    upper = _mm_add_pd(upper, shift);
    __m128d neg_lower = _mm_mul_pd(c0, gather(p.lower[0]));
    neg_lower = _mm_add_pd(neg_lower, _mm_mul_pd(c1, gather(p.lower[1])));
    neg_lower = _mm_add_pd(neg_lower, _mm_mul_pd(c2, gather(p.lower[2])));
    neg_lower = _mm_sub_pd(neg_lower, shift);
    const __m128d a_upper = two_floats(a.offsets.data() + 2 * j);
    const __m128d a_neg_lower = two_floats(a.offsets.data() + 2 * j + kAxes);
    return _mm_min_pd(_mm_add_pd(upper, a_neg_lower), _mm_add_pd(neg_lower, a_upper));
  }
  static double smaller_lane(__m128d v) {
    return _mm_cvtsd_f64(_mm_min_sd(v, _mm_unpackhi_pd(v, v)));
  }
#endif
  // Whether an axis overlap o < 0 is beyond the rounding slack (make_context). Kept out of line: only pairs
  // that are apart get here, and inlined its loads and maxima would be computed ahead for every pair.
  [[gnu::noinline]] static bool separated(const KDop& a, const KDop& b, const PairContext& c, double o) {
    return o < -slack(a, b, c);
  }
  [[gnu::always_inline]] static double slack(const KDop& a, const KDop& b, const PairContext& c) {
    return c.slack_per_a_scale * a.coordinate_scale() + c.slack_per_b_scale * b.coordinate_scale() +
           c.slack_translation;
  }

  static constexpr std::array<float, kPlanes> filled(float value) {
    std::array<float, kPlanes> out{};
    for (auto& x : out) x = value;
    return out;
  }
  // One expression for fit and contains, so a fitted point always tests as contained.
  static double project(const Vec3& axis, const Vec3& p) {
    return axis.x() * p.x() + axis.y() * p.y() + axis.z() * p.z();
  }
  // Largest |x|, |y|, |z| offset: bounds |n . x| for every offset of a fitted DOP, up to sqrt(3).
  [[nodiscard]] double coordinate_scale() const {
    double s = 0;
    for (std::size_t a = 0; a < 3; ++a)
      s = std::max({s, std::abs(double(offsets[a])), std::abs(double(offsets[a + kAxes]))});
    return s;
  }
};

namespace dop_sets {
struct Dop6 {
  static constexpr std::string_view name = "dop6";
  static constexpr bool split_along_directions = false;
  static constexpr dop_detail::DirectionSet<3> set{{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
};
// Axes plus the four corner diagonals (the cube's vertices).
struct Dop14 {
  static constexpr std::string_view name = "dop14";
  static constexpr bool split_along_directions = false;
  static constexpr dop_detail::DirectionSet<7> set{
      {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}}}};
};
// Axes plus the six edge diagonals (the cube's edge midpoints).
struct Dop18 {
  static constexpr std::string_view name = "dop18";
  static constexpr bool split_along_directions = false;
  static constexpr dop_detail::DirectionSet<9> set{{{{1, 0, 0},
                                                     {0, 1, 0},
                                                     {0, 0, 1},
                                                     {1, 1, 0},
                                                     {1, -1, 0},
                                                     {1, 0, 1},
                                                     {1, 0, -1},
                                                     {0, 1, 1},
                                                     {0, 1, -1}}}};
};
// Axes, edge diagonals and corner diagonals.
struct Dop26 {
  static constexpr std::string_view name = "dop26";
  static constexpr bool split_along_directions = false;
  static constexpr dop_detail::DirectionSet<13> set{{{{1, 0, 0},
                                                      {0, 1, 0},
                                                      {0, 0, 1},
                                                      {1, 1, 0},
                                                      {1, -1, 0},
                                                      {1, 0, 1},
                                                      {1, 0, -1},
                                                      {0, 1, 1},
                                                      {0, 1, -1},
                                                      {1, 1, 1},
                                                      {1, 1, -1},
                                                      {1, -1, 1},
                                                      {-1, 1, 1}}}};
};
template <int K>
struct ForK;
template <>
struct ForK<6> {
  using type = Dop6;
};
template <>
struct ForK<14> {
  using type = Dop14;
};
template <>
struct ForK<18> {
  using type = Dop18;
};
template <>
struct ForK<26> {
  using type = Dop26;
};
}  // namespace dop_sets

/// The classic k-DOPs, k in {6, 14, 18, 26}.
template <int K>
using Dop = KDop<typename dop_sets::ForK<K>::type>;

static_assert(BoundingVolume<Dop<6>> && DistanceVolume<Dop<6>>);
static_assert(BoundingVolume<Dop<14>> && DistanceVolume<Dop<14>>);
static_assert(BoundingVolume<Dop<18>> && DistanceVolume<Dop<18>>);
static_assert(BoundingVolume<Dop<26>> && DistanceVolume<Dop<26>>);

}  // namespace bvhlab
