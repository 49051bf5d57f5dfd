// The pair-traversal driver itself: queue policies, the order and count of hook calls, limits, and a
// strategy written only as hooks + policies.
#include "adb/adb_density.hpp"
#include "adb/tree.hpp"
#include "support/generated_meshes.hpp"
#include "traversal/adb.hpp"
#include "traversal/driver.hpp"
#include "traversal/exact.hpp"
#include "traversal/four_ary_heap.hpp"
#include "volumes/aabb.hpp"
#include "volumes/restricted_box.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <queue>
#include <random>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

struct Scene {
  Mesh a = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh b = testing::make_random_soup(500, 0.1, 3);
  Bvh<Aabb> tree_a = Bvh<Aabb>::build(a);
  Bvh<Aabb> tree_b = Bvh<Aabb>::build(b);
};

TEST(QueuePolicies, TakeInTheirOrder) {
  using Pair = QueuedPair<Aabb, double>;
  auto keyed = [](double key) { return Pair{key, 0, 0, {}, {}, {}}; };
  DepthFirst::Queue<Pair> stack;
  BestFirst::Queue<Pair> best;
  OrderedDepthFirst::Queue<Pair> ordered;
  for (double key : {1.0, 3.0, 2.0}) {
    stack.push(keyed(key));
    best.push(keyed(key));
    ordered.push(keyed(key));
  }
  EXPECT_EQ(stack.pop().key, 2.0);  // the last admitted
  EXPECT_EQ(best.pop().key, 3.0);   // the highest key
  EXPECT_EQ(ordered.pop().key, 3.0);
  // Ordered depth-first: the latest admissions come first, highest key first, before anything older.
  ordered.push(keyed(0.5));
  ordered.push(keyed(5.0));
  ordered.push(keyed(0.0));
  std::vector<double> rest;
  while (!ordered.empty()) rest.push_back(ordered.pop().key);
  EXPECT_EQ(rest, (std::vector<double>{5.0, 0.5, 0.0, 2.0, 1.0}));
  std::vector<double> best_rest;
  while (!best.empty()) best_rest.push_back(best.pop().key);
  EXPECT_EQ(best_rest, (std::vector<double>{2.0, 1.0}));
}

// The four-ary heap and the best-first queue around it give back the highest key at every pop, against
// std::priority_queue on random pushes and pops (heaps of every fill, the last group of children partial).
// The queue's heap keeps its first pairs in place (an InlineStack): it moves to the heap and grows there.
TEST(QueuePolicies, BestFirstTakesTheHighestKeyAsABinaryHeapWould) {
  struct Keyed {
    double key;
    int id;
  };
  std::mt19937 random(7);
  std::uniform_int_distribution<int> key_of(0, 40);  // few keys: many ties
  FourAryHeap<Keyed> heap;
  BestFirst::Queue<Keyed> best;
  std::priority_queue<double> reference;
  for (int step = 0; step < 20000; ++step) {
    const bool push = reference.empty() || random() % 5 < 3 - (step > 15000 ? 2 : 0);
    if (push) {
      const Keyed p{double(key_of(random)), step};
      heap.push(p);
      best.push(p);
      reference.push(p.key);
      continue;
    }
    ASSERT_EQ(heap.top().key, reference.top()) << "step " << step;
    ASSERT_EQ(best.top().key, reference.top()) << "step " << step;
    EXPECT_EQ(best.pop().key, reference.top());
    heap.pop();
    reference.pop();
    ASSERT_EQ(heap.size(), reference.size());
  }
  EXPECT_TRUE(heap.empty() == reference.empty());
}

