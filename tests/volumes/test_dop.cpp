// k-DOP specifics: Zachmann's re-alignment bound against the exact support of the transformed DOP, the
// prototype's non-simple vertices, the volume against an independent vertex enumeration, split directions.
// Also OBB and sphere properties that hold by construction of their fits.
#include "support/random_draws.hpp"
#include "volume_models.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <iostream>
#include <numbers>

namespace bvhlab::volume_tests {
namespace {

using testing::draw_vec3;

/// Every vertex of {x : n_m . x <= d_m}, by brute force over plane triples (reference, O(k^4)).
template <std::size_t Planes>
std::vector<Vec3> polytope_vertices(const std::array<Vec3, Planes>& normals,
                                    const std::array<double, Planes>& d) {
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < Planes; ++i)
    for (std::size_t j = i + 1; j < Planes; ++j)
      for (std::size_t l = j + 1; l < Planes; ++l) {
        Mat3 m;
        m << normals[i].transpose(), normals[j].transpose(), normals[l].transpose();
        if (std::abs(m.determinant()) < 1e-9) continue;
        const Vec3 x = m.partialPivLu().solve(Vec3(d[i], d[j], d[l]));
        bool feasible = true;
        for (std::size_t k = 0; k < Planes && feasible; ++k)
          feasible = normals[k].dot(x) <= d[k] + 1e-10 * (1 + std::abs(d[k]));
        if (feasible) out.push_back(x);
      }
  return out;
}

/// Volume from the vertices: sum over faces of d_m * area / 3, each face's vertices ordered by angle.
template <std::size_t Planes>
double reference_volume(const std::array<Vec3, Planes>& normals, std::array<double, Planes> d,
                        const Vec3& center) {
  for (std::size_t m = 0; m < Planes; ++m)
    d[m] -= normals[m].dot(center);  // about the centre: no cancellation
  const auto vertices = polytope_vertices(normals, d);
  double volume = 0;
  for (std::size_t m = 0; m < Planes; ++m) {
    const Vec3 e1 = normals[m].unitOrthogonal(), e2 = normals[m].cross(e1);
    std::vector<Eigen::Vector2d> face;
    for (const Vec3& x : vertices)
      if (std::abs(normals[m].dot(x) - d[m]) < 1e-9) face.emplace_back(e1.dot(x), e2.dot(x));
    if (face.size() < 3) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : face) mean += p;
    mean /= double(face.size());
    std::sort(face.begin(), face.end(), [&](const auto& a, const auto& b) {
      return std::atan2(a.y() - mean.y(), a.x() - mean.x()) < std::atan2(b.y() - mean.y(), b.x() - mean.x());
    });
    double twice_area = 0;
    for (std::size_t k = 0; k < face.size(); ++k) {
      const auto& p = face[k];
      const auto& q = face[(k + 1) % face.size()];
      twice_area += p.x() * q.y() - p.y() * q.x();
    }
    volume += d[m] * std::abs(twice_area) / 6;
  }
  return volume;
}

template <class BV>
class DopTest : public ::testing::Test {};
template <class BV>
struct IsDop : std::false_type {};
template <class Set>
struct IsDop<KDop<Set>> : std::true_type {};
using DopModels = testing::SelectTypes<IsDop, ShippedVolumes>::type;  // every shipped DOP
TYPED_TEST_SUITE(DopTest, DopModels, ModelName);

template <class BV>
std::array<double, BV::kPlanes> offsets_of(const BV& v) {
  std::array<double, BV::kPlanes> d;
  for (std::size_t m = 0; m < BV::kPlanes; ++m) d[m] = v.offsets[m];
  return d;
}

