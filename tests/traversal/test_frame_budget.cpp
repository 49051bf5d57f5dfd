// The frame scheduler (traversal/frame_budget.hpp): exact answers without a budget, the budget kept in total
// and per share, best-effort answers on exhaustion, every pair's root tested first, equal_split as the
// single-pair ADB, each pair as query_adb in the frame's order (best or depth first), the global order
// against equal shares, and refused options.
#include "adb/adb_density.hpp"
#include "bvh/mesh_io.hpp"
#include "support/generated_meshes.hpp"
#include "support/meshes.hpp"
#include "support/random_draws.hpp"
#include "traversal/exact.hpp"
#include "traversal/frame_schedule.hpp"
#include "volumes/aabb.hpp"
#include "volumes/obb.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using testing::draw_vec3;

/// The bundled meshes, normalised (longest side 2), as ADB-annotated trees of one volume.
template <class BV>
struct Meshes {
  std::vector<Tree<BV, AdbDensity>> trees;
  Meshes() {
    AnnotationContext context;
    context.threads = 1;
    for (const char* file : {"pinion.off", "jeep1.ms3d", "teapot.obj"}) {
      Mesh mesh = load_mesh(testing::bundled_mesh(file)).mesh;
      normalize_to_unit_cube(mesh);
      trees.push_back(annotate_adb(Bvh<BV>::build(mesh), 2, kDefaultAdbTau, context));
    }
  }
};

template <class BV>
const Meshes<BV>& meshes() {
  static const Meshes<BV> m;  // annotated once per test binary
  return m;
}

template <class BV>
using Frame = std::vector<FramePair<BV, AdbDensity>>;

/// B's pose: a random rotation, B's centre at `distance` from A's in a random direction.
RigidTransform pose_at(std::mt19937_64& rng, double distance) {
  RigidTransform pose = testing::random_pose(rng, 1.0);
  std::normal_distribution<double> normal;
  const Vec3 direction = draw_vec3(normal, rng).normalized();
  pose.translation = distance * direction;
  return pose;
}

/// `n` pairs of random meshes at distances drawn from [near, far].
template <class BV>
Frame<BV> random_frame(std::mt19937_64& rng, int n, double near, double far) {
  const auto& trees = meshes<BV>().trees;
  std::uniform_int_distribution<std::size_t> mesh(0, trees.size() - 1);
  std::uniform_real_distribution<double> distance(near, far);
  Frame<BV> frame;
  for (int k = 0; k < n; ++k)
    frame.push_back({&trees[mesh(rng)], &trees[mesh(rng)], pose_at(rng, distance(rng)), std::nullopt});
  return frame;
}

template <class BV>
bool exact_answer(const FramePair<BV, AdbDensity>& p) {
  return query_exact(p.a->bvh, p.b->bvh, p.b_to_a).collides;
}

template <class BV>
std::vector<PairOutcome> schedule(const Frame<BV>& frame, const FrameOptions& options) {
  return schedule_frame<BV, AdbDensity>(frame, options);
}

std::uint64_t total_bv_tests(const std::vector<PairOutcome>& outcomes) {
  std::uint64_t total = 0;
  for (const auto& o : outcomes) total += o.counters.bv_tests;
  return total;
}

std::vector<std::string> policy_names() {
  std::vector<std::string> names;
  for (const FramePolicy& p : frame_policies()) names.emplace_back(p.name);
  return names;
}

FrameOptions guided_exact(const std::string& policy) {
  FrameOptions options;
  options.policy = policy;
  options.p_min = 1;
  options.adb.exact_leaves = true;
  return options;
}

template <class BV>
class FrameExact : public ::testing::Test {};
using Volumes = ::testing::Types<Aabb, Obb>;
TYPED_TEST_SUITE(FrameExact, Volumes);