// The depth-first stack keeps its first pairs in place and moves to the heap past them: the pairs come back
// last in, first out, whole, across the move (a rbox pair: 168 bytes of walker state), and when pushed and
// popped around the boundary.
TEST(QueuePolicies, TheInlineStackKeepsEveryPairAcrossItsMoveToTheHeap) {
  using Pair = QueuedPair<RestrictedBox, double>;
  InlineStack<Pair, 4> stack;
  const auto pair = [](std::uint32_t k) {
    Pair p{double(k), k, 1000 + k, {}, {}, {}};
    p.wa.half = {double(k), 0.5, -1.0};
    p.wb.depth = 3 * k;
    return p;
  };
  EXPECT_TRUE(stack.empty());
  for (std::uint32_t k = 0; k < 3; ++k) stack.push_back(pair(k));
  stack.pop_back();  // 0, 1 left
  for (std::uint32_t k = 2; k < 40; ++k) {
    stack.push_back(pair(k));
    if (k % 5 == 0) stack.pop_back();  // on either side of the boundaries at 4, 8, 16 and 32
  }
  std::vector<std::uint32_t> expected = {0, 1};
  for (std::uint32_t k = 2; k < 40; ++k)
    if (k % 5 != 0) expected.push_back(k);
  ASSERT_EQ(stack.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(stack[i].a, expected[i]);
  while (!stack.empty()) {
    const Pair top = stack.back();
    const Pair want = pair(expected.back());
    EXPECT_EQ(top.key, want.key);
    EXPECT_EQ(top.b, want.b);
    EXPECT_EQ(top.wa.half, want.wa.half);
    EXPECT_EQ(top.wb.depth, want.wb.depth);
    expected.pop_back();
    stack.pop_back();
  }
  EXPECT_TRUE(expected.empty());
}

/// The exact hooks with a key (A's node size), so that the key-ordered queue policies can run them.
struct KeyedExactHooks : ExactHooks<Aabb, QueuedPair<Aabb, float>> {
  using ExactHooks::ExactHooks;
  const Bvh<Aabb>* tree_a = nullptr;
  Admission admit(Pair& p, bool overlap) {
    p.key = tree_a->size(p.a);
    return ExactHooks::admit(p, overlap);
  }
};

template <class QueuePolicy>
Result exact_with(const Scene& scene, const RigidTransform& pose, ContactMode mode) {
  Result result;
  const auto context = VolumeWalker<Aabb>::make_context(pose);
  const TreePair<Aabb> trees(scene.tree_a, scene.tree_b, pose, context, result.counters);
  KeyedExactHooks hooks(trees, result, mode);
  hooks.tree_a = &scene.tree_a;
  Unlimited limit;
  traverse<QueuePolicy, SplitLarger>(trees, hooks, limit);
  std::sort(result.contacts.begin(), result.contacts.end());
  return result;
}

TEST(Driver, EveryQueuePolicyGivesTheSameExactAnswer) {
  const Scene scene;
  std::mt19937_64 rng(41);
  int colliding = 0;
  for (int k = 0; k < 150; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    Result reference = query_exact(scene.tree_a, scene.tree_b, pose, ContactMode::All);
    std::sort(reference.contacts.begin(), reference.contacts.end());
    for (const Result& r : {exact_with<DepthFirst>(scene, pose, ContactMode::All),
                            exact_with<BestFirst>(scene, pose, ContactMode::All),
                            exact_with<OrderedDepthFirst>(scene, pose, ContactMode::All)}) {
      ASSERT_EQ(r.contacts, reference.contacts) << "pose " << k;
      // Every overlapping pair is visited whatever the order: the same work.
      EXPECT_EQ(r.counters.bv_tests, reference.counters.bv_tests);
      EXPECT_EQ(r.counters.nodes_visited, reference.counters.nodes_visited);
      EXPECT_EQ(r.counters.triangle_tests, reference.counters.triangle_tests);
    }
    const bool collides = !reference.contacts.empty();
    colliding += collides;
    for (const Result& r : {exact_with<DepthFirst>(scene, pose, ContactMode::First),
                            exact_with<BestFirst>(scene, pose, ContactMode::First),
                            exact_with<OrderedDepthFirst>(scene, pose, ContactMode::First)}) {
      ASSERT_EQ(r.collides, collides) << "pose " << k;
      if (collides) {
        ASSERT_TRUE(r.witness.has_value());
        EXPECT_TRUE(std::binary_search(reference.contacts.begin(), reference.contacts.end(), *r.witness));
      }
    }
  }
  EXPECT_GT(colliding, 20);
  EXPECT_LT(colliding, 130);
}

// ---- Hook calls, recorded ---------------------------------------------------------------------------------

/// Exact-like hooks that log every call: "E" evaluate, "A" admit, "L" leaf_pair, "C<n>" children_evaluated
/// with n children, "F" finish. Options make admit decide at a given call and add the children hook.
template <class BV, bool kChildrenHook>
struct RecordingHooks {
  using Pair = QueuedPair<BV>;

  explicit RecordingHooks(const TreePair<BV>& trees) : trees(trees) {}

  const TreePair<BV>& trees;
  std::vector<std::string> log;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> evaluated, admitted, leaves;
  int decide_at_admit = -1;  ///< the admit call (0-based) that answers Decide
  int finished = 0;
  Ended ended = Ended::QueueEmpty;
  std::size_t left_in_queue = 0;
  std::pair<std::uint32_t, std::uint32_t> next_in_queue{};

  bool evaluate(const Pair& p) {
    log.push_back("E");
    evaluated.emplace_back(p.a, p.b);
    return trees.overlap(p);
  }
  Admission admit(Pair& p, bool overlap) {
    log.push_back("A");
    admitted.emplace_back(p.a, p.b);
    if (static_cast<int>(admitted.size()) - 1 == decide_at_admit) return Admission::Decide;
    return overlap ? Admission::Queue : Admission::Drop;
  }
  Step leaf_pair(const Pair& p) {
    log.push_back("L");
    leaves.emplace_back(p.a, p.b);
    return Step::Continue;
  }
  Step children_evaluated(const Pair&, const bool*, int count) requires kChildrenHook {
    log.push_back("C" + std::to_string(count));
    return Step::Continue;
  }
  template <class Queue>
  void finish(Queue& queue, Ended why) {
    log.push_back("F");
    ++finished;
    ended = why;
    left_in_queue = 0;
    if (!queue.empty()) next_in_queue = {queue.top().a, queue.top().b};
    while (!queue.empty()) queue.pop(), ++left_in_queue;
  }
};

template <class Descent, bool kChildrenHook, class BV = Aabb, class Limit = Unlimited>
RecordingHooks<BV, kChildrenHook> record(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& pose,
                                         Counters& counters, Limit limit = {}, int decide_at_admit = -1) {
  const auto context = VolumeWalker<BV>::make_context(pose);
  const TreePair<BV> trees(a, b, pose, context, counters);
  RecordingHooks<BV, kChildrenHook> hooks(trees);
  hooks.decide_at_admit = decide_at_admit;
  traverse<DepthFirst, Descent>(trees, hooks, limit);
  return hooks;
}

TEST(Driver, HooksAreCalledAsDocumented) {
  const Scene scene;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.6, 0.1, 0));
  for (bool with_children_hook : {false, true}) {
    Counters counters;
    const auto hooks = with_children_hook
                           ? record<SplitLarger, true>(scene.tree_a, scene.tree_b, pose, counters).log
                           : record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, counters).log;
    // One evaluate per BV test, each followed (at once, or after its siblings and the children hook) by
    // its admit; one finish at the end, as nothing decided.
    ASSERT_GT(counters.bv_tests, 10u);
    EXPECT_EQ(std::count(hooks.begin(), hooks.end(), "E"), static_cast<long>(counters.bv_tests));
    EXPECT_EQ(std::count(hooks.begin(), hooks.end(), "A"), static_cast<long>(counters.bv_tests));
    EXPECT_EQ(hooks.front(), "E");
    EXPECT_EQ(hooks.back(), "F");
    EXPECT_EQ(std::count(hooks.begin(), hooks.end(), "F"), 1);
    const long leaves = std::count(hooks.begin(), hooks.end(), "L");
    const long expansions = (static_cast<long>(counters.bv_tests) - 1) / 2;  // SplitLarger: two children
    EXPECT_EQ(leaves + expansions, static_cast<long>(counters.nodes_visited));
    if (with_children_hook) {
      EXPECT_EQ(std::count(hooks.begin(), hooks.end(), "C2"), expansions);
      // Staged: E E C2 A A for every expansion.
      for (std::size_t i = 0; i < hooks.size(); ++i) {
        if (hooks[i] == "C2") {
          ASSERT_GE(i, 2u);
          ASSERT_LT(i + 2, hooks.size());
          EXPECT_EQ(hooks[i - 2] + hooks[i - 1] + hooks[i + 1] + hooks[i + 2], "EEAA");
        }
      }
    } else {
      for (std::size_t i = 0; i + 1 < hooks.size(); ++i) {
        if (hooks[i] == "E") {
          EXPECT_EQ(hooks[i + 1], "A");  // each child admitted right after its test
        }
      }
    }
  }
}

