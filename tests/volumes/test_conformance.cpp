// Conformance of every bounding-volume model with the BoundingVolume concept's contract
// (volumes/concept.hpp): fits hold their points, merges hold both inputs, overlap is conservative against
// exact triangle tests (with many just-touching pairs and the special poses), and is not vacuous; bounding
// boxes and volumes agree with Monte Carlo sampling of contains().
#include "bvh/triangle_intersection.hpp"
#include "support/random_draws.hpp"
#include "volume_models.hpp"

#include <gtest/gtest.h>

#include <numbers>

namespace bvhlab::volume_tests {
namespace {

using testing::draw_vec3;

template <class BV>
class VolumeConformance : public ::testing::Test {};
TYPED_TEST_SUITE(VolumeConformance, AllModels, ModelName);

TYPED_TEST(VolumeConformance, IsPlainDataWithStableName) {
  using BV = TypeParam;
  static_assert(BoundingVolume<BV>);
  EXPECT_FALSE(BV::name().empty());
  EXPECT_EQ(BV::name().find(' '), std::string_view::npos);
  // Default-constructed volumes are empty: they hold nothing and measure nothing.
  const BV empty{};
  EXPECT_FALSE(empty.contains(Vec3::Zero()));
  EXPECT_EQ(empty.volume(), 0);
  EXPECT_TRUE(empty.bounding_box().empty());
  EXPECT_TRUE(BV::fit(std::span<const Vec3>()).bounding_box().empty());
}

TYPED_TEST(VolumeConformance, FitContainsItsPoints) {
  using BV = TypeParam;
  for (const PointSet& set : sample_point_sets(1)) {
    const BV v = BV::fit(set.points);
    const Box box = v.bounding_box();
    for (const Vec3& p : set.points) {
      ASSERT_TRUE(v.contains(p)) << set.label << ": point " << p.transpose();
      ASSERT_TRUE(box.contains(p)) << set.label << ": bounding box misses " << p.transpose();
    }
    EXPECT_GE(v.volume(), 0) << set.label;
    EXPECT_LE(v.volume(), box.volume() * (1 + 1e-9)) << set.label;
  }
}

TYPED_TEST(VolumeConformance, FitRejectsNonFinitePoints) {
  using BV = TypeParam;
  const std::vector<Vec3> bad = {Vec3(0, 0, 0), Vec3(1, std::numeric_limits<double>::quiet_NaN(), 0)};
  EXPECT_THROW(BV::fit(bad), std::invalid_argument);
  const std::vector<Vec3> infinite = {Vec3(std::numeric_limits<double>::infinity(), 0, 0)};
  EXPECT_THROW(BV::fit(infinite), std::invalid_argument);
}

TYPED_TEST(VolumeConformance, MergeContainsBoth) {
  using BV = TypeParam;
  const auto sets = sample_point_sets(2);
  std::mt19937_64 rng(3);
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const PointSet& first = sets[k];
    const PointSet& second = sets[(k * 7 + 3) % sets.size()];
    const BV a = BV::fit(first.points), b = BV::fit(second.points);
    for (const BV& merged : {BV::merge(a, b), BV::merge(b, a)}) {
      for (const auto* set : {&first, &second})
        for (const Vec3& p : set->points)
          ASSERT_TRUE(merged.contains(p)) << first.label << " + " << second.label << ": " << p.transpose();
    }
    // Merging with an empty volume keeps everything.
    const BV with_empty = BV::merge(BV{}, a);
    for (const Vec3& p : first.points) ASSERT_TRUE(with_empty.contains(p)) << first.label;
  }
  // The merge must also hold points of the inputs' volumes, not only their fitted points: sample inside a.
  for (int k = 0; k < 20; ++k) {
    const auto& set = sets[k % sets.size()];
    const BV a = BV::fit(set.points), b = BV::fit(sets[(k + 5) % sets.size()].points);
    const BV merged = BV::merge(a, b);
    const Box box = a.bounding_box();
    std::uniform_real_distribution<double> unit(0, 1);
    for (int s = 0; s < 200; ++s) {
      const Vec3 p = box.min + box.extent().cwiseProduct(draw_vec3(unit, rng));
      if (a.contains(p)) {
        ASSERT_TRUE(merged.contains(p)) << set.label << ": " << p.transpose();
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------------------
// Conservativeness against exact triangle tests.

struct ContactCase {
  std::vector<TrianglePoints> a;  // A's frame; a[0] touches b[0]
  std::vector<TrianglePoints> b;  // B's frame
  RigidTransform pose;            // B -> A
  std::string kind;
};

struct NamedRotation {
  std::string name;
  Mat3 rotation;
};

std::vector<NamedRotation> special_rotations() {
  using Eigen::AngleAxisd;
  const double pi = std::numbers::pi;
  Mat3 half_x, half_y, half_z, quarter_z;
  half_x << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  half_y << -1, 0, 0, 0, 1, 0, 0, 0, -1;
  half_z << -1, 0, 0, 0, -1, 0, 0, 0, 1;
  quarter_z << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return {
      {"identity", Mat3::Identity()},
      {"pi about x", half_x},
      {"pi about y", half_y},
      {"pi about z", half_z},
      {"pi/2 about z", quarter_z},
      {"pi about (1,1,1)", AngleAxisd(pi, Vec3(1, 1, 1).normalized()).toRotationMatrix()},
      {"pi about (1,1,0)", AngleAxisd(pi, Vec3(1, 1, 0).normalized()).toRotationMatrix()},
      {"protocol Rz(pi) Rx(pi)",
       (AngleAxisd(pi, Vec3::UnitZ()) * AngleAxisd(pi, Vec3::UnitX())).toRotationMatrix()},
      {"protocol Rz(pi/2) Rx(pi/2)",
       (AngleAxisd(pi / 2, Vec3::UnitZ()) * AngleAxisd(pi / 2, Vec3::UnitX())).toRotationMatrix()},
      {"1e-9 about (0.3,-0.5,0.8)", AngleAxisd(1e-9, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix()},
  };
}

bool pair_intersects(const TrianglePoints& a, const TrianglePoints& b_local, const RigidTransform& pose) {
  return triangles_intersect_exact(a, transformed(pose, b_local));
}

/// Triangle pairs that intersect exactly: half of them crossing, half pushed apart along a random direction
/// until they only just touch (bisection to the last representable step). Some volumes hold extra triangles.
std::vector<ContactCase> make_contact_cases(const Mat3& rotation, const std::string& kind, int count,
                                            std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<ContactCase> cases;
  while (int(cases.size()) < count) {
    const double offset = unit(rng) < 0.2 ? 1e3 : 1;
    const double size_a = std::pow(10, -2 * unit(rng)), size_b = std::pow(10, -2 * unit(rng));
    ContactCase c;
    c.kind = kind;
    c.a.push_back(random_triangle(rng, offset * gaussian_vec(rng), size_a));
    c.b.push_back(random_triangle(rng, offset * gaussian_vec(rng), size_b));
    auto barycentric = [&](const TrianglePoints& t) {
      double u = unit(rng), v = unit(rng);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      return Vec3(t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]));
    };
    c.pose.rotation = rotation;
    c.pose.translation = barycentric(c.a[0]) - rotation * barycentric(c.b[0]);
    if (!pair_intersects(c.a[0], c.b[0], c.pose)) continue;  // grazing at the start: draw again
    if (unit(rng) < 0.5) {
      const Vec3 direction = gaussian_vec(rng).normalized();
      const double far = 4 * (size_a + size_b) * 3;
      RigidTransform moved = c.pose;
      moved.translation += far * direction;
      if (pair_intersects(c.a[0], c.b[0], moved)) continue;
      double lo = 0, hi = far;
      for (int k = 0; k < 80 && hi > lo; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (mid == lo || mid == hi) break;
        moved.translation = c.pose.translation + mid * direction;
        (pair_intersects(c.a[0], c.b[0], moved) ? lo : hi) = mid;
      }
      c.pose.translation += lo * direction;
      c.kind += " touching";
      if (!pair_intersects(c.a[0], c.b[0], c.pose)) continue;  // cannot happen: lo always intersects
    } else {
      c.kind += " crossing";
    }
    if (unit(rng) < 0.4) {
      // Clusters: the volumes then have shapes of their own, not just a triangle's.
      const int extra_a = 1 + int(3 * unit(rng)), extra_b = 1 + int(3 * unit(rng));
      const Vec3 ca = c.a[0][0], cb = c.b[0][1];
      for (int k = 0; k < extra_a; ++k)
        c.a.push_back(random_triangle(rng, ca + size_a * gaussian_vec(rng), size_a));
      for (int k = 0; k < extra_b; ++k)
        c.b.push_back(random_triangle(rng, cb + size_b * gaussian_vec(rng), size_b));
    }
    cases.push_back(std::move(c));
  }
  return cases;
}

const std::vector<ContactCase>& contact_cases() {
  static const std::vector<ContactCase> cases = [] {
    std::mt19937_64 rng(17);
    std::vector<ContactCase> out;
    for (int k = 0; k < 400; ++k) {
      auto one = make_contact_cases(random_rotation(rng), "random pose", 1, rng);
      out.insert(out.end(), one.begin(), one.end());
    }
    for (const auto& [name, rotation] : special_rotations()) {
      auto some = make_contact_cases(rotation, name, 60, rng);
      out.insert(out.end(), some.begin(), some.end());
    }
    return out;
  }();
  return cases;
}

TYPED_TEST(VolumeConformance, OverlapIsConservativeForIntersectingTriangles) {
  using BV = TypeParam;
  const auto& cases = contact_cases();
  int touching = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const ContactCase& c = cases[k];
    const std::vector<Vec3> pa = vertices_of(c.a), pb = vertices_of(c.b);
    const BV a = BV::fit(pa), b = BV::fit(pb);
    ASSERT_TRUE(BV::overlap(a, b, BV::make_context(c.pose)))
        << "case " << k << " (" << c.kind << "): intersecting triangles, volumes reported apart";
    // The single touching triangles alone, too (no cluster to give slack).
    ASSERT_TRUE(BV::overlap(BV::fit(vertices_of(std::span(c.a).first(1))),
                            BV::fit(vertices_of(std::span(c.b).first(1))), BV::make_context(c.pose)))
        << "case " << k << " (" << c.kind << "), single triangles";
    touching += c.kind.ends_with("touching");
  }
  // The mix must really contain many just-touching pairs, or it proves little about the slack.
  EXPECT_GT(touching, int(cases.size()) / 3);
}

TYPED_TEST(VolumeConformance, OverlapIsConservativeForMovedCopiesOfOneCloud) {
  // B = A's own points expressed in B's frame: the volumes hold the same set in space, so they must overlap.
  using BV = TypeParam;
  std::mt19937_64 rng(23);
  for (const PointSet& set : sample_point_sets(4)) {
    for (int k = 0; k < 10; ++k) {
      RigidTransform pose;
      pose.rotation = k == 0 ? Mat3::Identity() : random_rotation(rng);
      pose.translation = (k % 3) * gaussian_vec(rng);
      const RigidTransform to_b = pose.inverse();
      std::vector<Vec3> in_b;
      for (const Vec3& p : set.points) in_b.push_back(to_b.apply(p));
      ASSERT_TRUE(BV::overlap(BV::fit(set.points), BV::fit(in_b), BV::make_context(pose))) << set.label;
    }
  }
}

TYPED_TEST(VolumeConformance, ClearlySeparatedVolumesDoNotOverlap) {
  // Beyond 3.5 times the sum of the bounding boxes' circumradii every model's test must see the gap: the
  // re-boxing of an AABB or the re-aligned DOP at most inflate B by sqrt(3) about its box's centre, and
  // testing along A's x, y, z loses another sqrt(3); OBB, sphere and capsule are tighter. So this can fail.
  using BV = TypeParam;
  std::mt19937_64 rng(29);
  const auto sets = sample_point_sets(5);
  int tested = 0;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const BV a = BV::fit(sets[k].points), b = BV::fit(sets[(k + 3) % sets.size()].points);
    const Box box_a = a.bounding_box(), box_b = b.bounding_box();
    const double ra = box_a.extent().norm() / 2, rb = box_b.extent().norm() / 2;
    for (int j = 0; j < 20; ++j) {
      RigidTransform pose;
      pose.rotation = j == 0 ? Mat3::Identity() : random_rotation(rng);
      const Vec3 direction = gaussian_vec(rng).normalized();
      const double distance = 3.5 * (ra + rb) * (1 + 1e-6) + 1e-12;
      // Place B's box centre at A's box centre + distance * direction.
      pose.translation = box_a.center() + distance * direction - pose.rotation * box_b.center();
      ASSERT_FALSE(BV::overlap(a, b, BV::make_context(pose)))
          << sets[k].label << " vs " << sets[(k + 3) % sets.size()].label << ", pose " << j;
      ++tested;
    }
  }
  EXPECT_GT(tested, 100);
}

TYPED_TEST(VolumeConformance, IdenticalVolumesOverlapAtIdentityAndSeparateWhenShifted) {
  using BV = TypeParam;
  std::mt19937_64 rng(31);
  for (const PointSet& set : sample_point_sets(6)) {
    const BV v = BV::fit(set.points);
    EXPECT_TRUE(BV::overlap(v, v, BV::make_context(RigidTransform::identity()))) << set.label;
    // Shifted by more than the box's extent along x, with no rotation: every model must see that gap.
    const Box box = v.bounding_box();
    const double shift = 2 * box.extent().norm() + 1e-9 * (1 + box.max.cwiseAbs().maxCoeff());
    EXPECT_FALSE(BV::overlap(v, v, BV::make_context(RigidTransform::translate(Vec3(shift, 0, 0)))))
        << set.label;
  }
}

// The OBB's test hands on the boxes' placement (FramePlacingVolume, read by the ADB estimate in the nodes'
// frames): it answers as the plain test and places both boxes as the pair lies, each one's half-extents and
// B's axes and centre in A's box frame.
static_assert(FramePlacingVolume<Obb>);
TEST(ObbPlacement, ThePlacingTestAnswersAsThePlainOneAndPlacesBothBoxes) {
  std::mt19937_64 rng(37);
  const auto sets = sample_point_sets(7);
  int overlapping = 0, apart = 0;
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const Obb a = Obb::fit(sets[k].points), b = Obb::fit(sets[(k + 2) % sets.size()].points);
    const OrientedBox oa = a.oriented_box(), ob = b.oriented_box();
    for (int j = 0; j < 20; ++j) {
      RigidTransform pose;
      pose.rotation = random_rotation(rng);
      pose.translation = (0.1 * j) * gaussian_vec(rng) * (1 + oa.half.norm() + ob.half.norm());
      const auto context = Obb::make_context(pose);
      PlacedBoxes placed;
      const bool answer = Obb::overlap(a, b, context, placed);
      ASSERT_EQ(answer, Obb::overlap(a, b, context)) << sets[k].label << ", pose " << j;
      (answer ? overlapping : apart) += 1;
      EXPECT_EQ(placed.half_a, oa.half) << sets[k].label;
      EXPECT_EQ(placed.half_b, ob.half) << sets[k].label;
      const Mat3 rotation = oa.axes.transpose() * pose.rotation * ob.axes;
      const Vec3 centre = oa.local(pose.apply(ob.center));
      EXPECT_LT((placed.b_in_a.rotation - rotation).cwiseAbs().maxCoeff(), 1e-12) << sets[k].label;
      EXPECT_LT((placed.b_in_a.translation - centre).norm(), 1e-12 * (1 + centre.norm())) << sets[k].label;
    }
  }
  EXPECT_GT(overlapping, 10);
  EXPECT_GT(apart, 10);
}

// ---------------------------------------------------------------------------------------------------------
// Bounding box and volume against Monte Carlo sampling of contains().

TYPED_TEST(VolumeConformance, BoundingBoxAndVolumeAgreeWithSampling) {
  using BV = TypeParam;
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> unit(0, 1);
  int measured = 0;
  for (const PointSet& set : sample_point_sets(7)) {
    const BV v = BV::fit(set.points);
    const Box box = v.bounding_box();
    ASSERT_FALSE(box.empty()) << set.label;
    // Sample a box 1.5 times the bounding box (about its centre): nothing inside the volume may fall
    // outside the bounding box, and the hit fraction estimates the volume.
    const Vec3 extent = box.extent() * 1.5;
    const Vec3 corner = box.center() - extent / 2;
    const double sample_volume = extent.prod();
    const int n = 4000;
    int inside = 0;
    for (int s = 0; s < n; ++s) {
      const Vec3 p = corner + extent.cwiseProduct(draw_vec3(unit, rng));
      if (!v.contains(p)) continue;
      ++inside;
      ASSERT_TRUE(box.contains(p)) << set.label << ": contained point outside bounding_box " << p.transpose();
    }
    if (!(sample_volume > 0) || v.volume() < 1e-3 * sample_volume) continue;  // flat: nothing to estimate
    const double fraction = double(inside) / n, expected = v.volume() / sample_volume;
    const double sigma = std::sqrt(expected * (1 - expected) / n);
    EXPECT_NEAR(fraction, expected, 5 * sigma + 1e-3) << set.label << ": volume() disagrees with sampling";
    ++measured;
  }
  EXPECT_GT(measured, 10);
}

}  // namespace
}  // namespace bvhlab::volume_tests
