// The proximity queries' typed tests (traversal/distance.hpp) against a brute force over every triangle
// pair, for every volume with a distance bound: declared here, instantiated for a part of the volumes in
// each of test_distance.cpp and test_distance_dops.cpp, so that no unit compiles every volume's queries.
#pragma once

#include "support/brute_force_distance.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/distance.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace bvhlab::distance_tests {

using testing::brute_force_distance;

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Distance from point p to triangle t (both in one frame): how far a reported closest point is off it.
inline double off_triangle(const Vec3& p, const TrianglePoints& t) {
  return triangle_distance({p, p, p}, t).distance;
}

inline RigidTransform translated(RigidTransform pose, const Vec3& shift) {
  pose.translation += shift;
  return pose;
}

template <class BV>
class DistanceQuery : public ::testing::Test {
 protected:
  Mesh a = testing::make_torus(0.7, 0.25, 12, 6);
  Mesh b = testing::make_random_soup(100, 0.15, 3);
  Bvh<BV> tree_a = Bvh<BV>::build(a);
  Bvh<BV> tree_b = Bvh<BV>::build(b);
  /// The reported points lie on the named triangles (B's moved by `pose`) and are as far apart as reported.
  void expect_points_on_named_triangles(const DistanceResult& r, const RigidTransform& pose) const {
    ASSERT_TRUE(r.triangles.has_value());
    const TrianglePoints tb = b.triangle(r.triangles->b);
    const TrianglePoints moved = {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])};
    EXPECT_LT(off_triangle(r.on_a, a.triangle(r.triangles->a)), 1e-12);
    EXPECT_LT(off_triangle(r.on_b, moved), 1e-12);
    EXPECT_NEAR((r.on_a - r.on_b).norm(), r.distance, 1e-12);
  }
  /// Poses from deep overlap to a few object sizes apart.
  std::vector<RigidTransform> poses() const {
    std::mt19937_64 rng(17);
    std::vector<RigidTransform> out;
    for (int k = 0; k < 24; ++k) out.push_back(testing::random_pose(rng, 0.5 + 0.25 * k));
    return out;
  }
};

TYPED_TEST_SUITE_P(DistanceQuery);

TYPED_TEST_P(DistanceQuery, FindsTheNearestTrianglePairWithItsPoints) {
  int touching = 0, apart = 0;
  for (const RigidTransform& pose : this->poses()) {
    const DistanceResult r = query_distance(this->tree_a, this->tree_b, pose);
    const double expected = brute_force_distance(this->a, this->b, pose);
    ASSERT_EQ(r.distance, expected);
    ASSERT_TRUE(r.exact);
    ASSERT_FALSE(r.budget_exhausted);
    ASSERT_EQ(r.lower_bound, r.distance);
    ASSERT_TRUE(r.triangles.has_value());
    this->expect_points_on_named_triangles(r, pose);
    // Distance 0 exactly when the exact intersection query finds a contact.
    EXPECT_EQ(r.distance == 0, query_exact(this->tree_a, this->tree_b, pose).collides);
    (r.distance == 0 ? touching : apart) += 1;
  }
  EXPECT_GT(touching, 3);
  EXPECT_GT(apart, 8);
}

TYPED_TEST_P(DistanceQuery, PrunesMostPairsWhenApart) {
  // Far apart, the bound must spare nearly all of the |A| x |B| triangle pairs a brute force tests.
  const RigidTransform pose = translated(RigidTransform{}, Vec3(3, 0.5, 0));
  const DistanceResult r = query_distance(this->tree_a, this->tree_b, pose);
  EXPECT_LT(r.counters.triangle_tests, this->a.triangles.size() * this->b.triangles.size() / 20);
}