TYPED_TEST(FrameExact, WithoutABudgetEveryPolicyGivesTheExactAnswers) {
  std::mt19937_64 rng(3);
  const Frame<TypeParam> frame = random_frame<TypeParam>(rng, 40, 0.5, 2.5);
  int colliding = 0;
  for (const auto& name : policy_names()) {
    const auto outcomes = schedule(frame, guided_exact(name));
    ASSERT_EQ(outcomes.size(), frame.size());
    colliding = 0;
    for (std::size_t k = 0; k < frame.size(); ++k) {
      const bool truth = exact_answer(frame[k]);
      EXPECT_EQ(outcomes[k].collides, truth) << name << ", pair " << k;
      EXPECT_TRUE(outcomes[k].exact) << name << ", pair " << k;
      EXPECT_FALSE(outcomes[k].budget_exhausted) << name << ", pair " << k;
      EXPECT_EQ(outcomes[k].probability, truth ? 1.0 : 0.0) << name << ", pair " << k;
      colliding += truth;
    }
  }
  // Both answers occur.
  EXPECT_GT(colliding, 5);
  EXPECT_LT(colliding, 35);
}

// A best-effort answer: flagged, not exact, a probability in [0, 1], "collision" iff it reaches the
// threshold.
void expect_best_effort(const PairOutcome& o, const FrameOptions& options, const std::string& where) {
  EXPECT_FALSE(o.exact) << where;
  EXPECT_GE(o.probability, 0.0) << where;
  EXPECT_LE(o.probability, 1.0) << where;
  EXPECT_EQ(o.collides, o.probability >= options.adb.best_effort_threshold) << where;
}

TEST(FrameBudget, TheBvTestBudgetHoldsInTotalAndPerShare) {
  std::mt19937_64 rng(5);
  const Frame<Aabb> frame = random_frame<Aabb>(rng, 30, 0.3, 1.8);
  const std::uint64_t n = frame.size();
  int flagged = 0;
  for (const auto& name : policy_names()) {
    for (std::uint64_t budget : {1u, 7u, 30u, 31u, 100u, 777u, 5000u}) {
      FrameOptions options;
      options.policy = name;
      options.budget.max_bv_tests = budget;
      const auto outcomes = schedule(frame, options);
      const std::uint64_t total = total_bv_tests(outcomes);
      EXPECT_LE(total, budget) << name << ", budget " << budget;
      bool any_flagged = false;
      for (std::size_t k = 0; k < n; ++k) {
        const PairOutcome& o = outcomes[k];
        const std::string where = name + ", budget " + std::to_string(budget) + ", pair " + std::to_string(k);
        if (name == "equal_split") {
          EXPECT_LE(o.counters.bv_tests, (budget + n - 1) / n) << where;
        }
        if (!o.budget_exhausted) continue;
        any_flagged = true;
        ++flagged;
        expect_best_effort(o, options, where);
      }
      // A frame cut short spent its whole budget (equal shares may leave a decided pair's share unspent).
      if (any_flagged && name != "equal_split") {
        EXPECT_EQ(total, budget) << name << ", budget " << budget;
      }
    }
  }
  EXPECT_GT(flagged, 100);
}

TEST(FrameBudget, NoTestOrOneTestFlagsEveryUndecidedPair) {
  std::mt19937_64 rng(7);
  const Frame<Aabb> frame = random_frame<Aabb>(rng, 20, 0.0, 0.2);  // every root pair overlaps
  for (const auto& name : policy_names()) {
    FrameOptions one;
    one.policy = name;
    one.p_min = 1;  // no estimate decides: the first pair's root test leaves it open
    one.budget.max_bv_tests = 1;
    FrameOptions none = one;  // a deadline that has passed at the first look: no test at all
    none.budget = {0, 1e-9};
    for (const FrameOptions& options : {one, none}) {
      const auto outcomes = schedule(frame, options);
      const std::uint64_t tests = options.budget.max_bv_tests;
      EXPECT_EQ(total_bv_tests(outcomes), tests) << name;
      for (std::size_t k = 0; k < frame.size(); ++k) {
        const std::string where = name + ", " + std::to_string(tests) + " tests, pair " + std::to_string(k);
        EXPECT_TRUE(outcomes[k].budget_exhausted) << where;
        expect_best_effort(outcomes[k], options, where);
        // Only the first pair had its root test: its estimate is positive; the others know nothing.
        if (k == 0 && tests == 1) {
          EXPECT_GT(outcomes[k].probability, 0.0) << where;
        } else {
          EXPECT_EQ(outcomes[k].probability, 0.0) << where;
        }
      }
    }
  }
}