TYPED_TEST(DopTest, RealignedSupportBoundsTheExactSupport) {
  // For each plane of A, the context's bound on B's support must be >= the exact support of B's transformed
  // DOP (its vertices mapped by the pose), and equal to it at the identity. Also reports the mean excess.
  using BV = TypeParam;
  const auto& normals = BV::tables().normals;
  std::mt19937_64 rng(41);
  double excess_sum = 0, width_sum = 0;
  int checked = 0;
  for (const PointSet& set : sample_point_sets(8)) {
    const BV b = BV::fit(set.points);
    const auto d = offsets_of(b);
    const auto vertices = polytope_vertices(normals, d);
    ASSERT_FALSE(vertices.empty()) << set.label;
    const double scale = 1 + b.bounding_box().extent().norm() + b.bounding_box().max.cwiseAbs().maxCoeff();
    for (int k = 0; k < 12; ++k) {
      RigidTransform pose;
      pose.rotation = k == 0 ? Mat3::Identity() : random_rotation(rng);
      pose.translation = k % 2 ? gaussian_vec(rng) : Vec3::Zero();
      const typename BV::PairContext c = BV::make_context(pose);
      for (std::size_t m = 0; m < BV::kPlanes; ++m) {
        double exact = -std::numeric_limits<double>::infinity();
        for (const Vec3& x : vertices) exact = std::max(exact, normals[m].dot(pose.apply(x)));
        double bound = c.shift(m);
        for (int j = 0; j < 3; ++j) {
          // A plane and its opposite share their coefficients.
          const double coefficient = c.coefficient(m % BV::kAxes, j);
          ASSERT_GE(coefficient, -1e-12) << "coefficient outside the normal cone";
          bound += coefficient * d[c.plane(m, j)];
        }
        ASSERT_GE(bound, exact - 1e-9 * scale) << set.label << ", pose " << k << ", plane " << m;
        if (k == 0) {
          // At the identity the bound is B's own offset (which float rounding may leave a hair off the
          // polytope, so compare with the offset, not the vertex support).
          ASSERT_NEAR(bound, d[m], 1e-12 * scale) << set.label << ": identity must be exact";
        }
        excess_sum += bound - exact;
        ++checked;
      }
      width_sum += b.bounding_box().extent().sum() / 3 * BV::kPlanes;
    }
  }
  std::cout << BV::name() << ": mean support over-estimate / mean width = " << excess_sum / width_sum
            << " over " << checked << " plane bounds\n";
  ::testing::Test::RecordProperty("support_overestimate_ratio", std::to_string(excess_sum / width_sum));
}

TYPED_TEST(DopTest, VolumeMatchesVertexEnumeration) {
  using BV = TypeParam;
  for (const PointSet& set : sample_point_sets(9)) {
    const BV v = BV::fit(set.points);
    const double reference =
        std::clamp(reference_volume(BV::tables().normals, offsets_of(v), v.bounding_box().center()), 0.0,
                   v.bounding_box().volume());
    EXPECT_NEAR(v.volume(), reference, 1e-9 * (1 + v.bounding_box().volume())) << set.label;
  }
}

TYPED_TEST(DopTest, KnownVolumes) {
  using BV = TypeParam;
  std::vector<Vec3> cube, octahedron;
  for (int k = 0; k < 8; ++k) cube.emplace_back(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1);
  for (int a = 0; a < 3; ++a)
    for (int s : {-1, 1}) octahedron.push_back(s * Vec3::Unit(a));
  // Offsets along diagonals are irrational, so float rounding widens them by ~1e-7 relative.
  EXPECT_NEAR(BV::fit(cube).volume(), 8, 1e-12);
  // Every set contains x, y, z; the 14- and 26-DOP contain all corner diagonals, so they fit the octahedron.
  const double octahedron_volume = BV::fit(octahedron).volume();
  if (BV::name() == "dop14" || BV::name() == "dop26") {
    EXPECT_NEAR(octahedron_volume, 4.0 / 3.0, 1e-6);
  } else if (BV::name() == "dop6") {
    EXPECT_NEAR(octahedron_volume, 8, 1e-12);
  }
  EXPECT_GE(octahedron_volume, 4.0 / 3.0 - 1e-12);
}