TYPED_TEST_P(DistanceQuery, AnytimeIntervalHoldsTheDistanceAndClosesWithTheFullBudget) {
  for (const RigidTransform& pose : this->poses()) {
    const DistanceResult full = query_distance(this->tree_a, this->tree_b, pose);
    for (std::uint64_t cap : {1, 2, 5, 20, 100, 1000}) {
      const DistanceResult r = query_distance_anytime(this->tree_a, this->tree_b, pose, Budget{cap, 0});
      ASSERT_LE(r.lower_bound, full.distance) << "cap " << cap;
      ASSERT_GE(r.distance, full.distance) << "cap " << cap;
      ASSERT_LE(r.counters.bv_tests, cap);
      if (r.budget_exhausted) continue;
      ASSERT_EQ(r.distance, full.distance);
      ASSERT_TRUE(r.exact);
    }
    // The search needs no more than the full query's tests, and its dives (a few tests per level) take at
    // most a quarter of all, plus one dive's worth: twice the full query's and a dive suffice.
    const std::uint64_t dive = 2 * (this->tree_a.stats().depth + this->tree_b.stats().depth);
    const DistanceResult ample = query_distance_anytime(this->tree_a, this->tree_b, pose,
                                                        Budget{2 * full.counters.bv_tests + dive + 1, 0});
    EXPECT_EQ(ample.distance, full.distance);
    EXPECT_EQ(ample.lower_bound, full.distance);
  }
}

TYPED_TEST_P(DistanceQuery, AStoppedIntervalKeepsEveryAncestorsBound) {
  // A child pair is no nearer than its parent pair, so a stopped query's lower end is never below the
  // bound of the root pair (what a budget of one test answers), whatever the children's own bounds.
  int raised = 0;
  for (const RigidTransform& pose : this->poses()) {
    const double root = query_distance_anytime(this->tree_a, this->tree_b, pose, Budget{1, 0}).lower_bound;
    for (std::uint64_t cap : {2, 5, 10, 20, 40, 70, 100, 150}) {
      const DistanceResult r = query_distance_anytime(this->tree_a, this->tree_b, pose, Budget{cap, 0});
      ASSERT_GE(r.lower_bound, root) << "cap " << cap;
      raised += r.lower_bound > root;
    }
  }
  EXPECT_GT(raised, 0);  // the search lifts the lower end on some poses
}

TYPED_TEST_P(DistanceQuery, AStoppedSearchAnswersAFiniteUpperEndOnSurfacePoints) {
  // Even a budget spent before any leaf pair answers a pair of points on the two surfaces: the upper end is
  // their distance, not infinity.
  for (const RigidTransform& pose : this->poses()) {
    for (std::uint64_t cap : {1, 2, 3, 5}) {
      const DistanceResult r = query_distance_anytime(this->tree_a, this->tree_b, pose, Budget{cap, 0});
      ASSERT_TRUE(std::isfinite(r.distance)) << "cap " << cap;
      ASSERT_TRUE(r.triangles.has_value());
      this->expect_points_on_named_triangles(r, pose);
      EXPECT_LE(r.counters.bv_tests, cap);
    }
  }
}

TYPED_TEST_P(DistanceQuery, WithinToleranceAgreesWithTheDistance) {
  for (const RigidTransform& pose : this->poses()) {
    const double d = query_distance(this->tree_a, this->tree_b, pose).distance;
    EXPECT_EQ(query_within(this->tree_a, this->tree_b, pose, 0).collides, d == 0);
    if (d == 0) continue;
    for (double eps : {d * 0.5, std::nextafter(d, 0.0), d, d * 1.5}) {
      const Result r = query_within(this->tree_a, this->tree_b, pose, eps);
      ASSERT_EQ(r.collides, d <= eps) << "eps " << eps << " distance " << d;
      if (r.collides) {
        ASSERT_TRUE(r.witness.has_value());
        const TrianglePoints tb = this->b.triangle(r.witness->b);
        EXPECT_LE(triangle_distance(this->a.triangle(r.witness->a),
                                    {pose.apply(tb[0]), pose.apply(tb[1]), pose.apply(tb[2])})
                      .distance,
                  eps);
      }
    }
  }
}

