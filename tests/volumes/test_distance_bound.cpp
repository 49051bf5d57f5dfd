// Distance lower bounds of the bounding volumes (volumes/concept.hpp, `DistanceVolume`; issue #38): never
// above the distance of the points a volume holds, 0 exactly where overlap() is true, useful for separated
// objects, and computed as precisely at coordinates around 1e6 as at the origin. The restricted boxtree has
// no bound (a distance strategy refuses it by name).
#include "support/random_clouds.hpp"
#include "support/test_volumes.hpp"
#include "support/volume_lists.hpp"
#include "volumes/obb4.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

namespace bvhlab::distance_tests {
namespace {

using testing::diameter_of;
using testing::log_uniform;
using testing::mean_of;
using testing::point_distance;
using testing::random_cloud;
using testing::random_direction;
using testing::random_pose_rotation;

// ---------------------------------------------------------------------------------------------------------
// Which models have the bound (compile time).

static_assert(!DistanceVolume<RestrictedBox>, "the restricted boxtree is hierarchical: no distance bound");
static_assert(HierarchicalVolume<RestrictedBox> && DistanceVolume<RestrictedBox::Decoded>);
static_assert(BoundingVolume<testing::Capsule> && !DistanceVolume<testing::Capsule>,
              "the bound is an optional refinement: a volume without it is still a BoundingVolume");

template <class BV>
struct HasDistanceBound : std::bool_constant<DistanceVolume<BV>> {};
/// Every shipped model with the bound: Aabb, the k-DOPs, Obb, Sphere. The sanitizer builds keep one k-DOP for
/// the family, as the typed traversal tests do (support/volume_lists.hpp): the k-DOPs share one template, and
/// the four others would add about 16 s to the ASan stage.
#ifdef BVHLAB_LEAN_VOLUMES
using DistanceVolumes = ::testing::Types<Aabb, Dop24, Obb, Sphere>;
#else
using DistanceVolumes = testing::SelectTypes<HasDistanceBound, ShippedVolumes>::type;
#endif
static_assert(DistanceVolume<Aabb> && DistanceVolume<Obb> && DistanceVolume<Sphere> &&
              DistanceVolume<Dop<6>> && DistanceVolume<Dop<14>> && DistanceVolume<Dop<18>> &&
              DistanceVolume<Dop24> && DistanceVolume<Dop<26>>);

struct VolumeName {
  template <class BV>
  static std::string GetName(int) {
    return std::string(BV::name());
  }
};

template <class BV>
class DistanceBound : public ::testing::Test {};
TYPED_TEST_SUITE(DistanceBound, DistanceVolumes, VolumeName);

// ---------------------------------------------------------------------------------------------------------
// Random clouds and poses.

constexpr double kEps = std::numeric_limits<double>::epsilon();

/// Two clouds (A's in A's frame, B's in B's) and the pose mapping B's frame into A's.
struct Pair {
  std::vector<Vec3> a, b;
  RigidTransform pose;
};

/// Clouds of sizes 1e-3 to 1e3, centred near the origin or (one pair in four) at coordinates around 1e6
/// in their own frames, placed from overlapping to far apart (centre distance 0 to 30 times the sizes).
/// One pair in eight is two single points apart along one of A's axes (or, for half of them, any
/// direction), where box and DOP bounds equal the distance up to their slack (sphere and OBB bounds too
/// when the points sit at their frames' origins): a bound that left out its slack would exceed it.
Pair random_pair(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0, 1);
  auto center = [&](double scale) -> Vec3 {
    if (unit(rng) < 0.25) {
      Vec3 far;
      for (int k = 0; k < 3; ++k) far[k] = (rng() % 2 ? 1e6 : -1e6) * (1 + 0.1 * unit(rng));
      return far;
    }
    if (unit(rng) < 0.1) return Vec3::Zero();
    return scale * log_uniform(rng, -1, 2) * random_direction(rng);
  };
  const double scale_a = log_uniform(rng, -3, 3), scale_b = log_uniform(rng, -3, 3);
  Pair pair;
  if (unit(rng) < 0.125) {
    // Float coordinates: the volumes store them without widening, so nothing but the slack separates the
    // bound from the distance (the pose's translation still rounds).
    auto in_float = [](const Vec3& v) {
      return Vec3(rounded_to_float(v.x()), rounded_to_float(v.y()), rounded_to_float(v.z()));
    };
    pair.a = {in_float(center(scale_a))};
    pair.b = {in_float(center(scale_b))};
    pair.pose.rotation = random_pose_rotation(rng);
    Vec3 direction = Vec3::Zero();
    direction[rng() % 3] = rng() % 2 ? 1 : -1;
    if (unit(rng) < 0.5) direction = random_direction(rng);
    pair.pose.translation = pair.a[0] + scale_a * direction - pair.pose.rotation * pair.b[0];
    return pair;
  }
  pair.a = random_cloud(rng, center(scale_a), scale_a);
  pair.b = random_cloud(rng, center(scale_b), scale_b);
  pair.pose.rotation = random_pose_rotation(rng);
  const double separation = unit(rng) < 0.2 ? 0 : (scale_a + scale_b) * log_uniform(rng, -1.5, 1.5);
  pair.pose.translation =
      mean_of(pair.a) + separation * random_direction(rng) - pair.pose.rotation * mean_of(pair.b);
  return pair;
}

// ---------------------------------------------------------------------------------------------------------
// Conservative: never above the distance of the contained points, never negative.

TYPED_TEST(DistanceBound, NeverExceedsThePointDistance) {
  using BV = TypeParam;
  std::mt19937_64 rng(38);
  int positive = 0;
  double tightest = 0;
  constexpr int kCases = 10000;
  for (int k = 0; k < kCases; ++k) {
    const Pair pair = random_pair(rng);
    const BV a = BV::fit(pair.a), b = BV::fit(pair.b);
    for (const Vec3& p : pair.a) ASSERT_TRUE(a.contains(p)) << "case " << k;
    for (const Vec3& q : pair.b) ASSERT_TRUE(b.contains(q)) << "case " << k;
    const double bound = BV::distance_lower_bound(a, b, BV::make_context(pair.pose));
    double magnitude = 0;
    const double distance = point_distance(pair.a, pair.b, pair.pose, &magnitude);
    ASSERT_GE(bound, 0) << "case " << k;
    // Rounding the long double distance to double moves it by half an ulp; its own rounding is ~1e-19.
    ASSERT_LE(bound, distance + kEps * distance + 1e-17 * magnitude)
        << "case " << k << ": bound " << bound << " > point distance " << distance << " (by "
        << (bound - distance) / distance << " relative)";
    positive += bound > 0;
    if (distance > 0) tightest = std::max(tightest, bound / distance);
  }
  // Not vacuous: most separated pairs get a positive bound, and some come close to the distance.
  EXPECT_GT(positive, kCases / 3);
  std::printf("[ measured ] %s: %d of %d bounds positive, largest bound / distance 1 - %.1e\n",
              std::string(BV::name()).c_str(), positive, kCases, 1 - tightest);
}

// ---------------------------------------------------------------------------------------------------------
// Consistent with overlap(): bound > 0 implies overlap() is false, i.e. where overlap() is true the bound is
// 0. Why that is right: a positive bound proves the volumes apart (no point of a within that distance of a
// point of b), so answering false there loses no contact; and a conservative overlap() may say true for
// volumes that are apart, so the implication is a contract, not a consequence: each model builds its bound
// from overlap()'s own gaps and slack, and a traversal that mixes the two tests must not see them disagree
// about a pair. Checked on random pairs and, where a disagreement would hide, along bisections to the pose
// where overlap() flips.

template <class BV>
void expect_consistent(const BV& a, const BV& b, const RigidTransform& pose, int& overlapping, int& positive,
                       const char* where, int k) {
  const auto context = BV::make_context(pose);
  const bool overlap = BV::overlap(a, b, context);
  const double bound = BV::distance_lower_bound(a, b, context);
  if (overlap) {
    ++overlapping;
    ASSERT_EQ(bound, 0) << where << " case " << k << ": overlap() is true, the bound is " << bound;
  }
  if (bound > 0) {
    ++positive;
    ASSERT_FALSE(overlap) << where << " case " << k;
  }
}

TYPED_TEST(DistanceBound, ZeroExactlyWhereOverlapIsTrue) {
  using BV = TypeParam;
  std::mt19937_64 rng(3838);
  int overlapping = 0, positive = 0, evaluations = 0;
  for (int k = 0; k < 4000; ++k, ++evaluations) {
    const Pair pair = random_pair(rng);
    expect_consistent(BV::fit(pair.a), BV::fit(pair.b), pair.pose, overlapping, positive, "random", k);
    if (this->HasFatalFailure()) return;
  }
  // Bisection along a random direction from concentric (overlapping) to far apart, to the last
  // representable step; both sides of the flip are checked, and every pose on the way.
  int flips = 0;
  for (int k = 0; k < 600; ++k) {
    Pair pair = random_pair(rng);
    const BV a = BV::fit(pair.a), b = BV::fit(pair.b);
    const Vec3 direction = random_direction(rng);
    const Vec3 start = mean_of(pair.a) - pair.pose.rotation * mean_of(pair.b);
    const double far = 4 * (diameter_of(pair.a) + diameter_of(pair.b)) + 1e-6 * start.norm() + 1e-300;
    auto at = [&](double s) {
      RigidTransform pose = pair.pose;
      pose.translation = start + s * direction;
      return pose;
    };
    if (!BV::overlap(a, b, BV::make_context(at(0))) || BV::overlap(a, b, BV::make_context(at(far)))) continue;
    double lo = 0, hi = far;  // overlap at lo, not at hi
    for (int step = 0; step < 200; ++step) {
      const double mid = 0.5 * (lo + hi);
      if (mid == lo || mid == hi) break;
      const RigidTransform pose = at(mid);
      ++evaluations;
      expect_consistent(a, b, pose, overlapping, positive, "bisection", k);
      if (this->HasFatalFailure()) return;
      (BV::overlap(a, b, BV::make_context(pose)) ? lo : hi) = mid;
    }
    expect_consistent(a, b, at(lo), overlapping, positive, "last overlapping", k);
    expect_consistent(a, b, at(hi), overlapping, positive, "first apart", k);
    evaluations += 2;
    ++flips;
  }
  EXPECT_GT(overlapping, evaluations / 10);
  EXPECT_GT(positive, evaluations / 10);
  EXPECT_GT(flips, 300);
  std::printf(
      "[ measured ] %s: %d poses (%d bisections to the flip): overlap() true in %d, bound > 0 in %d\n",
      std::string(BV::name()).c_str(), evaluations, flips, overlapping, positive);
}

// ---------------------------------------------------------------------------------------------------------
// The cutoff form (distance_lower_bound_below, volumes/concept.hpp), on the form the traversals test: below
// the cutoff the same bound, bit for bit; at or past it a bound of at least the cutoff, never above the full
// one (but for the rounding of a square root). Volumes without a cutoff of their own answer the full bound;
// for the OBB and the RSS some pairs must take the shortcut, or the check would be vacuous (the RSS's only
// near contact, where its separation step finds no gap: 51 pairs of these 12,000, the OBB's 153).

template <class BV>
auto tested_form(const BV& v) {
  if constexpr (UnpackedVolume<BV>)
    return BV::unpack(v);
  else
    return v;
}

TYPED_TEST(DistanceBound, ACutoffChangesOnlyTheBoundsPastIt) {
  using BV = TypeParam;
  std::mt19937_64 rng(3939);
  std::uniform_real_distribution<double> unit(0, 1);
  int shortcuts = 0;
  for (int k = 0; k < 3000; ++k) {
    const Pair pair = random_pair(rng);
    const auto a = tested_form(BV::fit(pair.a)), b = tested_form(BV::fit(pair.b));
    const auto context = BV::make_context(pair.pose);
    const double full =
        distance_lower_bound_below<BV>(a, b, context, std::numeric_limits<double>::infinity());
    ASSERT_EQ(full, BV::distance_lower_bound(BV::fit(pair.a), BV::fit(pair.b), context)) << "case " << k;
    for (const double share : {0.5 * unit(rng), 1.0, 1 + unit(rng), 4.0}) {
      const double cutoff = full * share;
      const double bound = distance_lower_bound_below<BV>(a, b, context, cutoff);
      if (full < cutoff) {
        ASSERT_EQ(bound, full) << "case " << k << ", cutoff " << cutoff;
      } else {
        ASSERT_GE(bound, cutoff) << "case " << k << ", full bound " << full;
        ASSERT_LE(bound, full + 4 * kEps * full) << "case " << k << ", cutoff " << cutoff;
        shortcuts += bound != full;
      }
    }
  }
  if constexpr (std::is_same_v<BV, Obb> || std::is_same_v<BV, Rss>) {
    EXPECT_GT(shortcuts, 20);
  }
  std::printf("[ measured ] %s: %d bounds past the cutoff answered short of the full bound\n",
              std::string(BV::name()).c_str(), shortcuts);
}

// ---------------------------------------------------------------------------------------------------------
// Useful: for clouds apart by at least 3 times the sum of their diameters, the bound is a fair part of the
// distance D. The floors are about half the smallest ratio measured here (boxes and 6-DOPs 0.55 to 0.57, the
// other DOPs 0.78 to 0.85, OBBs 0.68, spheres 0.86): a bound of 0, or one twice as loose, fails. For spheres
// the floor holds in the worst case too: the bound is at least D - 2 (r_a + r_b), a fitted radius is at most
// half the bounding box's diagonal (sqrt(3) / 2 of the diameter), so the bound is >= (1 - sqrt(3) / 3) D.

template <class BV>
double useful_floor() {
  if constexpr (std::is_same_v<BV, Aabb> || std::is_same_v<BV, Dop<6>>) return 0.25;
  return 0.4;
}

TYPED_TEST(DistanceBound, UsefulForSeparatedClouds) {
  using BV = TypeParam;
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<double> ratios;
  while (ratios.size() < 3000) {
    // Centres within 100 sizes of the frame's origin: the volumes store floats, whose resolution follows
    // the coordinates, not the cloud (the far frames are the invariance test's).
    const double scale_a = log_uniform(rng, -3, 3), scale_b = scale_a * log_uniform(rng, -1, 1);
    Pair pair;
    pair.a = random_cloud(rng, scale_a * log_uniform(rng, -1, 2) * random_direction(rng), scale_a);
    pair.b = random_cloud(rng, scale_b * log_uniform(rng, -1, 2) * random_direction(rng), scale_b);
    const double diameters = diameter_of(pair.a) + diameter_of(pair.b);
    if (diameters == 0) continue;
    pair.pose.rotation = random_pose_rotation(rng);
    // Centre distance 3.5 to 10 times the diameters (the point distance is then at least ~3 times them).
    pair.pose.translation = mean_of(pair.a) + diameters * (3.5 + 6.5 * unit(rng)) * random_direction(rng) -
                            pair.pose.rotation * mean_of(pair.b);
    const double distance = point_distance(pair.a, pair.b, pair.pose);
    if (distance < 3 * diameters) continue;
    const BV a = BV::fit(pair.a), b = BV::fit(pair.b);
    const double bound = BV::distance_lower_bound(a, b, BV::make_context(pair.pose));
    ASSERT_GE(bound, useful_floor<BV>() * distance)
        << "case " << ratios.size() << ": bound " << bound << ", point distance " << distance
        << ", diameters " << diameters;
    ratios.push_back(bound / distance);
  }
  std::sort(ratios.begin(), ratios.end());
  const double median = ratios[ratios.size() / 2];
  std::printf("[ measured ] %s: bound / distance over %zu separated pairs: median %.3f, minimum %.3f\n",
              std::string(BV::name()).c_str(), ratios.size(), median, ratios.front());
  ::testing::Test::RecordProperty("median_ratio", std::to_string(median));
  ::testing::Test::RecordProperty("min_ratio", std::to_string(ratios.front()));
}

// ---------------------------------------------------------------------------------------------------------
// Translation invariance: the same two volumes, once at the origin and once at coordinates around 1e6 in
// their frames (the pose moved to match), give the same bound within 1e-6 relative for a distance about 1.
// "The same volumes": fitting at 1e6 stores floats spaced 1/16 there, which alone would move the bound by
// about 0.1; so the volumes are fitted at 1e6 and moved back to the origin exactly (box corners, centres
// minus integer offsets are exact in float), or for a DOP by 1 float ulp of its small offsets (rounded
// outwards). What remains is the bound's own arithmetic and slack at large coordinates.

template <class BV>
BV moved_back(const BV& v, const Vec3& offset) {
  auto exact = [](double x) {
    const float f = rounded_to_float(x);
    EXPECT_EQ(double(f), x) << "moving back is not exact";
    return f;
  };
  BV out = v;
  if constexpr (std::is_same_v<BV, Aabb>) {
    for (int k = 0; k < 3; ++k) {
      out.lo[k] = exact(double(v.lo[k]) - offset[k]);
      out.hi[k] = exact(double(v.hi[k]) - offset[k]);
    }
  } else if constexpr (std::is_same_v<BV, Sphere> || std::is_same_v<BV, Obb> || std::is_same_v<BV, Rss>) {
    for (int k = 0; k < 3; ++k) out.center[k] = exact(double(v.center[k]) - offset[k]);
  } else {
    // offsets[a] >= n_a . x and offsets[a + k/2] >= -n_a . x: moving every x by -offset moves the first by
    // -n_a . offset and the second by +n_a . offset.
    const auto& axes = BV::tables().axes;
    for (std::size_t axis = 0; axis < BV::kAxes; ++axis) {
      const double shift = axes[axis].dot(offset);
      out.offsets[axis] = float_up(double(v.offsets[axis]) - shift);
      out.offsets[axis + BV::kAxes] = float_up(double(v.offsets[axis + BV::kAxes]) + shift);
    }
  }
  return out;
}

/// 1e-6 relative for boxes and spheres: their slack at coordinates 1e6 is a few 1e-8, and an OBB divides it
/// by an axis length of at least 0.1 (obb.hpp, kMinEdgeAxis), which keeps it below 7e-7. A DOP's overlap
/// slack, which its bound subtracts too, is 512 ulps of each side's coordinates and of the translation
/// (kdop.hpp, make_context): about 1.5e-6 at coordinates 1e6 (measured: up to 1.5e-6 relative at distances
/// 0.8 to 1.6); 4e-6 leaves it a margin.
template <class BV>
double invariance_tolerance() {
  if constexpr (std::is_same_v<BV, Aabb> || std::is_same_v<BV, Obb> || std::is_same_v<BV, Sphere> ||
                std::is_same_v<BV, Rss>)
    return 1e-6;
  return 4e-6;
}

TYPED_TEST(DistanceBound, SameAtCoordinatesAround1e6) {
  using BV = TypeParam;
  std::mt19937_64 rng(1000000);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> jitter(-1000, 1000);
  auto far_offset = [&] {
    Vec3 o;
    for (int k = 0; k < 3; ++k) o[k] = (rng() % 2 ? 1 : -1) * (1e6 + jitter(rng));
    return o;
  };
  double worst = 0;
  int cases = 0, positive = 0;
  while (cases < 1000) {
    // Clouds of size 0.02 to 0.1 about their frames' origins, about 1 apart.
    Pair pair;
    pair.a = random_cloud(rng, Vec3::Zero(), 0.02 + 0.08 * unit(rng));
    pair.b = random_cloud(rng, Vec3::Zero(), 0.02 + 0.08 * unit(rng));
    pair.pose.rotation = random_pose_rotation(rng);
    pair.pose.translation = (1 + 0.5 * unit(rng)) * random_direction(rng);
    const double distance = point_distance(pair.a, pair.b, pair.pose);
    if (distance < 0.8 || distance > 1.6) continue;
    ++cases;
    const Vec3 offset_a = far_offset(), offset_b = far_offset();
    std::vector<Vec3> far_a, far_b;
    for (const Vec3& p : pair.a) far_a.push_back(p + offset_a);
    for (const Vec3& q : pair.b) far_b.push_back(q + offset_b);
    RigidTransform far_pose = pair.pose;
    far_pose.translation = pair.pose.translation + offset_a - pair.pose.rotation * offset_b;
    const BV a_far = BV::fit(far_a), b_far = BV::fit(far_b);
    const BV a = moved_back(a_far, offset_a), b = moved_back(b_far, offset_b);
    const double near_bound = BV::distance_lower_bound(a, b, BV::make_context(pair.pose));
    const double far_bound = BV::distance_lower_bound(a_far, b_far, BV::make_context(far_pose));
    positive += near_bound > 0;
    // Both are bounds of the same distance (the far points are rounded by about 1e-10).
    ASSERT_LE(near_bound, distance + 1e-9) << "case " << cases;
    ASSERT_LE(far_bound, distance + 1e-9) << "case " << cases;
    const double relative = std::abs(far_bound - near_bound) / distance;
    ASSERT_LE(relative, invariance_tolerance<BV>())
        << "case " << cases << ": at the origin " << near_bound << ", at 1e6 " << far_bound;
    worst = std::max(worst, relative);
  }
  EXPECT_GT(positive, cases * 9 / 10);  // not vacuous: the bounds compared are mostly positive
  std::printf("[ measured ] %s: largest relative change of the bound at coordinates 1e6: %.2e\n",
              std::string(BV::name()).c_str(), worst);
}

// ---------------------------------------------------------------------------------------------------------
// The oriented boxes' four-lane bound (Obb4::distance_bounds, the wide distance walk's): one box of A against
// four of B, placed as the walk places them, lanes stored relative to origins near the clouds (as a wide
// tree stores them, also at coordinates around 1e6). Never above the lane's point distance, the vector
// path equal to the scalar reference, positive only where the four-lane overlap test parts the lane, and
// infinite for an empty lane.

TEST(ObbLanes, DistanceBoundsNeverExceedThePointDistance) {
  std::mt19937_64 rng(3804);
  std::uniform_real_distribution<double> unit(-1, 1);
  int positive = 0, lanes = 0;
  double tightest = 0;
  for (int round = 0; round < 2500; ++round) {
    const Pair pair = random_pair(rng);
    const Obb box_a = Obb::fit(pair.a);
    const Vec3 origin_a = box_a.bounding_box().center(), origin_b = Obb::fit(pair.b).bounding_box().center();
    Obb4 a, b;
    a.set(0, box_a, origin_a);
    a = Obb4::broadcast(a, 0);
    std::array<std::vector<Vec3>, 4> clouds;  // B's lanes: the cloud, moved by up to its own size
    const double size = diameter_of(pair.b) + 1e-3;
    for (int k = 0; k < 4; ++k) {
      const Vec3 shift(size * unit(rng), size * unit(rng), size * unit(rng));
      for (const Vec3& q : pair.b) clouds[k].push_back(q + (k == 0 ? Vec3::Zero() : shift));
      if (round % 7 != k) b.set(k, Obb::fit(clouds[k]), origin_b);  // now and then a lane stays empty
    }
    const auto context = Obb4::make_context(pair.pose, origin_a, origin_b);
    const Obb4 placed = Obb4::place(b, context);
    const auto bounds = Obb4::distance_bounds(a, placed, context);
    ASSERT_EQ(bounds, Obb4::distance_bounds_scalar(a, placed, context)) << "round " << round;
    // The walk's steps, which build no broadcast or placed Obb4, answer alike: lane 0 of A's node against
    // B's four placed, and four A lanes (here A's one, broadcast) against each placed B lane.
    ASSERT_EQ(bounds, Obb4::distance_bounds_to_b(a, 0, b, context)) << "round " << round;
    for (int k = 0; k < 4; ++k)
      ASSERT_EQ(Obb4::distance_bounds_to_a(a, b, k, context)[0], bounds[k]) << "round " << round << " " << k;
    const unsigned overlapping = Obb4::overlap_placed(a, placed, context);
    for (int k = 0; k < 4; ++k) {
      if (b.empty(k)) {
        ASSERT_EQ(bounds[k], std::numeric_limits<float>::infinity()) << "round " << round << " lane " << k;
        continue;
      }
      ++lanes;
      double magnitude = 0;
      const double distance = point_distance(pair.a, clouds[k], pair.pose, &magnitude);
      ASSERT_GE(bounds[k], 0) << "round " << round << " lane " << k;
      ASSERT_LE(bounds[k], distance + kEps * distance + 1e-17 * magnitude)
          << "round " << round << " lane " << k << ": bound " << bounds[k] << " > point distance "
          << distance;
      if (bounds[k] > 0) {
        ++positive;
        ASSERT_FALSE(overlapping & (1u << k)) << "round " << round << " lane " << k;
      }
      if (distance > 0) tightest = std::max(tightest, bounds[k] / distance);
    }
  }
  EXPECT_GT(positive, lanes / 3);
  EXPECT_GT(tightest, 0.9);  // not vacuous: some bounds come close to the distance
  std::printf("[ measured ] obb lanes: %d of %d bounds positive, largest bound / distance 1 - %.1e\n",
              positive, lanes, 1 - tightest);
}

}  // namespace
}  // namespace bvhlab::distance_tests