TEST(Driver, LeafPairsAndChildPairsAreWhatTheDescentSays) {
  const Scene scene;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.6, 0.1, 0));
  Counters counters;
  const auto split_both = record<SplitBoth, true>(scene.tree_a, scene.tree_b, pose, counters);
  for (const auto& [i, j] : split_both.leaves)
    EXPECT_TRUE(scene.tree_a.node(i).is_leaf() && scene.tree_b.node(j).is_leaf());
  // Both inner: four children; one leaf: two; never anything else.
  for (const auto& entry : split_both.log) {
    if (entry[0] == 'C') {
      EXPECT_TRUE(entry == "C4" || entry == "C2") << entry;
    }
  }
  EXPECT_NE(std::find(split_both.log.begin(), split_both.log.end(), "C4"), split_both.log.end());
  // The first pair evaluated is the root; the first expansion of SplitBoth is the roots' four children.
  ASSERT_GE(split_both.evaluated.size(), 5u);
  EXPECT_EQ(split_both.evaluated[0], (std::pair<std::uint32_t, std::uint32_t>{0, 0}));
  const TreeNode& ra = scene.tree_a.node(0);
  const TreeNode& rb = scene.tree_b.node(0);
  EXPECT_EQ(split_both.evaluated[1], (std::pair{ra.left(), rb.left()}));
  EXPECT_EQ(split_both.evaluated[2], (std::pair{ra.left(), rb.right()}));
  EXPECT_EQ(split_both.evaluated[3], (std::pair{ra.right(), rb.left()}));
  EXPECT_EQ(split_both.evaluated[4], (std::pair{ra.right(), rb.right()}));
}

