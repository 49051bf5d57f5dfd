// The broad phases against brute force (and brute force against Box::overlaps), their input rules and the
// dynamic tree's fattened boxes. World boxes: test_world_box.cpp.
#include "bench/core/generators.hpp"
#include "support/random_draws.hpp"
#include "traversal/broad_phase/registry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using testing::draw_vec3;

std::vector<ObjectPair> overlapping_pairs(const std::vector<Box>& boxes) {
  std::vector<ObjectPair> out;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j)
      if (boxes[i].overlaps(boxes[j])) out.push_back({i, j});
  return out;
}

Box box_at(const Vec3& centre, const Vec3& half) {
  return {centre - half, centre + half};
}

// Boxes spread uniformly over [-100, 100]^3, or gathered in a few tight clusters (many overlaps).
std::vector<Box> random_boxes(std::size_t n, bool clustered, std::mt19937_64& rng) {
  std::vector<Vec3> clusters;
  for (int k = 0; k < 5; ++k) clusters.push_back(generators::uniform_point(rng, -100, 100));
  std::normal_distribution<double> spread(0, 6);
  std::vector<Box> boxes;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 centre = clustered ? Vec3(clusters[i % clusters.size()] + draw_vec3(spread, rng))
                                  : generators::uniform_point(rng, -100, 100);
    boxes.push_back(box_at(centre, generators::uniform_point(rng, 0.2, 4)));
  }
  return boxes;
}

// One frame of motion: a small random step for every box, a far jump for about one box in fifty, and a
// change of size now and then.
void random_walk(std::vector<Box>& boxes, std::mt19937_64& rng) {
  std::normal_distribution<double> step(0, 0.4);
  for (Box& b : boxes) {
    Vec3 centre = b.center() + draw_vec3(step, rng);
    Vec3 half = b.extent() * 0.5;
    if (generators::uniform(rng, 0, 1) < 0.02) centre = generators::uniform_point(rng, -150, 150);
    if (generators::uniform(rng, 0, 1) < 0.05) half = generators::uniform_point(rng, 0.2, 6);
    b = box_at(centre, half);
  }
}

TEST(BroadPhase, BruteForceEqualsBoxOverlaps) {
  std::mt19937_64 rng(3);
  const std::vector<Box> boxes = random_boxes(400, true, rng);
  BruteForce brute;
  brute.update(boxes);
  const auto expected = overlapping_pairs(boxes);
  EXPECT_GT(expected.size(), 100u);
  EXPECT_EQ(brute.pairs(), expected);
}

TEST(BroadPhase, EveryBroadPhaseEqualsBruteForceOverMovingFrames) {
  struct Case {
    std::size_t n;
    bool clustered;
    std::uint64_t seed;
  };
  const Case cases[] = {{2, false, 1},  {10, true, 2},    {300, false, 3},
                        {300, true, 4}, {2000, false, 5}, {1200, true, 6}};
  for (const Case& c : cases) {
    SCOPED_TRACE("n = " + std::to_string(c.n) + (c.clustered ? ", clustered" : ", spread") + ", seed " +
                 std::to_string(c.seed));
    std::mt19937_64 rng(c.seed);
    std::vector<Box> boxes = random_boxes(c.n, c.clustered, rng);
    std::vector<std::unique_ptr<AnyBroadPhase>> phases;
    for (const std::string& name : broad_phase_names()) phases.push_back(make_broad_phase(name));
    std::size_t total = 0;
    for (int frame = 0; frame < 55; ++frame) {
      const auto expected = overlapping_pairs(boxes);
      for (auto& phase : phases) {
        phase->update(boxes);
        ASSERT_EQ(phase->pairs(), expected) << phase->name() << ", frame " << frame;
      }
      total += expected.size();
      random_walk(boxes, rng);
    }
    if (c.n >= 300) {
      EXPECT_GT(total, 55u) << "too few overlaps to prove anything";
    }
  }
}