// Every pair's root comes first: pairs whose root boxes are apart are decided exactly by that one test, under
// every policy, even when the budget leaves the others undecided.
TEST(FrameBudget, PairsFarApartAreDecidedExactlyAfterOneTest) {
  std::mt19937_64 rng(11);
  Frame<Aabb> frame = random_frame<Aabb>(rng, 24, 0.0, 0.6);
  std::vector<bool> far(frame.size());
  for (std::size_t k = 0; k < frame.size(); k += 3) {
    frame[k].b_to_a = pose_at(rng, 10.0);  // boxes of longest side 2 at 10 apart: disjoint whatever the turn
    far[k] = true;
  }
  for (const auto& name : policy_names()) {
    for (std::uint64_t budget : {0u, 24u, 60u}) {
      FrameOptions options;
      options.policy = name;
      options.p_min = 1;  // overlapping pairs stay open until the budget or their queue ends
      options.budget.max_bv_tests = budget;
      const auto outcomes = schedule(frame, options);
      int flagged = 0;
      for (std::size_t k = 0; k < frame.size(); ++k) {
        const std::string where = name + ", budget " + std::to_string(budget) + ", pair " + std::to_string(k);
        flagged += outcomes[k].budget_exhausted;
        if (!far[k]) continue;
        EXPECT_FALSE(outcomes[k].collides) << where;
        EXPECT_TRUE(outcomes[k].exact) << where;
        EXPECT_FALSE(outcomes[k].budget_exhausted) << where;
        EXPECT_EQ(outcomes[k].counters.bv_tests, 1u) << where;
      }
      if (budget != 0) {
        EXPECT_GT(flagged, 0) << name << ": the budget should have cut the frame short";
      }
    }
  }
}

// equal_split runs each pair as the single-pair time-critical ADB under its share.
/// query_adb in the traversal order a frame's pairs take.
Result query_in_order(const FramePair<Aabb, AdbDensity>& pair, const AdbOptions& options, FrameOrder order) {
  return order == FrameOrder::depth_first ? query_adb<AdbDepthFirst>(*pair.a, *pair.b, pair.b_to_a, options)
                                          : query_adb<AdbBestFirst>(*pair.a, *pair.b, pair.b_to_a, options);
}

TEST(FrameBudget, EqualSplitIsTheSinglePairAdbUnderItsShare) {
  std::mt19937_64 rng(13);
  const Frame<Aabb> frame = random_frame<Aabb>(rng, 25, 0.2, 1.6);
  const std::uint64_t n = frame.size();
  int flagged = 0;
  for (const FrameOrder order : {FrameOrder::best_first, FrameOrder::depth_first})
    for (const auto& [p_min, budget] :
         {std::pair{0.9, n}, {0.9, 3 * n + 7}, {0.9, 20 * n + 3}, {1.0, 5 * n}}) {
      FrameOptions options;
      options.policy = "equal_split";
      options.order = order;
      options.p_min = p_min;
      options.budget.max_bv_tests = budget;
      const auto outcomes = schedule(frame, options);
      for (std::size_t k = 0; k < n; ++k) {
        AdbOptions single = options.pair_options();
        single.budget.max_bv_tests = budget / n + (k < budget % n ? 1 : 0);
        const Result r = query_in_order(frame[k], single, order);
        const std::string where = std::string(frame_order_name(order)) + ", budget " +
                                  std::to_string(budget) + ", pair " + std::to_string(k);
        EXPECT_EQ(outcomes[k].collides, r.collides) << where;
        EXPECT_EQ(outcomes[k].probability, r.probability) << where;
        EXPECT_EQ(outcomes[k].budget_exhausted, r.budget_exhausted) << where;
        EXPECT_EQ(outcomes[k].exact, r.exact) << where;
        EXPECT_EQ(outcomes[k].counters.bv_tests, r.counters.bv_tests) << where;
        EXPECT_EQ(outcomes[k].counters.nodes_visited, r.counters.nodes_visited) << where;
        flagged += r.budget_exhausted;
      }
    }
  EXPECT_GT(flagged, 10);
}