TYPED_TEST_P(DistanceQuery, KeepsItsPrecisionFarFromTheOrigin) {
  // The same pair of objects, both moved 1e6 away. The query finds the brute force's distance there, and
  // that differs from the one at the origin by 1e-9 of it plus what moving the vertices and applying the pose
  // at 1e6 round (a few ulps of 1e6, about 1e-10 each): no precision is lost beyond the data's own.
  const Vec3 far(1e6, -1e6, 1e6);
  Mesh a_far = this->a, b_far = this->b;
  for (Vec3& v : a_far.vertices) v += far;
  for (Vec3& v : b_far.vertices) v += far;
  const auto tree_a = Bvh<TypeParam>::build(a_far);
  const auto tree_b = Bvh<TypeParam>::build(b_far);
  std::mt19937_64 rng(4);
  for (int k = 0; k < 4; ++k) {
    RigidTransform pose = testing::random_pose(rng, 0.1);
    pose.translation += Vec3(2.5, 0, 0);
    const double near_origin = query_distance(this->tree_a, this->tree_b, pose).distance;
    // B's frame maps into A's: moving both by `far` conjugates the pose.
    RigidTransform far_pose = pose;
    far_pose.translation = pose.translation + far - pose.rotation * far;
    const DistanceResult r = query_distance(tree_a, tree_b, far_pose);
    ASSERT_EQ(r.distance, brute_force_distance(a_far, b_far, far_pose)) << "pose " << k;
    const double data_rounding = 8 * std::nextafter(1e6, kInf) - 8e6;
    EXPECT_NEAR(r.distance, near_origin, 1e-9 * near_origin + data_rounding) << "pose " << k;
    EXPECT_NEAR((r.on_a - r.on_b).norm(), r.distance, 1e-9 * near_origin + data_rounding);
  }
}

/// A sequence of poses, each a small step from the last: where a coherent query has something to reuse.
inline std::vector<RigidTransform> small_steps() {
  std::vector<RigidTransform> out;
  for (int k = 0; k < 30; ++k)
    out.push_back(RigidTransform{Eigen::AngleAxisd(0.02 * k, Vec3(0, 0, 1)).toRotationMatrix(),
                                 Vec3(1.6 - 0.04 * k, 0.1, 0)});
  return out;
}

TYPED_TEST_P(DistanceQuery, CoherentQueriesAnswerAsColdOnesWithLessWork) {
  CoherentState distance_state, anytime_state, within_state;
  std::uint64_t cold_bv = 0, coherent_bv = 0;
  int touching = 0;
  for (const RigidTransform& pose : small_steps()) {
    const DistanceResult cold = query_distance(this->tree_a, this->tree_b, pose);
    const DistanceResult warm = query_distance_coherent(this->tree_a, this->tree_b, pose, distance_state);
    ASSERT_EQ(warm.distance, cold.distance);
    ASSERT_EQ(warm.lower_bound, cold.lower_bound);
    ASSERT_TRUE(warm.exact);
    EXPECT_NEAR((warm.on_a - warm.on_b).norm(), warm.distance, 1e-12);
    cold_bv += cold.counters.bv_tests;
    coherent_bv += warm.counters.bv_tests;
    touching += cold.distance == 0;
    // The anytime interval still holds the distance when the remembered pair seeds it.
    const DistanceResult stopped =
        query_distance_anytime_coherent(this->tree_a, this->tree_b, pose, Budget{10, 0}, anytime_state);
    ASSERT_LE(stopped.lower_bound, cold.distance);
    ASSERT_GE(stopped.distance, cold.distance);
    for (double eps : {0.0, cold.distance * 0.9, cold.distance * 1.1}) {
      const Result within = query_within_coherent(this->tree_a, this->tree_b, pose, eps, within_state);
      ASSERT_EQ(within.collides, cold.distance <= eps) << "eps " << eps;
    }
  }
  EXPECT_GT(touching, 0);  // the steps cross into contact
  EXPECT_LT(coherent_bv, cold_bv);
}

REGISTER_TYPED_TEST_SUITE_P(DistanceQuery, FindsTheNearestTrianglePairWithItsPoints, PrunesMostPairsWhenApart,
                            AnytimeIntervalHoldsTheDistanceAndClosesWithTheFullBudget,
                            AStoppedIntervalKeepsEveryAncestorsBound,
                            AStoppedSearchAnswersAFiniteUpperEndOnSurfacePoints,
                            WithinToleranceAgreesWithTheDistance, KeepsItsPrecisionFarFromTheOrigin,
                            CoherentQueriesAnswerAsColdOnesWithLessWork);

}  // namespace bvhlab::distance_tests