TYPED_TEST(DopTest, VectorTestAnswersAsTheScalarReference) {
  // overlap() (two axes per vector instruction where the machine has them) against overlap_scalar on the
  // same pairs: random poses, each pair also moved along a random direction to just either side of where
  // the scalar test's answer flips, so the pairs that reach the rounding slack are compared too.
  using BV = TypeParam;
  std::mt19937_64 rng(47);
  const auto sets = sample_point_sets(10);
  int apart = 0, overlapping = 0;
  for (const PointSet& a_set : sets)
    for (const PointSet& b_set : sets) {
      const BV a = BV::fit(a_set.points), b = BV::fit(b_set.points);
      // The sets' means lie in their hulls, so in the volumes: placed on each other, the volumes overlap.
      const auto mean = [](const std::vector<Vec3>& points) {
        Vec3 sum = Vec3::Zero();
        for (const Vec3& p : points) sum += p;
        return Vec3(sum / double(points.size()));
      };
      const Vec3 a_mean = mean(a_set.points), b_mean = mean(b_set.points);
      for (int k = 0; k < 8; ++k) {
        RigidTransform pose;
        pose.rotation = random_rotation(rng);
        const Vec3 direction = gaussian_vec(rng).normalized();
        const auto answers_alike = [&](double distance) {
          pose.translation = a_mean - pose.rotation * b_mean + distance * direction;
          const auto context = BV::make_context(pose);
          const bool scalar = BV::overlap_scalar(a, b, context);
          EXPECT_EQ(BV::overlap(a, b, context), scalar)
              << a_set.label << " / " << b_set.label << ", pose " << k << ", distance " << distance;
          (scalar ? overlapping : apart) += 1;
          return scalar;
        };
        double near = 0, far = 10 * (a.bounding_box().extent().norm() + b.bounding_box().extent().norm()) + 1;
        ASSERT_TRUE(answers_alike(near));
        ASSERT_FALSE(answers_alike(far));
        for (int step = 0; step < 60; ++step) {  // bisection down to adjacent doubles
          const double middle = near + (far - near) / 2;
          if (middle == near || middle == far) break;
          (answers_alike(middle) ? near : far) = middle;
        }
        answers_alike(std::nextafter(near, 0.0));
        answers_alike(std::nextafter(far, 2 * far));
      }
    }
  EXPECT_GT(apart, 1000);
  EXPECT_GT(overlapping, 1000);
}

TYPED_TEST(DopTest, ExtremalVertexSearchAnswersAsTheScalarReference) {
  // The realignment's vertex search (two antipodal pairs per vector instruction where the machine has them)
  // against the one-at-a-time reference, and against the definition: a vertex of largest v . x, of the
  // first antipodal pair (i, i + half) that holds one. Directions at random, along the normals and towards
  // the vertices, where whole faces and edges tie.
  using BV = TypeParam;
  const auto& tables = BV::tables();
  const std::size_t half = tables.half;
  ASSERT_EQ(tables.vertices.size(), 2 * half);
  ASSERT_EQ(tables.xs.size(), half + half % 2);
  for (std::size_t i = 0; i < half; ++i)
    ASSERT_LT((tables.vertices[i].position + tables.vertices[i + half].position).norm(), 1e-12);
  std::vector<Vec3> directions(tables.normals.begin(), tables.normals.end());
  for (const auto& vertex : tables.vertices) directions.push_back(vertex.position);
  std::mt19937_64 rng(53);
  for (int k = 0; k < 2000; ++k) directions.push_back(gaussian_vec(rng).normalized());
  for (std::size_t k = 0, n = directions.size(); k < n; ++k) directions.push_back(-directions[k]);
  for (const Vec3& v : directions) {
    const std::size_t found = tables.extremal_vertex(v);
    ASSERT_EQ(found, tables.extremal_vertex_scalar(v)) << "direction " << v.transpose();
    const auto along = [&](std::size_t i) {  // the search's numbers: the first half's, negated for the second
      const std::size_t j = i % half;
      const double value = (v[0] * tables.xs[j] + v[1] * tables.ys[j]) + v[2] * tables.zs[j];
      return i < half ? value : -value;
    };
    for (std::size_t i = 0; i < 2 * half; ++i) {
      EXPECT_LE(along(i), along(found)) << "vertex " << i << " is farther, direction " << v.transpose();
      if (i % half < found % half)
        EXPECT_LT(along(i), along(found)) << "an earlier pair ties, direction " << v.transpose();
    }
  }
}

