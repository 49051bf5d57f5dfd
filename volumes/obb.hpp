// Oriented bounding box: centre, orientation, half-extents; separating-axis test on 15 axes.
//
// Storage (40 bytes): the orientation as a float quaternion, centre and half-extents as floats. The box is
// *defined* by the stored numbers: its axes are the columns of the rotation computed (in double, always by
// the same function) from the float quaternion, orthonormal to a few ulps. The fit widens the half-extents
// by a bound on what rounding the frame and centre to float can move (about 5e-7 of the box's size) and
// rounds them up, so storing the fit as floats never loses a point.
//
// Fit: the principal axes of the points' covariance (PCA), or the coordinate axes when those give a smaller
// box (PCA is poor for some symmetric or skewed sets); degenerate sets (flat, collinear, one point) need no
// special case, the eigen-solver still returns an orthonormal frame and the extents become zero.
//
// Overlap: the classic 15-axis test with B's box expressed in A's box frame. |C| is widened by a few ulps
// as usual, so near-parallel edges (cross products of rounding-noise length) cannot separate; and every
// comparison has a slack scaled by the magnitudes of the centres, translation and extents, which covers the
// rounding of those products (absolute errors grow with |t|, not with the box size).
#pragma once

#include "concept.hpp"
#include "storage.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace bvhlab {

struct Obb {
  std::array<float, 4> orientation{0, 0, 0, 1};  // quaternion (x, y, z, w), need not be unit
  Float3 center{0, 0, 0};
  Float3 half{-1, -1, -1};  // negative: empty

  struct PairContext {
    PlainMat3 rotation;  // B -> A
    Double3 translation;
    double translation_magnitude;  // max |t_i|
  };

  static constexpr std::string_view name() { return "obb"; }

