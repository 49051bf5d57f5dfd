// Coherent exact queries (traversal/coherent.hpp) on every shipped volume: along paths through contact and
// across unrelated poses they answer as CGAL's exact predicates do and as the cold query does, list the same
// contacts, do less work than the cold query on small steps, raise their front back to the root, keep their
// bounds, and refuse what they cannot serve.
#include "coherent_suite.hpp"
#include "support/errors.hpp"

#include <algorithm>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <utility>

namespace bvhlab::coherent_tests {
namespace {

using EvenVolumes = testing::AlternateTypes<0, testing::TraversalTestVolumes>::type;
INSTANTIATE_TYPED_TEST_SUITE_P(EvenVolumes, Coherent, EvenVolumes);

/// AABB trees, and a state whose first walk found no contact close to it: B moved along x from 1.0 to the
/// first pose without contact, 0.01 at a time.
class ClearOfContact : public ::testing::Test {
 protected:
  void SetUp() override {
    while (query_exact(a, b, pose).collides && pose.translation.x() < 3) pose.translation.x() += 0.01;
    // A new state's first query is the cold one; the second, at the same pose, walks from the root.
    ASSERT_FALSE(query_exact_coherent(a, b, pose, state).collides);
    ASSERT_FALSE(query_exact_coherent(a, b, pose, state).collides);
  }
  const Bvh<Aabb> a = Bvh<Aabb>::build(torus());
  const Bvh<Aabb> b = Bvh<Aabb>::build(soup());
  CoherentState state{CoherenceOptions{.max_cold_run = 0}};  // always the front: how it is walked
  RigidTransform pose = RigidTransform::translate(Vec3(1.0, 0.1, 0.05));
};

TEST_F(ClearOfContact, MovingApartRaisesTheFrontToTheRoot) {
  ASSERT_GT(state.front_size(), 10u);
  for (int k = 0; k < 250; ++k) {  // 0.01 per step: 2.5 units away, the boxes far apart
    pose.translation.x() += 0.01;
    ASSERT_EQ(query_exact_coherent(a, b, pose, state).collides, query_exact(a, b, pose).collides) << k;
  }
  EXPECT_EQ(state.front_size(), 1u);
  EXPECT_EQ(query_exact_coherent(a, b, pose, state).counters.bv_tests, 1u);
}

TEST_F(ClearOfContact, ObjectsApartTestTheRootAloneUntilTheyMeetAgain) {
  ASSERT_TRUE(query_exact(a, b, RigidTransform::translate(Vec3(1.0, 0.1, 0.05))).collides);
  for (const double x : {5.0, 5.1, 1.0, 5.0, 5.1}) {  // apart, apart again, back in contact (a jump), apart
    pose.translation.x() = x;
    const Result r = query_exact_coherent(a, b, pose, state);
    EXPECT_EQ(r.collides, x == 1.0) << x;
    if (x == 5.1) {
      EXPECT_EQ(state.front_size(), 1u);
      EXPECT_EQ(r.counters.bv_tests, 1u);
      EXPECT_EQ(r.counters.nodes_visited, 1u);
    }
  }
}

TEST(Coherent, TheStoredTreeStaysWithinMaxPairs) {
  const auto a = Bvh<Obb>::build(torus());
  const auto b = Bvh<Obb>::build(soup());
  CoherentState state(CoherenceOptions{.max_pairs = 16});
  std::size_t most = 0;
  for (const RigidTransform& pose : path(80, 0.01)) {
    ASSERT_EQ(query_exact_coherent(a, b, pose, state).collides, query_exact(a, b, pose).collides);
    most = std::max(most, state.stored_pairs());
  }
  EXPECT_LE(most, 16u);
  EXPECT_GT(most, 0u);
}

TEST_F(ClearOfContact, APoseJumpStartsFromTheRootAndJumpsInARowRunTheColdQuery) {
  pose.translation.x() += 0.01;
  ASSERT_FALSE(query_exact_coherent(a, b, pose, state).collides);
  EXPECT_EQ(state.jumps(), 0u);
  pose.translation.x() =
      -pose.translation.x();  // to the other side of A: B's box moves by far more than its radius
  const Result far = query_exact_coherent(a, b, pose, state);
  EXPECT_EQ(state.jumps(), 1u);
  // The walk from the root: the same work as a new state's (its second query at a pose: the first is cold),
  // and a front for the next step.
  CoherentState fresh;
  query_exact_coherent(a, b, pose, fresh);
  EXPECT_EQ(far.counters.bv_tests, query_exact_coherent(a, b, pose, fresh).counters.bv_tests);
  EXPECT_GE(state.stored_pairs(), 1u);
  pose.translation.y() += 2;  // a second jump right after: the cold query, and no front kept
  const Result again = query_exact_coherent(a, b, pose, state);
  EXPECT_EQ(state.jumps(), 2u);
  const Result cold = query_exact(a, b, pose);
  EXPECT_EQ(again.collides, cold.collides);
  EXPECT_EQ(again.counters.bv_tests, cold.counters.bv_tests);
  EXPECT_EQ(again.counters.nodes_visited, cold.counters.nodes_visited);
  EXPECT_EQ(state.stored_pairs(), cold.counters.bv_tests == 1 ? 1u : 0u);  // the root pair where apart
  pose.translation.y() -= 0.01;  // a step from there: no jump, a walk from the root stores the front
  const Result next = query_exact_coherent(a, b, pose, state);
  EXPECT_EQ(state.jumps(), 2u);
  EXPECT_EQ(next.collides, query_exact(a, b, pose).collides);
  EXPECT_GE(state.stored_pairs(), 1u);
}

TEST(Coherent, PosesThatKeepJumpingCostTheColdQueries) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  CoherentState state{CoherenceOptions{.max_jump = 0.05, .max_cold_run = 0}};
  int in_a_row = 0, apart = 0;
  for (const RigidTransform& pose : path(40, 0.2)) {  // each step moves B far past 0.05 of its radius
    const std::uint64_t jumps = state.jumps();
    const Result r = query_exact_coherent(a, b, pose, state);
    const Result cold = query_exact(a, b, pose);
    ASSERT_EQ(r.collides, cold.collides);
    if (state.jumps() == jumps || !state.jumping_on()) {
      if (r.counters.bv_tests == 1 && state.root_apart()) ++apart;  // the stored root pair, tested alone
      continue;
    }
    // The cold query's work, and at most the root pair (objects apart before) and the remembered contact
    // (one triangle pair a leaf) tried first.
    ++in_a_row;
    EXPECT_LE(r.counters.bv_tests, cold.counters.bv_tests + 1);
    EXPECT_LE(r.counters.nodes_visited, cold.counters.nodes_visited + 1);
    EXPECT_LE(r.counters.triangle_tests, cold.counters.triangle_tests + 1);
    // No front kept: at most the root pair, where the cold query found the objects apart.
    if (state.stored_pairs() != 0) EXPECT_TRUE(state.stored_pairs() == 1 && state.root_apart());
  }
  // The first query of a new state is answered cold too: each query, the first included, jumps in a row or
  // tests the root pair alone where the objects were apart. None walks.
  EXPECT_EQ(in_a_row + apart, 40);
  EXPECT_GT(in_a_row, 20);
}

TEST(Coherent, ANewStateStartsWithTheColdQuery) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  for (const double x : {0.7, 5.0}) {  // in contact, apart
    CoherentState state;
    const RigidTransform pose = RigidTransform::translate(Vec3(x, 0, 0));
    const Result first = query_exact_coherent(a, b, pose, state);
    const Result cold = query_exact(a, b, pose);
    EXPECT_EQ(first.collides, cold.collides);
    EXPECT_EQ(first.counters.bv_tests, cold.counters.bv_tests);
    EXPECT_EQ(first.counters.triangle_tests, cold.counters.triangle_tests);
    EXPECT_EQ(state.jumps(), 0u);  // not a jump from anywhere
    // In contact nothing is kept; apart, the root pair, which the next query tests alone.
    EXPECT_EQ(state.stored_pairs(), x < 1 ? 0u : 1u);
    if (x < 1) continue;
    EXPECT_EQ(query_exact_coherent(a, b, pose, state).counters.bv_tests, 1u);
  }
}