TEST(BroadPhase, TouchingBoxesCount) {
  const Box unit{Vec3(0, 0, 0), Vec3(1, 1, 1)};
  const std::vector<Box> boxes = {
      unit,
      {Vec3(1, 0, 0), Vec3(2, 1, 1)},          // shares a face with 0
      {Vec3(2, 1, 1), Vec3(3, 2, 2)},          // shares only a corner with 1
      {Vec3(3 + 1e-12, 0, 0), Vec3(4, 5, 5)},  // a hair away from 2
  };
  const std::vector<ObjectPair> expected = {{0, 1}, {1, 2}};
  for (const std::string& name : broad_phase_names()) {
    auto phase = make_broad_phase(name);
    phase->update(boxes);
    EXPECT_EQ(phase->pairs(), expected) << name;
  }
}

TEST(BroadPhase, IdenticalAndAllEqualBoxes) {
  const Box b{Vec3(-1, -2, -3), Vec3(1, 2, 3)};
  std::vector<Box> boxes(40, b);
  std::vector<ObjectPair> all;
  for (std::uint32_t i = 0; i < boxes.size(); ++i)
    for (std::uint32_t j = i + 1; j < boxes.size(); ++j) all.push_back({i, j});
  const std::vector<Box> two_identical = {b, {Vec3(10, 10, 10), Vec3(11, 11, 11)}, b};
  const std::vector<Box> points(3, Box{Vec3(5, 5, 5), Vec3(5, 5, 5)});  // zero-size boxes at one point
  for (const std::string& name : broad_phase_names()) {
    auto phase = make_broad_phase(name);
    phase->update(boxes);
    EXPECT_EQ(phase->pairs(), all) << name;
    phase->update(boxes);  // again, unchanged
    EXPECT_EQ(phase->pairs(), all) << name;
    auto other = make_broad_phase(name);
    other->update(two_identical);
    EXPECT_EQ(other->pairs(), (std::vector<ObjectPair>{{0, 2}})) << name;
    auto degenerate = make_broad_phase(name);
    degenerate->update(points);
    EXPECT_EQ(degenerate->pairs(), (std::vector<ObjectPair>{{0, 1}, {0, 2}, {1, 2}})) << name;
  }
}

TEST(BroadPhase, NoneAndOneObject) {
  for (const std::string& name : broad_phase_names()) {
    auto none = make_broad_phase(name);
    none->update({});
    none->update({});
    EXPECT_TRUE(none->pairs().empty()) << name;
    auto one = make_broad_phase(name);
    const std::vector<Box> single = {{Vec3(0, 0, 0), Vec3(1, 1, 1)}};
    one->update(single);
    one->update(single);
    EXPECT_TRUE(one->pairs().empty()) << name;
  }
}

void expect_refused(AnyBroadPhase& phase, const std::vector<Box>& boxes,
                    const std::vector<std::string>& words) {
  try {
    phase.update(boxes);
    ADD_FAILURE() << phase.name() << " accepted a bad update";
  } catch (const std::invalid_argument& e) {
    for (const auto& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
  }
}

TEST(BroadPhase, BadInputIsRefusedNamingIt) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<Box> good = {{Vec3(0, 0, 0), Vec3(1, 1, 1)}, {Vec3(0.5, 0, 0), Vec3(2, 1, 1)}};
  for (const std::string& name : broad_phase_names()) {
    SCOPED_TRACE(name);
    auto phase = make_broad_phase(name);
    phase->update(good);
    ASSERT_EQ(phase->pairs().size(), 1u);
    expect_refused(*phase, {good[0]}, {"1 boxes", "2 objects"});
    expect_refused(*phase, {good[0], good[1], good[1]}, {"3 boxes", "2 objects"});
    std::vector<Box> bad = good;
    bad[1].max.y() = nan;
    expect_refused(*phase, bad, {"object 1", "NaN"});
    bad = good;
    bad[0].min.z() = -inf;
    expect_refused(*phase, bad, {"object 0", "infinite"});
    bad = good;
    bad[1] = Box{};  // the default box is empty
    expect_refused(*phase, bad, {"object 1", "empty"});
    bad = good;
    std::swap(bad[0].min.x(), bad[0].max.x());
    expect_refused(*phase, bad, {"object 0", "empty"});
    // A refused update changes nothing.
    EXPECT_EQ(phase->pairs(), (std::vector<ObjectPair>{{0, 1}}));
    // Also on the first call, before any object is registered.
    auto fresh = make_broad_phase(name);
    expect_refused(*fresh, {Box{Vec3(0, 0, 0), Vec3(nan, 1, 1)}}, {"object 0"});
  }
}