// Without a budget, every policy gives ADB's answers pair by pair: the order changes only the work.
TEST(FrameBudget, WithoutABudgetEveryPolicyGivesAdbsAnswers) {
  std::mt19937_64 rng(17);
  const Frame<Aabb> frame = random_frame<Aabb>(rng, 30, 0.3, 1.8);
  for (const auto& name : policy_names()) {
    FrameOptions options;
    options.policy = name;
    options.p_min = 0.8;
    const auto outcomes = schedule(frame, options);
    for (std::size_t k = 0; k < frame.size(); ++k) {
      const Result r = query_adb(*frame[k].a, *frame[k].b, frame[k].b_to_a, options.pair_options());
      EXPECT_EQ(outcomes[k].collides, r.collides) << name << ", pair " << k;
      EXPECT_EQ(outcomes[k].exact, r.exact) << name << ", pair " << k;
      EXPECT_FALSE(outcomes[k].budget_exhausted) << name << ", pair " << k;
    }
  }
}

// Without a budget, each pair runs as query_adb in the frame's order, test for test: the depth-first order
// is ADB's depth-first query (adb_dfs), with and without confirming generations. The two orders differ in
// their work on this frame, so the comparison sees which one ran.
TEST(FrameBudget, WithoutABudgetEachPairRunsAsQueryAdbInTheFramesOrder) {
  std::mt19937_64 rng(29);
  const Frame<Aabb> frame = random_frame<Aabb>(rng, 30, 0.3, 1.8);
  for (const int levels : {0, 2}) {
    std::uint64_t tests[2] = {0, 0};
    for (const FrameOrder order : {FrameOrder::best_first, FrameOrder::depth_first})
      for (const auto& name : policy_names()) {
        FrameOptions options;
        options.policy = name;
        options.order = order;
        options.p_min = 0.999;
        options.adb.confirm_levels = static_cast<std::uint8_t>(levels);
        const auto outcomes = schedule(frame, options);
        for (std::size_t k = 0; k < frame.size(); ++k) {
          const Result r = query_in_order(frame[k], options.pair_options(), order);
          const std::string where = name + " " + std::string(frame_order_name(order)) + ", confirm_levels " +
                                    std::to_string(levels) + ", pair " + std::to_string(k);
          EXPECT_EQ(outcomes[k].collides, r.collides) << where;
          EXPECT_EQ(outcomes[k].probability, r.probability) << where;
          EXPECT_EQ(outcomes[k].exact, r.exact) << where;
          EXPECT_EQ(outcomes[k].counters.bv_tests, r.counters.bv_tests) << where;
        }
        tests[order == FrameOrder::depth_first] = total_bv_tests(outcomes);
      }
    EXPECT_NE(tests[0], tests[1]) << "confirm_levels " << levels;
  }
}

/// Half the pairs collide, half are near misses (root boxes overlapping, no contact). The colliding ones are
/// those ADB does not decide by their root test alone: on these meshes a deep overlap is decided by the root
/// under every policy, and a comparison of policies on them would compare nothing.
Frame<Aabb> contacts_and_near_misses(std::mt19937_64& rng, int n, double p_min) {
  Frame<Aabb> frame;
  AdbOptions adb;
  adb.p_min = p_min;
  int colliding = 0, missing = 0;
  while (colliding + missing < n) {
    const bool want_contact = colliding <= missing;
    const auto pair = random_frame<Aabb>(rng, 1, 0.8, 2.0)[0];
    const Result exact = query_exact(pair.a->bvh, pair.b->bvh, pair.b_to_a);
    if (exact.collides != want_contact || exact.counters.bv_tests < 3) continue;
    if (want_contact && query_adb(*pair.a, *pair.b, pair.b_to_a, adb).counters.bv_tests < 3) continue;
    frame.push_back(pair);
    (want_contact ? colliding : missing) += 1;
  }
  return frame;
}