TEST(Driver, ADecisionEndsTheTraversalWithoutFinish) {
  const Scene scene;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.6, 0.1, 0));
  Counters at_root;
  const auto root = record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, at_root, Unlimited{}, 0);
  EXPECT_EQ(root.log, (std::vector<std::string>{"E", "A"}));
  EXPECT_EQ(at_root.bv_tests, 1u);
  EXPECT_EQ(at_root.nodes_visited, 0u);
  Counters later;
  const auto fifth = record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, later, Unlimited{}, 4);
  EXPECT_EQ(fifth.finished, 0);
  EXPECT_EQ(fifth.log.back(), "A");
  EXPECT_EQ(fifth.admitted.size(), 5u);
}

TEST(Driver, ABudgetOfBvTestsStopsItExactlyAndKeepsTheUnexpandedPair) {
  const Scene scene;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.6, 0.1, 0));
  Counters unlimited;
  record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, unlimited);
  ASSERT_GT(unlimited.bv_tests, 40u);
  for (std::uint64_t cap : {1u, 2u, 3u, 10u, 39u}) {
    Counters counters;
    const auto hooks = record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, counters,
                                                  BudgetLimit(Budget{.max_bv_tests = cap, .deadline_us = 0}));
    EXPECT_EQ(counters.bv_tests, cap);
    EXPECT_EQ(hooks.finished, 1);
    EXPECT_EQ(hooks.ended, Ended::BudgetExhausted);
    // The pair being expanded went back onto the queue, on top: it is taken next. An odd cap runs out at
    // a first child (nothing of that expansion tested), an even one at the second, after the first
    // (SplitLarger's right child) was tested.
    ASSERT_GE(hooks.left_in_queue, 1u);
    const auto [next_a, next_b] = hooks.next_in_queue;
    const auto [last_a, last_b] = hooks.evaluated.back();
    if (cap == 1) {
      EXPECT_EQ(hooks.next_in_queue, hooks.evaluated.back());  // the root
    }
    if (cap % 2 == 0) {
      EXPECT_TRUE((last_b == next_b && last_a == scene.tree_a.node(next_a).right()) ||
                  (last_a == next_a && last_b == scene.tree_b.node(next_b).right()))
          << "cap " << cap;
    }
  }
  // A budget the traversal does not reach changes nothing.
  Counters roomy;
  const auto hooks = record<SplitLarger, false>(
      scene.tree_a, scene.tree_b, pose, roomy,
      BudgetLimit(Budget{.max_bv_tests = unlimited.bv_tests + 1, .deadline_us = 0}));
  EXPECT_EQ(roomy.bv_tests, unlimited.bv_tests);
  EXPECT_EQ(roomy.nodes_visited, unlimited.nodes_visited);
  EXPECT_EQ(hooks.ended, Ended::QueueEmpty);
}