TEST(BroadPhase, RegistryListsTheBroadPhasesAndRefusesUnknownNames) {
  EXPECT_EQ(broad_phase_names(),
            (std::vector<std::string>{"brute_force", "sweep_and_prune", "dynamic_aabb_tree"}));
  for (const auto& n : broad_phase_names()) EXPECT_EQ(make_broad_phase(n)->name(), n);
  try {
    make_broad_phase("octree");
    ADD_FAILURE() << "an unknown name was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'octree'"), std::string::npos) << what;
    for (const auto& n : broad_phase_names()) EXPECT_NE(what.find(n), std::string::npos) << what;
  }
}

TEST(DynamicAabbTree, SkipsUpdatesWhileTheFatBoxHolds) {
  std::mt19937_64 rng(11);
  std::vector<Box> boxes = random_boxes(500, false, rng);
  DynamicAabbTree tree;
  tree.update(boxes);
  EXPECT_EQ(tree.reinsertions(), 0u);
  // Tiny motions: far less than a tenth of any box's size.
  BruteForce reference;
  for (int frame = 0; frame < 10; ++frame) {
    for (Box& b : boxes) {
      const Vec3 shift = generators::uniform_point(rng, -1e-3, 1e-3);
      b = {b.min + shift, b.max + shift};
    }
    tree.update(boxes);
    reference.update(boxes);
    EXPECT_EQ(tree.last_reinsertions(), 0u) << "frame " << frame;
    EXPECT_EQ(tree.pairs(), reference.pairs());
  }
  EXPECT_EQ(tree.reinsertions(), 0u);
  for (std::uint32_t i = 0; i < boxes.size(); ++i) {
    const Box& fat = tree.fat_box(i);
    EXPECT_TRUE(fat.contains(boxes[i].min) && fat.contains(boxes[i].max)) << "object " << i;
  }
  // Large motions: every box moves by more than its margin.
  for (Box& b : boxes) {
    const Vec3 shift = Vec3::Constant(b.extent().maxCoeff() + 1);
    b = {b.min + shift, b.max + shift};
  }
  tree.update(boxes);
  reference.update(boxes);
  EXPECT_EQ(tree.last_reinsertions(), boxes.size());
  EXPECT_EQ(tree.reinsertions(), boxes.size());
  EXPECT_EQ(tree.pairs(), reference.pairs());
}

TEST(DynamicAabbTree, RefitsUnderCoherentMotionAndRebuildsWhenScattered) {
  std::mt19937_64 rng(12);
  std::vector<Box> boxes = random_boxes(800, false, rng);
  DynamicAabbTree tree;
  BruteForce reference;
  tree.update(boxes);
  // Every box a little further along one direction: all leave their fat boxes, the tree shape stays good.
  for (int frame = 0; frame < 5; ++frame) {
    for (Box& b : boxes) {
      const Vec3 shift(b.extent().maxCoeff(), 0, 0);
      b = {b.min + shift, b.max + shift};
    }
    tree.update(boxes);
    reference.update(boxes);
    EXPECT_EQ(tree.last_reinsertions(), boxes.size());
    EXPECT_EQ(tree.pairs(), reference.pairs());
  }
  EXPECT_EQ(tree.refits(), 5u);
  // Every box somewhere else: refitting the old shape would be poor, so it is rebuilt.
  boxes = random_boxes(800, false, rng);
  tree.update(boxes);
  reference.update(boxes);
  EXPECT_EQ(tree.refits(), 5u);
  EXPECT_EQ(tree.pairs(), reference.pairs());
}

