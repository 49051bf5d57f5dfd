// The density-update policies (adb/update.hpp) on a small twisting torus, each against an exact recount.
#include "adb/update.hpp"
#include "support/generated_meshes.hpp"
#include "volumes/aabb.hpp"
#include "volumes/obb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace bvhlab {
namespace {

const AnnotationContext kOneThread{1, {}};

/// The mesh twisted about the x axis: the slice at x turns by angle * x.
Mesh twisted(const Mesh& rest, double angle) {
  Mesh out = rest;
  for (Vec3& v : out.vertices) {
    const double a = angle * v.x(), c = std::cos(a), s = std::sin(a);
    v = Vec3(v.x(), c * v.y() - s * v.z(), s * v.y() + c * v.z());
  }
  return out;
}

/// Only the part beyond x = 0.6 bends (upwards).
Mesh bent_at_one_end(const Mesh& rest) {
  Mesh out = rest;
  for (Vec3& v : out.vertices) v.z() += 0.3 * std::max(0.0, v.x() - 0.6);
  return out;
}

Mesh translated(const Mesh& rest, const Vec3& by) {
  Mesh out = rest;
  for (Vec3& v : out.vertices) v += by;
  return out;
}

struct DensityUpdateTest : ::testing::Test {
  Mesh rest = testing::make_torus(1.0, 0.35, 32, 16);
  Tree<Aabb, AdbDensity> tree = annotate_adb(Bvh<Aabb>::build(rest), 2, kDefaultAdbTau, kOneThread);

  /// The exact counts of `bvh` as it is, annotated from scratch.
  static std::vector<std::uint8_t> exact(const Bvh<Aabb>& bvh) {
    return annotate_adb(bvh, 2, kDefaultAdbTau, kOneThread).density.possible_collision_cells;
  }
  static double mean_difference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.size(); ++i) sum += std::abs(int(a[i]) - int(b[i]));
    return sum / static_cast<double>(a.size());
  }
};

TEST_F(DensityUpdateTest, RecountAllEqualsAnnotatingAnew) {
  auto state = RecountAllUpdate::start(tree.bvh, tree.density, {});
  const auto before = tree.density.possible_collision_cells;
  tree.bvh.refit(twisted(rest, 0.8));
  DensityUpdateStats stats;
  RecountAllUpdate::update(tree.bvh, tree.density, state, kOneThread, &stats);
  const auto expected = exact(tree.bvh);
  EXPECT_NE(before, expected);  // the twist changes counts: otherwise the test proves nothing
  EXPECT_EQ(tree.density.possible_collision_cells, expected);
  EXPECT_EQ(stats.recounted_nodes, tree.bvh.nodes().size());
}

TEST_F(DensityUpdateTest, RecountMovedWithFractionZeroIsExact) {
  auto state =
      RecountMovedUpdate::start(tree.bvh, tree.density, update_params<RecountMovedUpdate>({{"fraction", 0}}));
  for (const double angle : {0.3, 0.8}) {  // two frames: the second starts from the first's counts
    tree.bvh.refit(twisted(rest, angle));
    DensityUpdateStats stats;
    RecountMovedUpdate::update(tree.bvh, tree.density, state, kOneThread, &stats);
    EXPECT_EQ(tree.density.possible_collision_cells, exact(tree.bvh)) << "angle " << angle;
    EXPECT_EQ(stats.recounted_nodes, tree.bvh.nodes().size());
  }
}

TEST_F(DensityUpdateTest, WithoutMotionEveryPolicyKeepsTheCounts) {
  with_each_density_update([&](auto type) {
    using U = typename decltype(type)::type;
    Tree<Aabb, AdbDensity> copy = tree;
    auto state = U::start(copy.bvh, copy.density, update_params<U>());
    copy.bvh.refit(rest);
    DensityUpdateStats stats;
    U::update(copy.bvh, copy.density, state, kOneThread, &stats);
    EXPECT_EQ(copy.density.possible_collision_cells, tree.density.possible_collision_cells) << U::name();
    if constexpr (std::is_same_v<U, RecountMovedUpdate>) {
      EXPECT_EQ(stats.recounted_nodes, 0u);
    }
  });
}

TEST_F(DensityUpdateTest, RecountMovedRecountsExactlyTheMovedNodes) {
  auto state = RecountMovedUpdate::start(tree.bvh, tree.density, update_params<RecountMovedUpdate>());
  const auto before = tree.density.possible_collision_cells;
  tree.bvh.refit(bent_at_one_end(rest));
  const auto moved = RecountMovedUpdate::moved_nodes(state, tree.bvh.node_boxes(), 2);
  ASSERT_GT(moved.size(), 0u);
  ASSERT_LT(moved.size(), tree.bvh.nodes().size());
  RecountMovedUpdate::update(tree.bvh, tree.density, state, kOneThread, nullptr);
  const auto expected = exact(tree.bvh);
  std::vector<bool> recounted(expected.size(), false);
  for (const std::uint32_t i : moved) recounted[i] = true;
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_EQ(tree.density.possible_collision_cells[i], recounted[i] ? expected[i] : before[i])
        << "node " << i;
}