int missed_collisions(const Frame<Aabb>& frame, const std::vector<PairOutcome>& outcomes) {
  int missed = 0;
  for (std::size_t k = 0; k < frame.size(); ++k) missed += exact_answer(frame[k]) && !outcomes[k].collides;
  return missed;
}

// At a quarter of the BV tests the frame's ADB answers cost without a budget, answering on exhaustion only
// from an estimate of at least p_min (the strict rule), the global order misses fewer collisions than equal
// shares: it spends the tests on the pairs most likely to collide.
TEST(FrameBudget, TheGlobalOrderMissesFewerCollisionsThanEqualShares) {
  std::mt19937_64 rng(19);
  int missed_global = 0, missed_equal = 0;
  for (int f = 0; f < 6; ++f) {
    FrameOptions options;
    options.adb.best_effort_threshold = options.p_min;
    const Frame<Aabb> frame = contacts_and_near_misses(rng, 40, options.p_min);
    const std::uint64_t full = total_bv_tests(schedule(frame, options));
    options.budget.max_bv_tests = full / 4;
    options.policy = "adb_probability";
    missed_global += missed_collisions(frame, schedule(frame, options));
    options.policy = "equal_split";
    missed_equal += missed_collisions(frame, schedule(frame, options));
  }
  EXPECT_LT(missed_global, missed_equal);
  EXPECT_GT(missed_equal, 10);  // the budget is tight enough for the comparison to mean something
}

TEST(FrameBudget, RoundRobinReachesEveryPair) {
  std::mt19937_64 rng(23);
  const Frame<Aabb> frame = contacts_and_near_misses(rng, 30, 0.9);
  const std::uint64_t n = frame.size();
  FrameOptions options;
  options.budget.max_bv_tests = n + 5 * n;  // the roots, then about one expansion each
  options.policy = "round_robin";
  const auto robin = schedule(frame, options);
  options.policy = "adb_probability";
  const auto global = schedule(frame, options);
  int robin_unexpanded = 0, global_unexpanded = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const bool robin_open =
        robin[k].budget_exhausted || robin[k].counters.bv_tests > 1;  // not its root alone
    robin_unexpanded += robin_open && robin[k].counters.nodes_visited == 0;
    global_unexpanded += global[k].budget_exhausted && global[k].counters.nodes_visited == 0;
  }
  EXPECT_EQ(robin_unexpanded, 0);
  EXPECT_GT(global_unexpanded, 0);  // the probability order does leave pairs at their root: the test matters
}

// A pair with an empty tree answers "no contact", unflagged and exact, as query_adb does: whether its turn
// came or a deadline ended the frame before it.
TEST(FrameBudget, AnEmptyTreeAnswersNoContactWithOrWithoutItsTurn) {
  const auto& full = meshes<Aabb>().trees[0];
  const Tree<Aabb, AdbDensity> empty{Bvh<Aabb>{}, full.density};  // no mesh builds one; a caller may
  ASSERT_TRUE(empty.bvh.empty());
  const Frame<Aabb> frame = {{&full, &empty, RigidTransform{}, std::nullopt},
                             {&empty, &full, RigidTransform{}, std::nullopt}};
  const Result alone = query_adb(full, empty, RigidTransform{}, AdbOptions{});
  FrameOptions generous, starved;
  starved.budget.deadline_us = 1e-9;  // passed at the first look: no pair has its turn
  for (const FrameOptions& options : {generous, starved})
    for (const PairOutcome& o : schedule(frame, options)) {
      EXPECT_EQ(o.collides, alone.collides);
      EXPECT_EQ(o.exact, alone.exact);
      EXPECT_EQ(o.budget_exhausted, alone.budget_exhausted);
      EXPECT_EQ(o.probability, alone.probability);
    }
}

// Frame-to-frame fronts (FrameMemory): pairs that touch deeply, named, then the same frame again.
Frame<Aabb> named_close_frame(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Frame<Aabb> frame = random_frame<Aabb>(rng, 30, 0.8, 1.6);
  for (std::size_t k = 0; k < frame.size(); ++k) frame[k].identity = 1000 + k;
  return frame;
}