// A stored tree deeper than the root pair, without a contact, is tested at its root pair first: objects
// that moved apart are answered by that one test, and the root pair alone is stored.
TEST_F(ClearOfContact, ObjectsThatMovedApartAreAnsweredAtTheRootPair) {
  CoherentState steady{CoherenceOptions{.max_jump = 1e9, .max_cold_run = 0}};  // never a jump, never cold
  ASSERT_FALSE(query_exact_coherent(a, b, pose, steady).collides);             // the cold one
  ASSERT_FALSE(query_exact_coherent(a, b, pose, steady).collides);             // the walk from the root
  ASSERT_GT(steady.front_size(), 10u);
  pose.translation.x() = 5.0;
  const Result apart = query_exact_coherent(a, b, pose, steady);
  EXPECT_FALSE(apart.collides);
  EXPECT_EQ(apart.counters.bv_tests, 1u);
  EXPECT_EQ(apart.counters.nodes_visited, 1u);
  EXPECT_TRUE(steady.root_apart());
}

// Where the root pair keeps overlapping, its test waits 1, 2, 4 ... up to 64 queries after each one that
// found it so; one that finds it apart makes the next due at once.
TEST(Coherent, TheRootPairsTestBacksOffWhileItOverlaps) {
  CoherentState state;
  EXPECT_TRUE(state.root_check_due());
  int expected = 1;
  for (int k = 0; k < 9; ++k) {
    state.root_checked(false);
    int skipped = 0;
    while (!state.root_check_due() && skipped < 1000) ++skipped;
    EXPECT_EQ(skipped, expected) << k;
    expected = std::min(64, 2 * expected);
  }
  state.root_checked(true);
  EXPECT_TRUE(state.root_check_due());
  state.root_checked(false);
  state.reset();
  EXPECT_TRUE(state.root_check_due());
}

