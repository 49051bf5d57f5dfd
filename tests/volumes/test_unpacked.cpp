// Unpacked volumes (volumes/concept.hpp, UnpackedVolume): what a tree keeps beside its stored volumes must be
// their unpacked form after every change, and the tests on it must answer as on the stored volumes.
#include "bvh/bvh.hpp"
#include "support/generated_meshes.hpp"
#include "support/random_draws.hpp"
#include "volumes/obb.hpp"
#include "volumes/rss.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

namespace bvhlab {
namespace {

using testing::draw_vec3;
using testing::random_pose;

template <class U>
bool same_bytes(const U& a, const U& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

/// Every node's kept form is the unpacked stored volume, bit for bit.
template <class BV>
void expect_unpacked(const Bvh<BV>& tree, const char* after) {
  ASSERT_EQ(tree.nodes().size(), tree.volumes().size());
  for (std::uint32_t i = 0; i < tree.nodes().size(); ++i)
    ASSERT_TRUE(same_bytes(tree.tested_volume(i), BV::unpack(tree.volume(i))))
        << "node " << i << " after " << after;
}

template <class BV>
void expect_kept_through_changes() {
  const Mesh torus = testing::make_torus(1.0, 0.3, 24, 12);
  Bvh<BV> tree = Bvh<BV>::build(torus);
  expect_unpacked(tree, "the build");
  Mesh moved = torus;
  for (Vec3& v : moved.vertices) v = Vec3(1.5 * v.x(), v.y() + 0.2 * v.x() * v.x(), 0.7 * v.z());
  tree.refit(moved, RefitMethod::Merge);
  expect_unpacked(tree, "a refit by merging");
  tree.refit(torus, RefitMethod::Fit);
  expect_unpacked(tree, "a refit by fitting");
  const Bvh<BV> loaded = Bvh<BV>::from_parts(tree.nodes(), tree.volumes(), tree.triangle_ids());
  expect_unpacked(loaded, "from_parts");
  EXPECT_EQ(tree.stats().bytes_per_node, sizeof(TreeNode) + sizeof(BV) + sizeof(typename BV::Unpacked));
}

TEST(UnpackedObb, TheTreeKeepsTheUnpackedFormOfEveryVolume) {
  expect_kept_through_changes<Obb>();
}

TEST(UnpackedRss, TheTreeKeepsTheUnpackedFormOfEveryVolume) {
  expect_kept_through_changes<Rss>();
}

/// 20,000 pairs of volumes around random point sets, in random poses: on each, the unpacked forms must answer
/// and bound as the stored ones, and `more(a, b, context, stored)` checks what else the volume offers. Both
/// answers must come up often. The stored overloads unpack and call the unpacked ones, so this guards the
/// two against drifting apart; a wrong unpack() itself fails the CGAL checks of test_rss and the conformance
/// suite (tried: half-lengths swapped in Rss::unpack failed 6 of them).
template <class BV, class More>
void expect_same_answers(std::uint64_t seed, More more) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  int overlapping = 0, apart = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 pa[6], pb[6];
    const Vec3 ca = draw_vec3(u, rng), cb = draw_vec3(u, rng);
    for (int p = 0; p < 6; ++p) pa[p] = ca + 0.5 * draw_vec3(u, rng), pb[p] = cb + 0.5 * draw_vec3(u, rng);
    const BV a = BV::fit(pa), b = BV::fit(pb);
    const auto context = BV::make_context(random_pose(rng, 0.5));
    const bool stored = BV::overlap(a, b, context);
    ASSERT_EQ(BV::overlap(BV::unpack(a), BV::unpack(b), context), stored) << k;
    ASSERT_EQ(BV::distance_lower_bound(BV::unpack(a), BV::unpack(b), context),
              BV::distance_lower_bound(a, b, context))
        << k;
    more(a, b, context, stored);
    if (::testing::Test::HasFatalFailure()) return;
    (stored ? overlapping : apart)++;
  }
  EXPECT_GT(overlapping, 1000);
  EXPECT_GT(apart, 1000);
}

TEST(UnpackedObb, AnswersPlacesAndBoundsAsTheStoredBoxes) {
  expect_same_answers<Obb>(17, [](const Obb& a, const Obb& b, const Obb::PairContext& context, bool stored) {
    PlacedBoxes from_stored, from_unpacked;
    ASSERT_EQ(Obb::overlap(a, b, context, from_stored), stored);
    ASSERT_EQ(Obb::overlap(Obb::unpack(a), Obb::unpack(b), context, from_unpacked), stored);
    ASSERT_EQ(from_stored.half_a, from_unpacked.half_a);
    ASSERT_EQ(from_stored.half_b, from_unpacked.half_b);
    ASSERT_EQ(from_stored.b_in_a.rotation, from_unpacked.b_in_a.rotation);
    ASSERT_EQ(from_stored.b_in_a.translation, from_unpacked.b_in_a.translation);
  });
}

TEST(UnpackedRss, AnswersAndBoundsAsTheStoredVolumes) {
  expect_same_answers<Rss>(19, [](const Rss&, const Rss&, const Rss::PairContext&, bool) {});
  // An empty volume overlaps nothing and bounds nothing, unpacked or not.
  const Rss empty, some = Rss::fit(std::array<Vec3, 1>{Vec3::Zero()});
  const auto context = Rss::make_context(RigidTransform{});
  EXPECT_FALSE(Rss::overlap(Rss::unpack(empty), Rss::unpack(some), context));
  EXPECT_EQ(Rss::distance_lower_bound(Rss::unpack(some), Rss::unpack(empty), context),
            Rss::distance_lower_bound(some, empty, context));
}

}  // namespace
}  // namespace bvhlab