/// The pairs decided "collision" below their roots: what a memory can save.
std::size_t decided_below_root(const std::vector<PairOutcome>& outcomes) {
  std::size_t n = 0;
  for (const auto& o : outcomes) n += o.collides && !o.budget_exhausted && o.counters.bv_tests > 1;
  return n;
}

TEST(FrameMemory, TheSameFrameAgainDecidesItsCollisionsAfterTheRootAndOneTest) {
  const Frame<Aabb> frame = named_close_frame(11);
  for (const auto& name : policy_names()) {
    FrameOptions options;
    options.policy = name;
    FrameMemory memory;
    const auto first = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
    ASSERT_GT(decided_below_root(first), 3u) << name << ": the test needs pairs decided below their roots";
    std::size_t remembered = 0;
    for (const auto& o : first) remembered += o.collides;
    EXPECT_EQ(memory.size(), remembered) << name;  // every collision here is one node pair's decision
    const auto again = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
    for (std::size_t k = 0; k < frame.size(); ++k) {
      const std::string where = name + ", pair " + std::to_string(k);
      EXPECT_EQ(again[k].collides, first[k].collides) << where;
      if (first[k].collides)
        EXPECT_LE(again[k].counters.bv_tests, 2u) << where;  // the root, then the remembered pair
      else
        EXPECT_EQ(again[k].counters.bv_tests, first[k].counters.bv_tests) << where;
    }
    // Without a memory the second frame is the first again.
    EXPECT_EQ(total_bv_tests(schedule(frame, options)), total_bv_tests(first)) << name;
  }
}

// Under confirm_levels a collision is decided by the last pair of a confirmed chain; the memory keeps that
// pair, which decides again on its own estimate, without a second chain. Collisions decided by the leaf
// pairs' combined evidence leave nothing and run as before.
TEST(FrameMemory, UnderConfirmLevelsTheChainsLastPairDecidesAgainAlone) {
  const Frame<Aabb> frame = named_close_frame(15);
  for (const FrameOrder order : {FrameOrder::best_first, FrameOrder::depth_first}) {
    FrameOptions options;
    options.order = order;
    options.adb.confirm_levels = 2;
    const std::string name(frame_order_name(order));
    FrameMemory memory;
    const auto first = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
    std::size_t chains = 0;  // collisions remembered below the root, where a chain of three pairs decided
    const auto again = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
    for (std::size_t k = 0; k < frame.size(); ++k) {
      const std::string where = name + ", pair " + std::to_string(k);
      EXPECT_EQ(again[k].collides, first[k].collides) << where;
      const bool recalled = first[k].collides && again[k].counters.bv_tests <= 2;
      if (!recalled) {
        EXPECT_EQ(again[k].counters.bv_tests, first[k].counters.bv_tests) << where;
      }
      chains += recalled && first[k].counters.bv_tests > 8;  // a chain of two generations costs more
    }
    EXPECT_GT(chains, 3u) << name << ": the test needs collisions decided by chains";
  }
}

TEST(FrameMemory, APairWithoutARootTestAnswersWhatItRemembers) {
  const Frame<Aabb> frame = named_close_frame(12);
  FrameOptions options;
  FrameMemory memory;
  const auto first = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
  FrameOptions none = options;
  none.budget = {0, 1e-9};  // a deadline that has passed at the first look: no root test at all
  FrameMemory kept = memory;
  const auto late = schedule_frame<Aabb, AdbDensity>(frame, none, &kept);
  const auto forgetful = schedule(frame, none);
  for (std::size_t k = 0; k < frame.size(); ++k) {
    const std::string where = "pair " + std::to_string(k);
    EXPECT_TRUE(late[k].budget_exhausted) << where;
    EXPECT_EQ(late[k].counters.bv_tests, 0u) << where;
    EXPECT_EQ(late[k].collides, first[k].collides) << where;
    EXPECT_EQ(late[k].probability, first[k].collides ? first[k].probability : 0.0) << where;
    EXPECT_FALSE(forgetful[k].collides) << where;
  }
  EXPECT_EQ(kept.size(), 0u);  // flagged answers are not remembered
}