TEST(Driver, ADeadlineIsCheckedBeforeEveryPop) {
  const Scene scene;
  const RigidTransform pose = RigidTransform::translate(Vec3(0.6, 0.1, 0));
  Counters unlimited;
  record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, unlimited);
  ASSERT_GT(unlimited.nodes_visited, 16u);
  Counters counters;
  // A deadline long past by the first check (a nanosecond after the start): the root was tested before the
  // loop, and the check before the first pop ends it.
  const auto hooks = record<SplitLarger, false>(scene.tree_a, scene.tree_b, pose, counters,
                                                BudgetLimit(Budget{.max_bv_tests = 0, .deadline_us = 1e-3}));
  EXPECT_EQ(counters.nodes_visited, 0u);
  EXPECT_EQ(counters.bv_tests, 1u);
  EXPECT_EQ(hooks.ended, Ended::BudgetExhausted);
  EXPECT_GE(hooks.left_in_queue, 1u);
}

// ---- A strategy as hooks + policies ---------------------------------------------------------------------

// A crude stand-in annotation (pc = min(g^3, triangles below the node)); the estimates only order the
// descent here, so their quality does not matter.
Tree<Aabb, AdbDensity> crude_annotation(Bvh<Aabb> bvh) {
  std::vector<std::uint8_t> counts;
  for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
    counts.push_back(static_cast<std::uint8_t>(std::min(8u, end - begin)));
  return {std::move(bvh), AdbDensity::make_storage({2, 0.5}, std::move(counts))};
}

TEST(Driver, ProbabilityOrderedDepthFirstIsHooksAndAQueuePolicy) {
  const Scene scene;
  const auto tree_a = crude_annotation(scene.tree_a);
  const auto tree_b = crude_annotation(scene.tree_b);
  const auto model = AdbDensity::estimator(tree_a.density, tree_b.density);
  AdbOptions options;
  options.exact_leaves = true;  // exact leaves: the answer must be the exact one, in any order
  std::mt19937_64 rng(43);
  int colliding = 0;
  for (int k = 0; k < 150; ++k) {
    const RigidTransform pose = testing::random_pose(rng, 1.5);
    Result result;
    const auto context = VolumeWalker<Aabb>::make_context(pose);
    const TreePair<Aabb> trees(tree_a.bvh, tree_b.bvh, pose, context, result.counters);
    const auto estimate = [&](const Box& box_a, const Box& box_b, double overlap, std::uint32_t i,
                              std::uint32_t j) { return model(i, box_a, j, box_b, overlap); };
    AdbHooks<Aabb, decltype(estimate)> hooks(trees, result, options, estimate);
    Unlimited limit;
    traverse<OrderedDepthFirst, SplitBoth>(trees, hooks, limit);
    const Result exact = query_exact(scene.tree_a, scene.tree_b, pose);
    ASSERT_EQ(result.collides, exact.collides) << "pose " << k;
    EXPECT_TRUE(result.exact);
    colliding += exact.collides;
  }
  EXPECT_GT(colliding, 20);
  EXPECT_LT(colliding, 130);
}

}  // namespace
}  // namespace bvhlab
