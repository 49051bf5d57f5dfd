// Coherent queries through the run-time layer: a variant with `coherent` answers every pose of a sequence as
// the cold query does, with less work; a caller's state continues a sequence across calls; strategies that
// do not run coherent, and states of other trees, are refused by name.
#include "engine/any_tree.hpp"
#include "engine/policies.hpp"
#include "engine/protocol.hpp"
#include "support/errors.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/coherent_state.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

namespace bvhlab {
namespace {

using testing::error_of;

AnyTree torus_tree(const std::string& bv, int segments = 24) {
  return AnyTree::build(testing::make_torus(0.7, 0.25, segments, 12), MeshUnits{}, bv,
                        density_spec("none", {}), BuildOptions{});
}

/// Protocol turns at distances where the tori touch at some steps and not at others.
std::vector<RigidTransform> turns() {
  std::vector<RigidTransform> poses;
  for (double d : {0.9, 1.2, 1.5})
    for (const RigidTransform& pose : protocol_poses(d, 150)) poses.push_back(pose);
  return poses;
}

StrategyVariant variant(const std::string& strategy, bool coherent) {
  StrategyVariant v = strategy_variant(strategy, {}, Budget{});
  v.coherent = coherent;
  return v;
}

std::vector<Result> run_all(const PreparedQuery& query, const std::vector<RigidTransform>& poses) {
  std::vector<Result> out(poses.size());
  query.run(poses, [&](std::size_t i, const Result& r) { out[i] = r; });
  return out;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted_contacts(const Result& r) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
  for (const auto& c : r.contacts) out.emplace_back(c.a, c.b);
  std::sort(out.begin(), out.end());
  return out;
}

std::uint64_t bv_tests(const std::vector<Result>& results) {
  std::uint64_t sum = 0;
  for (const Result& r : results) sum += r.counters.bv_tests;
  return sum;
}

class CoherentQuery : public ::testing::TestWithParam<const char*> {};

TEST_P(CoherentQuery, AnswersAsTheColdQueryWithFewerBvTests) {
  const AnyTree a = torus_tree(GetParam()), b = torus_tree(GetParam());
  const auto poses = turns();
  for (const char* strategy : {"exact", "all_contacts"}) {
    const auto cold = run_all(*a.prepare(b, variant(strategy, false)), poses);
    const auto coherent_query = a.prepare(b, variant(strategy, true));
    EXPECT_TRUE(coherent_query->coherent());
    const auto coherent = run_all(*coherent_query, poses);
    std::size_t colliding = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      ASSERT_EQ(coherent[i].collides, cold[i].collides) << strategy << " pose " << i;
      EXPECT_TRUE(coherent[i].exact);
      EXPECT_EQ(coherent[i].witness.has_value(), cold[i].collides) << strategy << " pose " << i;
      EXPECT_EQ(sorted_contacts(coherent[i]), sorted_contacts(cold[i])) << strategy << " pose " << i;
      colliding += cold[i].collides;
    }
    EXPECT_GT(colliding, 0u);  // the turns cover both answers
    EXPECT_LT(colliding, poses.size());
    EXPECT_LT(bv_tests(coherent), bv_tests(cold)) << strategy;
    // time() runs the same coherent sequence, with a state of its own.
    std::vector<QueryRecord> records;
    coherent_query->time(poses, 0, records);
    ASSERT_EQ(records.size(), poses.size());
    for (std::size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(records[i].collides, cold[i].collides) << strategy << " pose " << i;
      EXPECT_EQ(records[i].counters.bv_tests, coherent[i].counters.bv_tests) << strategy << " pose " << i;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Volumes, CoherentQuery, ::testing::Values("aabb", "obb", "rbox"));

TEST(CoherentQueryState, ACallersStateContinuesTheSequenceAcrossCalls) {
  const AnyTree a = torus_tree("aabb"), b = torus_tree("aabb");
  const auto poses = turns();
  const auto query = a.prepare(b, variant("exact", true));
  const auto whole = run_all(*query, poses);
  CoherentState state;
  std::vector<Result> halves(poses.size());
  const std::size_t half = poses.size() / 2;
  const std::span<const RigidTransform> all(poses);
  query->run(
      all.first(half), [&](std::size_t i, const Result& r) { halves[i] = r; }, state);
  EXPECT_TRUE(state.front_size() > 0 || state.witness) << "the state holds what the last pose left";
  query->run(
      all.subspan(half), [&](std::size_t i, const Result& r) { halves[half + i] = r; }, state);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(halves[i].collides, whole[i].collides) << i;
    EXPECT_EQ(halves[i].counters.bv_tests, whole[i].counters.bv_tests) << i;
  }
  // A state the caller reset starts the next call as a new state does.
  state.reset();
  EXPECT_EQ(state.front_size(), 0u);
  EXPECT_FALSE(state.witness);
  CoherentState fresh;
  Result after_reset, from_fresh;
  query->run(
      all.first(1), [&](std::size_t, const Result& r) { after_reset = r; }, state);
  query->run(
      all.first(1), [&](std::size_t, const Result& r) { from_fresh = r; }, fresh);
  EXPECT_EQ(after_reset.collides, from_fresh.collides);
  EXPECT_EQ(after_reset.counters.bv_tests, from_fresh.counters.bv_tests);
}

// time() with a caller's state (a world's pair, frame after frame): the warm-up queries run on a copy, so
// the timed ones do the work they would do without them, and the state continues from the last pose.
TEST(CoherentQueryState, WarmUpQueriesRunOnACopyOfTheCallersState) {
  const AnyTree a = torus_tree("aabb"), b = torus_tree("aabb");
  const auto poses = turns();
  const auto query = a.prepare(b, variant("exact", true));
  CoherentState plain, warmed;
  std::vector<QueryRecord> without, with;
  query->time(poses, 0, without, plain);
  query->time(poses, 5, with, warmed);
  ASSERT_EQ(with.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(with[i].collides, without[i].collides) << i;
    EXPECT_EQ(with[i].counters.bv_tests, without[i].counters.bv_tests) << i;
  }
  EXPECT_EQ(warmed.front_size(), plain.front_size());
  EXPECT_EQ(warmed.witness, plain.witness);
  EXPECT_THROW(a.prepare(b, variant("exact", false))->time(poses, 0, with, plain), std::logic_error);
}

// time_per_pose (a deforming object asked at the same poses frame after frame): pose k continues states[k],
// as a run with that state alone would; the warm-up queries run on copies.
TEST(CoherentQueryState, EachPoseContinuesItsOwnState) {
  const AnyTree a = torus_tree("aabb"), b = torus_tree("aabb");
  const auto poses = protocol_poses(1.2, 40);
  const auto query = a.prepare(b, variant("exact", true));
  std::vector<CoherentState> states(poses.size()), alone(poses.size());
  std::vector<QueryRecord> records;
  for (int frame = 0; frame < 2; ++frame) {
    query->time_per_pose(poses, 3, records, states);
    ASSERT_EQ(records.size(), poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k) {
      Result r;
      query->run(
          std::span(&poses[k], 1), [&](std::size_t, const Result& x) { r = x; }, alone[k]);
      EXPECT_EQ(records[k].collides, r.collides) << k;
      EXPECT_EQ(records[k].counters.bv_tests, r.counters.bv_tests) << "frame " << frame << ", pose " << k;
    }
  }
  EXPECT_GT(states[0].witness_hits() + states[0].stored_pairs(), 0u);
  std::vector<CoherentState> too_few(poses.size() - 1);
  EXPECT_NE(error_of([&] { query->time_per_pose(poses, 0, records, too_few); }).find("one per pose"),
            std::string::npos);
  EXPECT_THROW(a.prepare(b, variant("exact", false))->time_per_pose(poses, 0, records, states),
               std::logic_error);
}

TEST(CoherentQueryState, AStateOfOtherTreesIsRefused) {
  const AnyTree a = torus_tree("aabb"), b = torus_tree("aabb"), c = torus_tree("aabb", 30);
  const auto poses = turns();
  CoherentState state;
  const auto sink = [](std::size_t, const Result&) {};
  a.prepare(b, variant("exact", true))->run(poses, sink, state);
  EXPECT_NE(
      error_of([&] { a.prepare(c, variant("exact", true))->run(poses, sink, state); }).find("other trees"),
      std::string::npos);
  // A query that was not prepared coherent keeps no state.
  EXPECT_THROW(a.prepare(b, variant("exact", false))->run(poses, sink, state), std::logic_error);
}

TEST(CoherentQueryState, EveryShippedStrategyRunsCoherent) {
  for (const StrategyInfo& s : strategy_table()) {
    EXPECT_TRUE(s.coherent) << s.name;
    EXPECT_EQ(s.coherent_refusal(), "") << s.name;
  }
  EXPECT_EQ(variant("exact", true).label(), "exact coherent");
  // The refusal of a strategy that does not run coherent: tests/bench/test_policies.cpp (the test-only one).
}

/// The ADB strategies through the engine: guided exact answers as the exact query; adb and time_critical
/// as the cold query but where the remembered pair decides on its own estimate (traversal/coherent_adb.hpp).
TEST(CoherentQueryState, AdbStrategiesRememberTheirDecidingPair) {
  const AnyTree a = AnyTree::build(testing::make_torus(0.7, 0.25, 24, 12), MeshUnits{}, "aabb",
                                   density_spec("adb", {}), BuildOptions{});
  const auto poses = turns();
  const auto exact = run_all(*a.prepare(a, variant("exact", false)), poses);
  for (const char* strategy : {"guided_exact", "adb", "adb_dfs", "adb_larger", "time_critical"}) {
    StrategyVariant v = strategy_variant(
        strategy, {}, strategy == std::string("time_critical") ? Budget{.max_bv_tests = 60} : Budget{});
    const auto cold = run_all(*a.prepare(a, v), poses);
    v.coherent = true;
    const auto coherent = run_all(*a.prepare(a, v), poses);
    std::size_t disagreements = 0;
    for (std::size_t i = 0; i < poses.size(); ++i) {
      disagreements += coherent[i].collides != cold[i].collides;
      if (strategy == std::string("guided_exact")) {
        EXPECT_EQ(coherent[i].collides, exact[i].collides) << i;
      }
    }
    EXPECT_LE(disagreements, poses.size() / 50) << strategy;
    EXPECT_LT(bv_tests(coherent), bv_tests(cold)) << strategy;
  }
}

}  // namespace
}  // namespace bvhlab