TEST(DynamicAabbTree, StaysBalancedUnderSortedInsertion) {
  // Registered scattered, then moved onto a line in order, a tenth of them per frame (so they are
  // reinserted one by one, not rebuilt): without rotations the line would grow into a list.
  std::mt19937_64 rng(8);
  std::vector<Box> boxes = random_boxes(1000, false, rng);
  DynamicAabbTree tree;
  tree.update(boxes);
  BruteForce reference;
  for (int frame = 0; frame < 10; ++frame) {
    for (int i = 100 * frame; i < 100 * (frame + 1); ++i)
      boxes[i] = box_at(Vec3(500 + 3.0 * i, 0, 0), Vec3(1, 1, 1));
    tree.update(boxes);
    EXPECT_EQ(tree.last_reinsertions(), 100u);
    reference.update(boxes);
    EXPECT_EQ(tree.pairs(), reference.pairs());
  }
  EXPECT_LE(tree.height(), 25);
}

// The tree's node boxes are floats rounded outwards: beyond the float range they reach infinity, among
// subnormals they round to the smallest steps. Neither may lose or add a pair.
TEST(DynamicAabbTree, FloatNodeBoxesKeepThePairsAtExtremeScales) {
  for (const double scale : {1e-41, 1e-30, 1.0, 1e30, 1e39, 1e200}) {
    std::mt19937_64 rng(21);
    std::vector<Box> boxes = random_boxes(300, true, rng);
    for (Box& b : boxes) b = {b.min * scale, b.max * scale};
    // Pairs that only just touch, and only just miss, at this scale.
    boxes.push_back(box_at(Vec3(0, 0, 0) * scale, Vec3(1, 1, 1) * scale));
    boxes.push_back(box_at(Vec3(2, 0, 0) * scale, Vec3(1, 1, 1) * scale));
    boxes.push_back(Box{Vec3(std::nextafter(3.0 * scale, 1e300), -scale, -scale), Vec3(4, 1, 1) * scale});
    DynamicAabbTree tree;
    BruteForce reference;
    tree.update(boxes);
    reference.update(boxes);
    EXPECT_EQ(tree.pairs(), reference.pairs()) << "scale " << scale;
  }
}

TEST(DynamicAabbTree, RejectsNegativeMargins) {
  EXPECT_THROW(DynamicAabbTree(DynamicAabbTree::Options{-0.1, 0}), std::invalid_argument);
  EXPECT_THROW(DynamicAabbTree(DynamicAabbTree::Options{0.1, std::numeric_limits<double>::quiet_NaN()}),
               std::invalid_argument);
}

TEST(SweepAndPrune, SweepsAlongTheWidestSpread) {
  std::mt19937_64 rng(2);
  std::vector<Box> boxes;
  for (int i = 0; i < 200; ++i)
    boxes.push_back(box_at(Vec3(generators::uniform(rng, -1, 1), generators::uniform(rng, -100, 100),
                                generators::uniform(rng, -5, 5)),
                           Vec3(0.5, 0.5, 0.5)));
  SweepAndPrune sap;
  sap.update(boxes);
  EXPECT_EQ(sap.axis(), 1);
  // Spread along z instead: the axis follows once, and the pairs stay right.
  for (Box& b : boxes) {
    const Vec3 c = b.center();
    b = box_at(Vec3(c.x(), c.z(), c.y()), Vec3(0.5, 0.5, 0.5));
  }
  sap.update(boxes);
  EXPECT_EQ(sap.axis(), 2);
  EXPECT_EQ(sap.axis_changes(), 1u);
  BruteForce reference;
  reference.update(boxes);
  EXPECT_EQ(sap.pairs(), reference.pairs());
}

TEST(SweepAndPrune, IncoherentMotionFallsBackToAFullSort) {
  std::mt19937_64 rng(4);
  std::vector<Box> boxes = random_boxes(1000, false, rng);
  SweepAndPrune sap;
  BruteForce reference;
  sap.update(boxes);
  // Small steps: insertion sort only.
  random_walk(boxes, rng);
  sap.update(boxes);
  EXPECT_EQ(sap.full_sorts(), 0u);
  // Every box somewhere else: far more inversions than a sort costs.
  boxes = random_boxes(1000, false, rng);
  sap.update(boxes);
  reference.update(boxes);
  EXPECT_EQ(sap.full_sorts(), 1u);
  EXPECT_EQ(sap.pairs(), reference.pairs());
}

}  // namespace
}  // namespace bvhlab