  /// Rotation matrix of a (not necessarily unit) quaternion; columns are the box axes.
  static Mat3 axes_of(const std::array<float, 4>& q) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double s = 2 / (x * x + y * y + z * z + w * w);
    Mat3 r;
    r << 1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y),  //
        s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x),   //
        s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y);
    return r;
  }

  static Obb fit(std::span<const Vec3> points) { return fit_with_margin(points, 0); }

  static Obb merge(const Obb& a, const Obb& b);

  /// Refitting a deformed mesh (Bvh::refit): the box of the triangles in `previous`'s orientation, kept
  /// bit for bit. One pass and no eigen-solve; as tight as fit() while the deformation keeps local
  /// orientations, looser when it turns the parts (RefitMethod::Fit renews the orientations).
  static Obb fit_in_frame_of(const Obb& previous, std::span<const TrianglePoints> triangles);

  static PairContext make_context(const RigidTransform& pose) {
    return {PlainMat3::from(pose.rotation), to_double3(pose.translation),
            pose.translation.cwiseAbs().maxCoeff()};
  }

  /// The box with its axes as a matrix (UnpackedVolume): trees keep it beside the stored box, since turning
  /// two quaternions into axes was about a seventh of a test (bench_bv_test, jeep1: 55 ns instead of 64).
  struct Unpacked {
    Mat3 axes;
    Vec3 center, half;
    double magnitude;
  };
  static Unpacked unpack(const Obb& v) {
    return {axes_of(v.orientation), to_vec(v.center), to_vec(v.half), v.magnitude()};
  }

  [[gnu::flatten]] static bool overlap(const Obb& a, const Obb& b, const PairContext& c) {
    return test(unpack(a), unpack(b), c, nullptr);
  }
  [[gnu::flatten]] static bool overlap(const Unpacked& a, const Unpacked& b, const PairContext& c) {
    return test(a, b, c, nullptr);
  }
  /// The same test, also handing on the placement it computes (FramePlacingVolume): for the ADB estimate
  /// in the nodes' frames, which would otherwise compute it again.
  [[gnu::flatten]] static bool overlap(const Obb& a, const Obb& b, const PairContext& c,
                                       PlacedBoxes& placed) {
    return test(unpack(a), unpack(b), c, &placed);
  }
  [[gnu::flatten]] static bool overlap(const Unpacked& a, const Unpacked& b, const PairContext& c,
                                       PlacedBoxes& placed) {
    return test(a, b, c, &placed);
  }

  /// DistanceVolume: the larger of the face gaps' Euclidean length in either box's frame (below) and the
  /// widest edge-axis gap, each gap less overlap()'s slack and an edge axis's divided by its length.
  /// Projection onto a unit axis does not increase distances, so each is a lower bound.
  /// Edge axes shorter than kMinEdgeAxis (edges within about 6 degrees of parallel) are skipped, which is
  /// always allowed: dividing by their length would magnify the slack, which is absolute and scales with
  /// the coordinates, more than tenfold (at coordinates 1e6 such an axis moved the bound by 1.3e-6 at
  /// distance 1), and they raise the bound only in rare near-parallel edge-edge poses (on the tests'
  /// separated clouds, a median of bound / distance 0.941 with all nine, 0.940 without those, 0.899 with
  /// none). 0 exactly where overlap() is true.
  [[gnu::flatten]] static double distance_lower_bound(const Obb& a, const Obb& b, const PairContext& c) {
    return distance_lower_bound(unpack(a), unpack(b), c);
  }
  /// With a `cutoff` (the distance the caller already has): a pair whose face gaps alone reach it is answered
  /// at once, without the edge axes, since the caller drops it either way.
  [[gnu::flatten]] static double distance_lower_bound(
      const Unpacked& a, const Unpacked& b, const PairContext& c,
      double cutoff = std::numeric_limits<double>::infinity()) {
    constexpr double kRounding = 1 - 16 * std::numeric_limits<double>::epsilon();
    const Placement p = place(a, b, c);
    // Each frame's three face gaps separate A's box from the box around B's along orthogonal axes: their
    // Euclidean length bounds the distance, and unlike the largest single gap it closes in on the distance
    // as the boxes shrink (one gap alone stays short by the cosine to the nearest axis, at every depth).
    // Face axes are unit to a few ulps (the final factor covers them).
    double on_a = 0, on_b = 0;
    for (int k = 0; k < 3; ++k) {
      on_a += square(std::max(0.0, face_gap_a(p, k) - p.slack));
      on_b += square(std::max(0.0, face_gap_b(p, k) - p.slack));
    }
    double best_squared = std::max(on_a, on_b);
    if (std::sqrt(best_squared) * kRounding >= cutoff) return std::sqrt(best_squared) * kRounding;
    edge_axes(p, best_squared, std::make_index_sequence<9>{});
    // The divisions, square roots and subtractions round by a few ulps of the result.
    return std::sqrt(best_squared) * kRounding;
  }

  [[nodiscard]] bool empty() const { return half[0] < 0; }

  /// For loaders of raw node bytes: finite, non-negative half extents and a quaternion that is close to unit
  /// length (fit stores unit ones; axes_of divides by the squared norm).
  [[nodiscard]] bool valid() const;
  [[nodiscard]] Scalar volume() const { return empty() ? 0 : 8 * double(half[0]) * half[1] * half[2]; }

  [[nodiscard]] Box bounding_box() const {
    if (empty()) return {};
    const Vec3 reach =
        axes_of(orientation).cwiseAbs() * to_vec(half) + Vec3::Constant(kFrameRounding * magnitude());
    return {to_vec(center) - reach, to_vec(center) + reach};
  }

  /// The box itself: its axes, centre and half-extents (FramedVolume).
  [[nodiscard]] OrientedBox oriented_box() const {
    if (empty()) return {};
    return {axes_of(orientation), to_vec(center), to_vec(half)};
  }

  [[nodiscard]] bool contains(const Vec3& p) const;

 private:
  // B's box in A's box frame and what the separating-axis gaps need; computed once per test.
  struct Placement {
    Mat3 m;      // B's axes (columns) in A's box frame
    Vec3 t;      // B's centre in A's box frame
    Mat3 abs_m;  // |m|, widened by a few ulps
    Vec3 ha, hb;
    double slack;  // rounding slack of every gap below
  };
  [[gnu::always_inline]] static Placement place(const Unpacked& a, const Unpacked& b, const PairContext& c) {
    // Copied out of the row-major map: the products with the map took about a third of the test.
    const Mat3 rotation = c.rotation.map();
    const Mat3 m = a.axes.transpose() * (rotation * b.axes);
    const Vec3 t = a.axes.transpose() * (rotation * b.center + to_vec(c.translation) - a.center);
    const Mat3 abs_m = m.cwiseAbs().array() + Scalar(8) * std::numeric_limits<Scalar>::epsilon();
    const double slack =
        64 * std::numeric_limits<double>::epsilon() * (a.magnitude + b.magnitude + c.translation_magnitude);
    return {m, t, abs_m, a.half, b.half, slack};
  }
  [[gnu::always_inline]] static double square(double x) { return x * x; }
  // |T . L| - radius_a - radius_b on A's face axis i, B's face axis j, and the edge axis a_i x b_j (not a
  // unit vector: its length is sqrt(m(i1, j)^2 + m(i2, j)^2)).
  [[gnu::always_inline]] static double face_gap_a(const Placement& p, int i) {
    return std::abs(p.t[i]) - p.ha[i] - p.abs_m.row(i).dot(p.hb);
  }
  [[gnu::always_inline]] static double face_gap_b(const Placement& p, int j) {
    return std::abs(p.t.dot(p.m.col(j))) - p.abs_m.col(j).dot(p.ha) - p.hb[j];
  }
  [[gnu::always_inline]] static double edge_gap(const Placement& p, int i, int j) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    const double distance = std::abs(p.t[i2] * p.m(i1, j) - p.t[i1] * p.m(i2, j));
    const double radius_a = p.ha[i1] * p.abs_m(i2, j) + p.ha[i2] * p.abs_m(i1, j);
    const double radius_b = p.hb[j1] * p.abs_m(i, j2) + p.hb[j2] * p.abs_m(i, j1);
    return distance - radius_a - radius_b;
  }

  // The distance bound's nine edge axes written out, each with constant indices: as a loop, the compiler
  // kept the loop, its (i + 1) % 3 index arithmetic and a branch per axis (the query ran a tenth slower).
  template <std::size_t... axis>
  [[gnu::always_inline]] static void edge_axes(const Placement& p, double& best_squared,
                                               std::index_sequence<axis...>) {
    (edge_axis<int(axis / 3), int(axis % 3)>(p, best_squared), ...);
  }
  // gap / length beats the best bound only where gap^2 > best^2 length^2, which is rare: a division then.
  template <int i, int j>
  [[gnu::always_inline]] static void edge_axis(const Placement& p, double& best_squared) {
    constexpr int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    const double gap = std::max(0.0, edge_gap(p, i, j) - p.slack);
    const double length_squared = p.m(i1, j) * p.m(i1, j) + p.m(i2, j) * p.m(i2, j);
    if (gap * gap > best_squared * length_squared && length_squared >= kMinEdgeAxis * kMinEdgeAxis)
        [[unlikely]]
      best_squared = gap * gap / length_squared;
  }

  // The 15-axis test; with `placed`, what it computed of the placement is written there.
  [[gnu::always_inline]] static bool test(const Unpacked& a, const Unpacked& b, const PairContext& c,
                                          PlacedBoxes* placed) {
    const Placement p = place(a, b, c);
    if (placed) *placed = {p.ha, p.hb, {p.m, p.t}};
    double gap = -std::numeric_limits<double>::infinity();  // largest (|T . L| - radii) over the axes
    for (int i = 0; i < 3; ++i) gap = std::max(gap, face_gap_a(p, i));
    for (int j = 0; j < 3; ++j) gap = std::max(gap, face_gap_b(p, j));
    // One branch: most pairs a traversal tests are separated by a face axis, so skip the 9 edge axes.
    if (gap > p.slack) return false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) gap = std::max(gap, edge_gap(p, i, j));
    return gap <= p.slack;
  }

  // One expression for fit and contains, so a fitted point always tests as contained.
  static Vec3 local_coordinates(const Mat3& axes, const Vec3& center, const Vec3& p);

  [[nodiscard]] double magnitude() const {
    return to_vec(center).cwiseAbs().maxCoeff() + to_vec(half).cwiseAbs().sum();
  }

  void write_corners(Vec3* out) const;

  // The stored box for the points in the orthonormal frame F. The stored frame F' = axes_of(float
  // quaternion) is within angle 2^-22 of F (quaternion components rounded to 2^-24 relative), and the stored
  // centre within 2^-24 |c| of the exact one, so each half-extent measured in F about c grows by
  // kFrameRounding * (largest |p - c|) + 2^-24 |c| (triangle inequality) and a few ulps. Bounding the
  // rounding instead of re-measuring against the stored floats also keeps this correct under GCC 12's -O2
  // SLP vectoriser, which folds double(float(x)) back to x.
  static constexpr double kFrameRounding = 0x1p-21;
  static constexpr double kMinEdgeAxis = 0.1;  // shortest edge axis distance_lower_bound divides by
  static Obb box_in_frame(std::span<const Vec3> points, const Mat3& frame, double margin);

  static Obb fit_with_margin(std::span<const Vec3> points, double margin);

  // Smaller volume wins; for (nearly) flat boxes, the smaller surface, then the smaller extents.
  static bool smaller(const Obb& a, const Obb& b);
};

static_assert(BoundingVolume<Obb> && FramedVolume<Obb> && DistanceVolume<Obb>);

}  // namespace bvhlab