TEST(FrameMemory, OtherTreesOrAnotherIdentityRecallNothing) {
  const Frame<Aabb> frame = named_close_frame(13);
  FrameOptions options;
  FrameMemory memory;
  const auto first = schedule_frame<Aabb, AdbDensity>(frame, options, &memory);
  Frame<Aabb> renamed = frame, swapped = frame;
  for (auto& pair : renamed) *pair.identity += 1000;
  const auto& trees = meshes<Aabb>().trees;
  for (auto& pair : swapped) pair.a = &trees[(pair.a - trees.data() + 1) % trees.size()];
  for (const Frame<Aabb>* other : {&renamed, &swapped}) {
    FrameMemory copy = memory;
    const auto with = schedule_frame<Aabb, AdbDensity>(*other, options, &copy);
    const auto without = schedule(*other, options);
    EXPECT_EQ(total_bv_tests(with), total_bv_tests(without));
  }
}

/// Runs `run`; it must throw std::invalid_argument whose message contains `name`.
template <class Run>
void expect_refused(Run&& run, const std::string& name) {
  try {
    run();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    return;
  }
  ADD_FAILURE() << "not refused: " << name;
}

TEST(FrameMemory, ChildConfirmationExactLeavesAndRepeatedIdentitiesAreRefused) {
  Frame<Aabb> frame = named_close_frame(14);
  FrameMemory memory;
  FrameOptions confirming;
  confirming.adb.confirm_with_children = true;
  expect_refused([&] { schedule_frame<Aabb, AdbDensity>(frame, confirming, &memory); },
                 "confirm_with_children");
  FrameOptions exact_leaves;
  exact_leaves.adb.exact_leaves = true;
  expect_refused([&] { schedule_frame<Aabb, AdbDensity>(frame, exact_leaves, &memory); }, "exact leaves");
  for (auto& pair : frame) pair.identity = 7;
  expect_refused([&] { schedule_frame<Aabb, AdbDensity>(frame, FrameOptions{}, &memory); }, "identity 7");
  EXPECT_EQ(memory.size(), 0u);
}

TEST(FrameBudget, BadOptionsAreRefusedByName) {
  const auto& tree = meshes<Aabb>().trees[0];
  const Frame<Aabb> frame = {{&tree, &tree, RigidTransform{}, std::nullopt}};
  const auto refused = [&](const FrameOptions& options, const std::string& name) {
    try {
      schedule(frame, options);
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "not refused: " << name;
  };
  for (double p_min : {0.0, -0.5, 1.5, std::nan("")}) {
    FrameOptions options;
    options.p_min = p_min;
    refused(options, "p_min");
  }
  FrameOptions late;
  late.budget.deadline_us = -1;
  refused(late, "deadline");
  FrameOptions unknown;
  unknown.policy = "fastest";
  refused(unknown, "unknown frame policy 'fastest'");
  refused(unknown, "adb_probability, uncertainty_per_cost, equal_split, round_robin");
  try {
    frame_order("sideways");
    ADD_FAILURE() << "order 'sideways' not refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown frame order 'sideways' (known: best_first, depth_first)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(frame_order("depth_first"), FrameOrder::depth_first);
  FrameOptions no_order;
  no_order.order = static_cast<FrameOrder>(7);
  refused(no_order, "order");
  FrameOptions inner;
  inner.adb.budget.max_bv_tests = 10;
  refused(inner, "adb.budget");
  FrameOptions threshold;
  threshold.adb.best_effort_threshold = 2;
  refused(threshold, "best_effort_threshold");

  const Frame<Aabb> null_tree = {{&tree, nullptr, RigidTransform{}, std::nullopt}};
  EXPECT_THROW(schedule(null_tree, FrameOptions{}), std::invalid_argument);
  try {
    schedule(null_tree, FrameOptions{});
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("pair 0 has a null tree"), std::string::npos) << e.what();
  }
  EXPECT_THROW(frame_policy("none"), std::invalid_argument);
  // An empty frame is fine.
  EXPECT_TRUE(schedule(Frame<Aabb>{}, FrameOptions{}).empty());
}

}  // namespace
}  // namespace bvhlab