TYPED_TEST(DopTest, RealignmentWalkFindsTheScansTripleBitForBit) {
  // realign walks the prototype's edges and stops only deep inside a vertex's normal cone; it must give the
  // scan's triple and coefficients exactly, and leave to the scan the directions where vertices tie: along
  // a face's normal, and along the sum of the two normals an edge lies on. Directions at random, of every
  // magnitude, and towards the vertices.
  using BV = TypeParam;
  const auto& tables = BV::tables();
  ASSERT_FALSE(tables.across.empty()) << "every shipped DOP's prototype has simple vertices: the walk is on";
  std::vector<Vec3> ties(tables.normals.begin(), tables.normals.end());
  for (const auto& vertex : tables.vertices) {
    const auto& planes = vertex.triples[0].planes;
    for (int k = 0; k < 3; ++k)
      ties.push_back(tables.normals[planes[k]] + tables.normals[planes[(k + 1) % 3]]);
  }
  std::mt19937_64 rng(61);
  std::vector<Vec3> random;
  for (int k = 0; k < 20000; ++k)
    random.push_back(gaussian_vec(rng).normalized() * std::pow(10.0, k % 7 * 50 - 150));
  const auto same_as_scan = [&](const Vec3& v) {
    std::array<std::uint8_t, 3> walked_planes{}, scanned_planes{};
    std::array<double, 3> walked{}, scanned{};
    const bool walk = tables.walk(v, walked_planes, walked);
    tables.realign_by_scan(v, scanned_planes, scanned);
    if (walk) {
      EXPECT_EQ(walked_planes, scanned_planes) << "direction " << v.transpose();
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(std::bit_cast<std::uint64_t>(walked[k]), std::bit_cast<std::uint64_t>(scanned[k]));
    }
    return walk;
  };
  int walked = 0;
  for (const Vec3& v : random) walked += same_as_scan(v);
  EXPECT_GE(walked, 19900) << "the walk should settle almost every direction at random";
  for (const auto& vertex : tables.vertices) same_as_scan(vertex.position);
  for (const Vec3& v : ties) EXPECT_FALSE(same_as_scan(v)) << "a tie, direction " << v.transpose();
}