TEST(Coherent, ARepeatedContactIsAnsweredByItsWitness) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  CoherentState state;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.7, 0, 0));
  ASSERT_TRUE(query_exact_coherent(a, b, pose, state).collides);  // a new state's first query: cold
  const Result first = query_exact_coherent(a, b, pose, state);   // the walk from the root
  ASSERT_TRUE(first.collides);
  EXPECT_GT(state.stored_pairs(), 1u);  // the tree walked up to the contact: the next walk starts there
  const Result again = query_exact_coherent(a, b, pose, state);
  EXPECT_TRUE(again.collides);
  EXPECT_EQ(again.witness, first.witness);
  EXPECT_EQ(again.counters.bv_tests, 0u);
  EXPECT_EQ(state.witness_hits(), 1u);
}

// In a cold turn (the front lost to queries from the root) the remembered contact is still tried first, and
// a cold answer's contact is remembered for the next query.
TEST(Coherent, AColdTurnKeepsTheRememberedContact) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  CoherentState state;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.7, 0, 0));
  ASSERT_TRUE(query_exact_coherent(a, b, pose, state).collides);  // cold, a new state's first query
  ASSERT_TRUE(query_exact_coherent(a, b, pose, state).collides);  // the walk from the root
  ASSERT_TRUE(state.witness.has_value());
  Counters costly;  // a walk far costlier than the cold query: a cold turn of two queries begins
  costly.bv_tests = 1'000'000;
  state.record_cost(costly, 0, CoherentState::Start::Front);
  ASSERT_EQ(state.cold_turns_left(), 2u);
  const Result by_contact = query_exact_coherent(a, b, pose, state);
  EXPECT_TRUE(by_contact.collides);
  EXPECT_EQ(by_contact.counters.bv_tests, 0u);
  EXPECT_EQ(state.witness_hits(), 1u);
  EXPECT_EQ(state.cold_turns_left(), 1u);  // the hit took a turn's place
  // Without a contact to try, the cold query answers and its contact is remembered.
  state.witness.reset();
  state.record_cost(costly, 0, CoherentState::Start::Front);
  ASSERT_GT(state.cold_turns_left(), 1u);
  const std::uint32_t turns = state.cold_turns_left();
  const Result cold = query_exact_coherent(a, b, pose, state);
  EXPECT_TRUE(cold.collides);
  EXPECT_GT(cold.counters.bv_tests, 0u);
  EXPECT_EQ(state.cold_turns_left(), turns - 1);
  ASSERT_TRUE(state.witness.has_value());
  EXPECT_EQ(query_exact_coherent(a, b, pose, state).counters.bv_tests, 0u);
  EXPECT_EQ(state.witness_hits(), 2u);
}