TEST_F(DensityUpdateTest, RecountMovedMeasuresMotionSinceEachNodesLastCount) {
  auto state = RecountMovedUpdate::start(tree.bvh, tree.density, update_params<RecountMovedUpdate>());
  const Vec3 step(0.01, 0, 0);
  tree.bvh.refit(translated(rest, step));
  const auto first = RecountMovedUpdate::moved_nodes(state, tree.bvh.node_boxes(), 2);
  RecountMovedUpdate::update(tree.bvh, tree.density, state, kOneThread, nullptr);
  tree.bvh.refit(translated(rest, 2 * step));
  const auto second = RecountMovedUpdate::moved_nodes(state, tree.bvh.node_boxes(), 2);
  // Nodes left alone the first time have now drifted twice as far; the recounted ones moved one step again.
  EXPECT_GT(first.size(), 0u);
  EXPECT_GT(second.size(), first.size());
  EXPECT_TRUE(std::includes(second.begin(), second.end(), first.begin(), first.end()));

  auto still = RecountMovedUpdate::start(tree.bvh, tree.density,
                                         update_params<RecountMovedUpdate>({{"ignore_translation", 1}}));
  tree.bvh.refit(translated(rest, 5 * step));
  EXPECT_TRUE(RecountMovedUpdate::moved_nodes(still, tree.bvh.node_boxes(), 2).empty());
}

TEST_F(DensityUpdateTest, SampledCountsApproachTheExactOnesAsSamplesGrow) {
  const Mesh deformed = twisted(rest, 0.8);
  Bvh<Aabb> moved = tree.bvh;
  moved.refit(deformed);
  const auto expected = exact(moved);
  auto error = [&](double per_triangle, int from_rest) {
    double sum = 0;
    for (const int seed : {1, 2, 3}) {
      Tree<Aabb, AdbDensity> copy = tree;
      auto state = SampledUpdate::start(
          copy.bvh, copy.density,
          update_params<SampledUpdate>(
              {{"per_triangle", per_triangle}, {"seed", seed}, {"from_rest", from_rest}}));
      copy.bvh.refit(deformed);
      SampledUpdate::update(copy.bvh, copy.density, state, kOneThread, nullptr);
      sum += mean_difference(copy.density.possible_collision_cells, expected);
    }
    return sum / 3;
  };
  const double coarse = error(1, 0), fine = error(64, 0);
  EXPECT_GT(coarse, 0.0);
  EXPECT_LT(fine, 0.5 * coarse) << "1 sample per triangle: " << coarse << ", 64: " << fine;
  EXPECT_LT(error(64, 1), error(1, 1));  // relative to the rest shape: less gain for a large twist
  const double stale = mean_difference(tree.density.possible_collision_cells, expected);
  EXPECT_LT(error(16, 1), stale);  // better than not updating at all
}

TEST_F(DensityUpdateTest, ParametersOutOfRangeAreRefusedByName) {
  auto refused = [](auto call, const std::string& policy, const std::string& parameter) {
    try {
      call();
      ADD_FAILURE() << policy << " " << parameter << " accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(policy), std::string::npos) << what;
      EXPECT_NE(what.find(parameter), std::string::npos) << what;
    }
  };
  refused([] { update_params<RecountMovedUpdate>({{"fraction", -0.1}}); }, "recount_moved", "fraction");
  refused(
      [] {
        update_params<RecountMovedUpdate>({{"ignore_translation", 2}});
      },
      "recount_moved", "ignore_translation");
  refused([] { update_params<SampledUpdate>({{"per_triangle", 0}}); }, "samples", "per_triangle");
  refused([] { update_params<SampledUpdate>({{"seed", 1.5}}); }, "samples", "seed");
  refused([] { update_params<StaleUpdate>({{"fraction", 0.5}}); }, "stale", "fraction");
  refused([] { with_density_update("recount_some", [](auto) {}); }, "recount_some", "recount_moved");
}

TEST_F(DensityUpdateTest, AStateIsRefusedOnAnotherTree) {
  const Tree<Aabb, AdbDensity> other =
      annotate_adb(Bvh<Aabb>::build(testing::make_torus(1.0, 0.35, 8, 6)), 2, kDefaultAdbTau, kOneThread);
  with_each_density_update([&](auto type) {
    using U = typename decltype(type)::type;
    auto state = U::start(tree.bvh, tree.density, update_params<U>());
    Tree<Aabb, AdbDensity> copy = other;
    EXPECT_THROW(U::update(copy.bvh, copy.density, state, kOneThread, nullptr), std::invalid_argument)
        << U::name();
  });
}

// On OBB trees "adb" counts in each node's own frame: the recounts follow it, the samples refuse.
TEST_F(DensityUpdateTest, OnObbTreesRecountsUseTheNodesFramesAndSamplesAreRefused) {
  auto obb = annotate_adb(Bvh<Obb>::build(rest), 2, kDefaultAdbTau, kOneThread);
  auto state =
      RecountMovedUpdate::start(obb.bvh, obb.density, update_params<RecountMovedUpdate>({{"fraction", 0}}));
  obb.bvh.refit(twisted(rest, 0.8));
  RecountMovedUpdate::update(obb.bvh, obb.density, state, kOneThread, nullptr);
  const auto expected = annotate_adb(obb.bvh, 2, kDefaultAdbTau, kOneThread).density.possible_collision_cells;
  EXPECT_EQ(obb.density.possible_collision_cells, expected);
  try {
    (void)SampledUpdate::start(obb.bvh, obb.density, update_params<SampledUpdate>());
    ADD_FAILURE() << "samples accepted an OBB tree";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("own frame"), std::string::npos) << e.what();
  }
}

TEST(DensityUpdateRegistry, NamesAreUniqueAndFound) {
  const auto names = density_update_names();
  ASSERT_EQ(names.size(), 4u);
  for (const std::string& name : names)
    EXPECT_EQ(with_density_update(name, [](auto type) { return std::string(decltype(type)::type::name()); }),
              name);
}

}  // namespace
}  // namespace bvhlab