TEST(DopRealignment, NonSimplePrototypeVerticesUseATripleWhoseConeHoldsTheDirection) {
  // The four corner diagonals alone: the prototype is an octahedron, four planes meet at each vertex.
  const dop_detail::DirectionSet<4> set{{{{1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {-1, 1, 1}}}};
  const dop_detail::Tables<4> tables(set);
  ASSERT_EQ(tables.vertices.size(), 6u);
  for (const auto& v : tables.vertices) EXPECT_EQ(v.triples.size(), 4u);
  EXPECT_TRUE(tables.across.empty()) << "no walk over vertices that are not simple";
  std::mt19937_64 rng(43);
  for (int k = 0; k < 2000; ++k) {
    Vec3 v = gaussian_vec(rng).normalized();
    if (k < 6) v = (k % 2 ? -1.0 : 1.0) * Vec3::Unit(k / 2);  // exactly at a vertex: every triple ties
    std::array<std::uint8_t, 3> planes;
    std::array<double, 3> lambda;
    tables.realign(v, planes, lambda);
    Vec3 combination = Vec3::Zero();
    double prototype_support = -std::numeric_limits<double>::infinity();
    for (const auto& vertex : tables.vertices)
      prototype_support = std::max(prototype_support, v.dot(vertex.position));
    for (int j = 0; j < 3; ++j) {
      EXPECT_GE(lambda[j], -1e-12) << "direction " << v.transpose();
      combination += lambda[j] * tables.normals[planes[j]];
    }
    EXPECT_LT((combination - v).norm(), 1e-12);
    EXPECT_NEAR(lambda[0] + lambda[1] + lambda[2], prototype_support, 1e-12);
  }
}

TEST(DopSplitDirections, Dop24OffersItsAxesOthersTheCoordinateAxes) {
  const auto dop24 = split_directions_of<Dop24>();
  ASSERT_EQ(dop24.size(), 12u);
  for (std::size_t i = 0; i < dop24.size(); ++i) {
    EXPECT_NEAR(dop24[i].norm(), 1, 1e-15);
    for (std::size_t j = 0; j < i; ++j)
      EXPECT_LT(std::abs(dop24[i].dot(dop24[j])), 1 - 1e-6) << "parallel axes";
  }
  EXPECT_EQ(split_directions_of<Dop<26>>().size(), 3u);
}

TEST(DopStorage, BytesPerVolume) {
  EXPECT_EQ(sizeof(Dop<6>), 24u);
  EXPECT_EQ(sizeof(Dop<14>), 56u);
  EXPECT_EQ(sizeof(Dop<18>), 72u);
  EXPECT_EQ(sizeof(Dop<26>), 104u);
  EXPECT_EQ(sizeof(Dop24), 96u);
  EXPECT_EQ(sizeof(Obb), 40u);
  EXPECT_EQ(sizeof(Sphere), 16u);
}

// ---------------------------------------------------------------------------------------------------------

TEST(ObbFit, NeverLargerThanTheAabbAndRecoversARotatedBox) {
  for (const PointSet& set : sample_point_sets(10)) {
    const Obb obb = Obb::fit(set.points);
    const Aabb aabb = Aabb::fit(set.points);
    // The coordinate frame is one of the fit's candidates; only float rounding and the widening by ~5e-7 of
    // the size and 2^-24 of the position (which give flat sets a sliver of volume) differ.
    const Box box = aabb.bounding_box();
    const double size = box.extent().norm(), widening = 1e-6 * (size + box.max.cwiseAbs().maxCoeff()) + 1e-40;
    const double sliver = 8 * (size + widening) * (size + widening) * widening;
    EXPECT_LE(obb.volume(), aabb.volume() * (1 + 1e-5) + sliver) << set.label;
  }
  // Points filling a rotated box: PCA finds the box, so the OBB is close to its true volume.
  std::mt19937_64 rng(47);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int k = 0; k < 5; ++k) {
    const Mat3 r = random_rotation(rng);
    const Vec3 half(2, 0.5, 0.1), center = gaussian_vec(rng);
    std::vector<Vec3> points;
    for (int i = 0; i < 2000; ++i) points.push_back(center + r * half.cwiseProduct(draw_vec3(unit, rng)));
    for (int c = 0; c < 8; ++c)  // the corners, so the true box is the tightest
      points.push_back(center + r * half.cwiseProduct(Vec3(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1)));
    const double true_volume = 8 * half.prod();
    const Obb obb = Obb::fit(points);
    // PCA of a sampled box is off by the sampling noise of the covariance: a few percent.
    EXPECT_LT(obb.volume(), 1.15 * true_volume) << "pose " << k;
    EXPECT_LT(obb.volume(), Aabb::fit(points).volume()) << "pose " << k;
    EXPECT_GE(obb.volume(), true_volume * (1 - 1e-9));
  }
}

TEST(SphereFit, WithinAFewPercentOfTheMinimalSphereForASymmetricCloud) {
  std::mt19937_64 rng(53);
  std::vector<Vec3> shell;
  for (int i = 0; i < 3000; ++i) shell.push_back(Vec3(1, 2, 3) + 2 * gaussian_vec(rng).normalized());
  const Sphere s = Sphere::fit(shell);
  EXPECT_LT(s.radius, 2 * 1.05);
  EXPECT_GE(s.radius, 2 * (1 - 1e-9));
  // A far outlier: the sphere stays near the one on the diameter (here also the minimal one).
  std::vector<Vec3> points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(10, 10, 10)};
  EXPECT_LE(Sphere::fit(points).radius, (Vec3(10, 10, 10).norm() / 2) * 1.01);
}

}  // namespace
}  // namespace bvhlab::volume_tests
