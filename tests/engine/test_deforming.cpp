// Trees of a deforming mesh through the run-time layer (engine/deforming.hpp): a refit is the typed refit,
// exact answers stay exact on refitted and rebuilt trees of every volume, density updates keep their
// counts as the policy says, and a tree is never changed while a query or a handle holds it.
#include "adb/update.hpp"
#include "bvh/deform.hpp"
#include "engine/deforming.hpp"
#include "support/errors.hpp"
#include "support/generated_meshes.hpp"
#include "volumes/aabb.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace bvhlab {
namespace {

using testing::error_of;

const Mesh& rest_torus() {
  static const Mesh mesh = testing::make_torus(0.7, 0.25, 24, 12);
  return mesh;
}

Mesh twisted(double t) {
  return deform(rest_torus(), parse_deformation("twist:amplitude=2"), t);
}

/// Every pose's result of `variant` with `a` fixed and `b` moved.
std::vector<Result> answers(const AnyTree& a, const AnyTree& b, const StrategyVariant& variant) {
  const std::vector<RigidTransform> poses = testing::poses_along_x();
  std::vector<Result> out(poses.size());
  a.prepare(b, variant)->run(poses, [&](std::size_t k, const Result& r) { out[k] = r; });
  return out;
}

std::vector<bool> collides(const std::vector<Result>& results) {
  std::vector<bool> out;
  for (const Result& r : results) out.push_back(r.collides);
  return out;
}

const StrategyVariant kExact = strategy_variant("exact", {}, {});
const DensitySpec kAdb = density_spec("adb", {});

TEST(DeformingTree, ARefitIsTheTypedRefit) {
  DeformingTree tree(rest_torus(), "aabb", {});
  const Mesh deformed = twisted(0.25);
  const double degradation = tree.refit(deformed, RefitMethod::Merge);
  Bvh<Aabb> typed = Bvh<Aabb>::build(rest_torus());
  typed.refit(deformed, RefitMethod::Merge);
  EXPECT_EQ(degradation, typed.degradation());
  EXPECT_GT(degradation, 1.0);  // the twist spreads the rest shape's boxes
  EXPECT_EQ(tree.tree().info().nodes, typed.stats().nodes);
  // The handle's world box follows the refitted root.
  const Box box = tree.tree().world_box(RigidTransform{});
  for (const Vec3& v : deformed.vertices) EXPECT_TRUE(box.contains(v));
}

TEST(DeformingTree, ExactAnswersStayExactOnRefittedAndRebuiltTreesOfEveryVolume) {
  const Mesh deformed = twisted(0.3);
  const AnyTree other = AnyTree::build(rest_torus(), {}, "aabb", {}, {});
  const auto truth = collides(answers(AnyTree::build(deformed, {}, "aabb", {}, {}), other, kExact));
  for (const std::string& bv : volume_names()) {
    SCOPED_TRACE(bv);
    DeformingTree tree(rest_torus(), bv, {});
    const AnyTree b = AnyTree::build(rest_torus(), {}, bv, {}, {});
    const double degraded = tree.refit(deformed, RefitMethod::Fit);
    EXPECT_EQ(collides(answers(tree.tree(), b, kExact)), truth);
    tree.rebuild(deformed);
    EXPECT_EQ(collides(answers(tree.tree(), b, kExact)), truth);
    // A rebuild starts the degradation again from the deformed shape.
    EXPECT_LT(tree.refit(deformed, RefitMethod::Fit), degraded);
  }
}

TEST(DeformingTree, ATreeIsNotRefittedWhileAQueryOrAHandleHoldsIt) {
  DeformingTree tree(rest_torus(), "obb", {});
  const AnyTree other = AnyTree::build(rest_torus(), {}, "obb", {}, {});
  {
    const auto query = tree.tree().prepare(other, kExact);
    EXPECT_NE(error_of([&] { tree.refit(twisted(0.1), RefitMethod::Merge); }).find("still holds the tree"),
              std::string::npos);
  }
  {
    const AnyTree copy = tree.tree();
    EXPECT_NE(error_of([&] { tree.refit(twisted(0.1), RefitMethod::Merge); }).find("still holds the tree"),
              std::string::npos);
  }
  EXPECT_GT(tree.refit(twisted(0.1), RefitMethod::Merge), 1.0);  // released: refitted
}

TEST(DeformingTree, AMeshOfAnotherTopologyIsRefusedByName) {
  DeformingTree tree(rest_torus(), "dop24", {});
  EXPECT_NE(error_of([&] {
              tree.refit(testing::make_torus(0.7, 0.25, 12, 8), RefitMethod::Merge);
            }).find("refit: the mesh has"),
            std::string::npos);
  EXPECT_NE(error_of([] { DeformingTree(rest_torus(), "no_such_bv", {}); }).find("no_such_bv"),
            std::string::npos);
}

/// A FollowingDensity of `policy` on an obb tree refitted to a strong twist, and that tree.
struct Followed {
  DeformingTree plain{rest_torus(), "obb", {}};
  FollowingDensity counts;
  AnyTree recount;