/// The stored pairs marked as leading to the remembered contact: a chain from the root pair to the contact's
/// leaf pair, one marked child per marked inner pair, and no other mark (none without a contact). Returns
/// the chain's length.
std::size_t checked_witness_path(CoherentState& state) {
  const std::vector<FrontPair>& pairs = state.pairs();
  const auto marked =
      std::count_if(pairs.begin(), pairs.end(), [](const FrontPair& p) { return p.leads_to_witness != 0; });
  if (!state.witness || pairs.empty()) {
    EXPECT_EQ(marked, 0);
    return 0;
  }
  std::size_t at = 0, length = 1;
  EXPECT_TRUE(pairs[0].leads_to_witness);
  while (pairs[at].count > 0) {
    const FrontPair& parent = pairs[at];
    int marked_children = 0;
    for (std::uint32_t c = 0; c < parent.count; ++c)
      if (pairs[parent.first + c].leads_to_witness) ++marked_children, at = parent.first + c;
    EXPECT_EQ(marked_children, 1);
    if (marked_children != 1) return 0;
    ++length;
  }
  EXPECT_EQ(std::make_pair(pairs[at].a, pairs[at].b), *state.witness);
  EXPECT_EQ(std::size_t(marked), length);
  return length;
}

template <TreeVolume BV>
void expect_paths_to_the_witness() {
  const auto a = Bvh<BV>::build(torus());
  const auto b = Bvh<BV>::build(soup());
  CoherentState state{CoherenceOptions{.max_cold_run = 0}};
  int walks_to_a_new_contact = 0;
  for (const RigidTransform& pose : path(160)) {
    const auto witness = state.witness;
    ASSERT_EQ(query_exact_coherent(a, b, pose, state).collides, query_exact(a, b, pose).collides);
    const std::size_t length = checked_witness_path(state);
    if (state.witness && state.witness != witness && length > 1) ++walks_to_a_new_contact;
  }
  EXPECT_GT(walks_to_a_new_contact, 3);
}

// After a walk that found a contact, the stored tree marks the way to it: a walk after the contact is lost
// goes that way first (the contact moved, most likely not far).
TEST(Coherent, TheStoredTreeMarksTheWayToItsContact) {
  expect_paths_to_the_witness<Aabb>();
  expect_paths_to_the_witness<Obb>();
}

// The same path twice: one state as it is, one whose marks are wiped before every query (its walks go in
// the stored order). Both answer as the cold query; the one that goes the marked way first tests fewer pairs.
TEST(Coherent, AWalkAfterALostContactGoesTheMarkedWayFirst) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  CoherentState marked{CoherenceOptions{.max_cold_run = 0}}, unmarked{CoherenceOptions{.max_cold_run = 0}};
  Counters marked_work, unmarked_work;
  for (const RigidTransform& pose : path(240)) {
    for (FrontPair& p : unmarked.pairs()) p.leads_to_witness = 0;
    const Result cold = query_exact(a, b, pose);
    const Result r = query_exact_coherent(a, b, pose, marked);
    const Result u = query_exact_coherent(a, b, pose, unmarked);
    ASSERT_EQ(r.collides, cold.collides);
    ASSERT_EQ(u.collides, cold.collides);
    marked_work += r.counters;
    unmarked_work += u.counters;
  }
  EXPECT_LT(marked_work.bv_tests, unmarked_work.bv_tests);
  EXPECT_LT(marked_work.triangle_tests, unmarked_work.triangle_tests);
}

// Judged by work, a walk pays for the tree it stores (five units a pair): a walk of the cold query's
// counters that stores pairs costs more than the cold query, and the next queries start from the root.
TEST(Coherent, AWalksStoredPairsCountAsItsWork) {
  Counters work;
  work.nodes_visited = 100;
  work.bv_tests = 100;
  CoherentState state;
  state.record_cost(work, 0, CoherentState::Start::Root);
  state.record_cost(work, 0, CoherentState::Start::Front);
  EXPECT_EQ(state.cold_turns_left(), 0u);  // the same work: the front does not lose
  state.record_cost(work, 0, CoherentState::Start::Front, 100);
  EXPECT_EQ(state.cold_turns_left(), 2u);
  CoherentState timed{CoherenceOptions{.judge = CoherenceOptions::Judge::time}};  // seconds alone
  timed.record_cost(work, 1.0, CoherentState::Start::Root);
  timed.record_cost(work, 1.0, CoherentState::Start::Front, 100);
  EXPECT_EQ(timed.cold_turns_left(), 0u);
}

// The front is compared with the median of the last queries from the root: one far costlier query (a new
// state's first, at a pose where much overlaps) does not make every walk look cheap.
TEST(Coherent, OneCostlyQueryFromTheRootDoesNotStandForAll) {
  Counters costly, cheap, walk;
  costly.bv_tests = 40'000;
  cheap.bv_tests = 600;
  walk.bv_tests = 1'000;
  CoherentState state;
  state.record_cost(costly, 0, CoherentState::Start::Root);
  state.record_cost(cheap, 0, CoherentState::Start::Root);
  state.record_cost(walk, 0, CoherentState::Start::Front);
  EXPECT_EQ(state.cold_turns_left(), 2u);  // the walk costs more than the usual query from the root
  // With more samples, the median: two costly ones among five leave it at the cheap queries' cost.
  CoherentState five;
  for (const Counters& c : {costly, cheap, costly, cheap, cheap})
    five.record_cost(c, 0, CoherentState::Start::Root);
  five.record_cost(walk, 0, CoherentState::Start::Front);
  EXPECT_EQ(five.cold_turns_left(), 2u);
  // And a walk cheaper than that median keeps walking.
  CoherentState pays;
  for (const Counters& c : {costly, walk, costly, walk, costly})
    pays.record_cost(c, 0, CoherentState::Start::Root);
  pays.record_cost(cheap, 0, CoherentState::Start::Front);
  EXPECT_EQ(pays.cold_turns_left(), 0u);
}