  explicit Followed(const std::string& policy)
      : counts({policy, {}}, plain.tree().annotated(kAdb, {})), recount(refit_and_recount()) {
    counts.take_volumes(plain.tree());
  }
  AnyTree refit_and_recount() {
    plain.refit(twisted(0.25), RefitMethod::Merge);
    return plain.tree().annotated(kAdb, {});
  }
};

TEST(FollowingDensity, EachPolicyKeepsItsCountsAsItSays) {
  Followed all("recount_all");
  all.counts.update();
  EXPECT_EQ(all.counts.count_error(all.recount).mean_difference, 0.0);
  Followed stale("stale");
  stale.counts.update();
  const CountError drift = stale.counts.count_error(stale.recount);
  EXPECT_GT(drift.mean_difference, 0.0);  // the rest shape's counts no longer fit
  EXPECT_GT(drift.under_counted, 0.0);
  stale.counts.restart();  // after a rebuild: counted anew
  EXPECT_EQ(stale.counts.count_error(stale.recount).mean_difference, 0.0);
}

TEST(FollowingDensity, ItsTreeAnswersAdbQueries) {
  Followed all("recount_all");
  all.counts.update();
  const AnyTree other = AnyTree::build(rest_torus(), {}, "obb", {}, {}).annotated(kAdb, {});
  const auto adb = answers(all.counts.tree(), other, strategy_variant("adb", {{"p_min", 0.9}}, {}));
  const auto fresh = answers(all.recount, other, strategy_variant("adb", {{"p_min", 0.9}}, {}));
  ASSERT_EQ(adb.size(), fresh.size());
  for (std::size_t k = 0; k < adb.size(); ++k) {  // the recount's counts: the same answers
    EXPECT_EQ(adb[k].collides, fresh[k].collides) << k;
    EXPECT_EQ(adb[k].counters.bv_tests, fresh[k].counters.bv_tests) << k;
  }
}

TEST(FollowingDensity, RefusalsNameWhatIsWrong) {
  DeformingTree plain(rest_torus(), "obb", {});
  EXPECT_NE(error_of([&] {
              FollowingDensity({"stale", {}}, plain.tree());
            }).find("keep adb counts"),
            std::string::npos);
  const AnyTree annotated = plain.tree().annotated(kAdb, {});
  EXPECT_NE(error_of([&] {
              FollowingDensity({"recount_some", {}}, annotated);
            }).find("recount_moved"),
            std::string::npos);  // the choices are named
  EXPECT_NE(error_of([&] {
              FollowingDensity({"recount_moved", {{"no_such", 1}}}, annotated);
            }).find("no_such"),
            std::string::npos);
  FollowingDensity counts({"stale", {}}, annotated);
  const AnyTree aabb = AnyTree::build(rest_torus(), {}, "aabb", {}, {});
  EXPECT_NE(error_of([&] { counts.take_volumes(aabb); }).find("a plain obb tree is needed"),
            std::string::npos);
  const AnyTree held = counts.tree();
  EXPECT_NE(error_of([&] { counts.update(); }).find("still holds the tree"), std::string::npos);
  EXPECT_NE(error_of([&] { counts.take_volumes(plain.tree()); }).find("still holds the tree"),
            std::string::npos);
}

}  // namespace
}  // namespace bvhlab