TEST(Coherent, RefusesWhatItCannotServe) {
  const auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  const auto other = Bvh<Aabb>::build(testing::make_torus(0.5, 0.2, 12, 8));
  CoherentState state;
  query_exact_coherent(a, b, RigidTransform::identity(), state);
  EXPECT_NE(testing::error_of([&] {
              query_exact_coherent(a, other, RigidTransform::identity(), state);
            }).find("made for other trees"),
            std::string::npos);
  RigidTransform scaled;
  scaled.rotation *= 2;
  EXPECT_THROW(query_exact_coherent(a, b, scaled, state), std::invalid_argument);
  {
    std::promise<void> taken, done;
    std::thread other([&] {
      const CoherentState::InUse held(state);  // as another thread's query would
      taken.set_value();
      done.get_future().wait();
    });
    taken.get_future().wait();
    const std::string error =
        testing::error_of([&] { query_exact_coherent(a, b, RigidTransform::identity(), state); });
    CoherentState copy = state;  // a copy is a state of its own, not in use
    const std::string copy_error =
        testing::error_of([&] { query_exact_coherent(a, b, RigidTransform::identity(), copy); });
    done.set_value();
    other.join();
    EXPECT_NE(error.find("in use by another query"), std::string::npos) << error;
    EXPECT_EQ(copy_error, "(no error)");
  }
  EXPECT_NO_THROW(query_exact_coherent(a, b, RigidTransform::identity(), state));
  {
    // A thread that holds the state for a loop of queries runs them (the engine's runs do so).
    const CoherentState::InUse held(state);
    EXPECT_NO_THROW(query_exact_coherent(a, b, RigidTransform::identity(), state));
    EXPECT_NO_THROW(query_exact_coherent(a, b, RigidTransform::identity(), state));
  }
  EXPECT_NO_THROW(query_exact_coherent(a, b, RigidTransform::identity(), state));
  EXPECT_THROW(CoherentState(CoherenceOptions{.max_pairs = 0}), std::invalid_argument);
  EXPECT_THROW(CoherentState(CoherenceOptions{.max_jump = std::nan("")}), std::invalid_argument);
  EXPECT_THROW(CoherentState(CoherenceOptions{.max_jump = -1}), std::invalid_argument);
}

TEST(Coherent, ATreeMadeAnewWhereTheOldOneWasIsRefused) {
  // The same mesh, the same node count, the same address: still another tree, whose node pairs the stored
  // front does not index (a deforming object rebuilt between frames).
  const auto b = Bvh<Aabb>::build(soup());
  std::optional<Bvh<Aabb>> a(Bvh<Aabb>::build(torus()));
  const Bvh<Aabb>* address = &*a;
  CoherentState state;
  query_exact_coherent(*a, b, RigidTransform::identity(), state);
  a.emplace(Bvh<Aabb>::build(torus()));
  ASSERT_EQ(&*a, address);
  EXPECT_NE(testing::error_of([&] {
              query_exact_coherent(*a, b, RigidTransform::identity(), state);
            }).find("made for other trees"),
            std::string::npos);
}

TEST(Coherent, ARefittedTreeKeepsItsState) {
  // The torus swells frame by frame into B, which stays where it is (at the last pose along x where they
  // touch): refit keeps the topology, so the front carries over, and the answers are the cold query's on the
  // refitted tree.
  auto a = Bvh<Aabb>::build(torus());
  const auto b = Bvh<Aabb>::build(soup());
  RigidTransform pose = RigidTransform::translate(Vec3(1.0, 0.1, 0.05));
  while (query_exact(a, b, pose).collides) pose.translation.x() += 0.01;
  pose.translation.x() -= 0.01;
  CoherentState state;
  int colliding = 0;
  Counters cold_work, coherent_work;
  for (int frame = 0; frame < 40; ++frame) {
    Mesh swollen = torus();
    for (Vec3& v : swollen.vertices) v *= 0.97 + 0.0015 * frame;
    a.refit(swollen);
    const Result cold = query_exact(a, b, pose);
    const Result r = query_exact_coherent(a, b, pose, state);
    ASSERT_EQ(r.collides, cold.collides) << "frame " << frame;
    colliding += r.collides;
    cold_work += cold.counters;
    coherent_work += r.counters;
  }
  EXPECT_GT(colliding, 3) << "frames in contact";  // both answers along the way
  EXPECT_LT(colliding, 37) << "frames in contact";
  EXPECT_EQ(state.jumps(), 0u);
  EXPECT_LT(coherent_work.bv_tests, cold_work.bv_tests);
}

}  // namespace
}  // namespace bvhlab::coherent_tests
