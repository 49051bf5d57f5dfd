// The broad phases against brute force (and brute force against Box::overlaps), their input rules, the
// dynamic tree's fattened boxes, and world boxes against every transformed vertex.
#include "bench/core/generators.hpp"
#include "bvh/mesh_io.hpp"
#include "support/meshes.hpp"
#include "support/random_draws.hpp"
#include "support/volume_lists.hpp"
#include "traversal/broad_phase/registry.hpp"
#include "traversal/broad_phase/world_box.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using testing::draw_quaternion;
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

// World boxes: every transformed vertex inside, never larger than the root's rotated bounding box.

template <class BV>
class WorldBox : public ::testing::Test {};
TYPED_TEST_SUITE(WorldBox, testing::TraversalTestVolumes);

// The rotated bounding box, computed independently: the AABB of its eight transformed corners.
Box rotated_corners(const Box& local, const RigidTransform& pose) {
  Box out;
  for (int k = 0; k < 8; ++k)
    out.extend(pose.apply(Vec3(k & 1 ? local.max.x() : local.min.x(), k & 2 ? local.max.y() : local.min.y(),
                               k & 4 ? local.max.z() : local.min.z())));
  return out;
}

RigidTransform random_rigid(std::mt19937_64& rng, double reach) {
  std::normal_distribution<double> normal;
  const Eigen::Quaterniond q = draw_quaternion(normal, rng);
  RigidTransform pose;
  pose.rotation = q.normalized().toRotationMatrix();
  pose.translation = generators::uniform_point(rng, -reach, reach);
  return pose;
}

TYPED_TEST(WorldBox, ContainsEveryTransformedVertexAndIsNoLargerThanTheRotatedRootBox) {
  using BV = TypeParam;
  std::vector<Mesh> meshes = {generators::make_torus(3, 1, 24, 12), generators::make_box(5, 10, 20),
                              generators::make_cylinder(10, 40, 16)};
  for (auto& v : meshes[0].vertices) v += Vec3(7, -2, 1);  // off-centre
  std::mt19937_64 rng(17);
  for (const Mesh& mesh : meshes) {
    const auto tree = Bvh<BV>::build(mesh);
    const Box local = tree.root_volume().bounding_box();
    for (int k = 0; k < 40; ++k) {
      const RigidTransform pose = random_rigid(rng, k < 20 ? 10.0 : 1e4);
      const Box world = world_box(tree, pose);
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(world.contains(pose.apply(v)))
            << mesh.name << ", pose " << k << ": vertex " << pose.apply(v).transpose() << " outside ["
            << world.min.transpose() << "] - [" << world.max.transpose() << "]";
      // With the bounding ball: still every vertex, and never larger than without it.
      const Box balled = world_box(tree, pose, bounding_ball(tree));
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(balled.contains(pose.apply(v))) << mesh.name << ", pose " << k << " (with the ball)";
      EXPECT_TRUE((balled.min.array() >= world.min.array()).all() &&
                  (balled.max.array() <= world.max.array()).all());
      // With the root bounds (a k-DOP root's vertices): still every vertex, and no looser than with the
      // ball alone but for the vertices' slack (a few 1e-9 of the root's size).
      const RootBounds bounds = root_bounds(tree);
      const Box bounded = world_box(tree, pose, bounds);
      for (const Vec3& v : mesh.vertices)
        ASSERT_TRUE(bounded.contains(pose.apply(v))) << mesh.name << ", pose " << k << " (root bounds)";
      const double slack = 1e-8 * (local.extent().maxCoeff() + local.center().norm());
      EXPECT_TRUE((bounded.min.array() >= balled.min.array() - slack).all() &&
                  (bounded.max.array() <= balled.max.array() + slack).all())
          << mesh.name << ", pose " << k;
      const Box reference = rotated_corners(local, pose);
      const double tolerance =
          1e-9 * (reference.extent().maxCoeff() + pose.translation.cwiseAbs().maxCoeff());
      EXPECT_TRUE((world.min.array() >= reference.min.array() - tolerance).all() &&
                  (world.max.array() <= reference.max.array() + tolerance).all())
          << mesh.name << ", pose " << k;
    }
  }
}

// A DOP of the prototype's own shape: the support bound is exact there, so both sides of every world axis
// must meet the rotated prototype's extreme vertices (the lower side comes from the upper side's search).
TEST(WorldBox, DopOfThePrototypeShapeGivesTheExactRotatedBox) {
  using Dop = KDop<dop_sets::Zachmann24>;
  std::vector<Vec3> corners;
  for (const auto& vertex : Dop::tables().vertices) corners.push_back(vertex.position);
  const Dop prototype = Dop::fit(corners);
  std::mt19937_64 rng(5);
  for (int k = 0; k < 50; ++k) {
    const RigidTransform pose = random_rigid(rng, 10.0);
    Box exact;
    for (const Vec3& c : corners) exact.extend(pose.apply(c));
    const Box world = world_box(prototype, pose);
    // Offsets are floats rounded upwards: a few 1e-7 of the prototype's size of about 1.
    EXPECT_LT((world.max - exact.max).cwiseAbs().maxCoeff(), 1e-5) << "pose " << k;
    EXPECT_LT((world.min - exact.min).cwiseAbs().maxCoeff(), 1e-5) << "pose " << k;
  }
}

// The DOP's vertices by brute force, independently of dop_vertices: every triple of its planes solved by a
// pivoting QR, the points inside every half-space kept, no merging.
template <class Set>
std::vector<Vec3> brute_force_dop_vertices(const KDop<Set>& dop) {
  constexpr std::size_t kAxes = KDop<Set>::kAxes;
  std::vector<Vec3> normals;
  for (const auto& raw : Set::set.raw) normals.push_back(Vec3(raw[0], raw[1], raw[2]).normalized());
  for (std::size_t a = 0; a < kAxes; ++a) normals.push_back(-normals[a]);
  double scale = 0;
  for (const float d : dop.offsets) scale = std::max(scale, std::abs(double(d)));
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < normals.size(); ++i)
    for (std::size_t j = i + 1; j < normals.size(); ++j)
      for (std::size_t l = j + 1; l < normals.size(); ++l) {
        Mat3 m;
        m << normals[i].transpose(), normals[j].transpose(), normals[l].transpose();
        const auto qr = m.colPivHouseholderQr();
        if (qr.rank() < 3) continue;
        const Vec3 x = qr.solve(Vec3(dop.offsets[i], dop.offsets[j], dop.offsets[l]));
        bool inside = true;
        for (std::size_t q = 0; q < normals.size(); ++q)
          inside = inside && normals[q].dot(x) <= double(dop.offsets[q]) + 1e-9 * scale;
        if (inside) out.push_back(x);
      }
  return out;
}

// The world box from the DOP's vertices, against the points the DOP was fitted to, the LP bound, and the
// brute-force vertices, under random rotations.
template <class Set>
void expect_exact_dop_support(const std::vector<Vec3>& points, const std::string& label,
                              std::mt19937_64& rng) {
  const KDop<Set> dop = KDop<Set>::fit(points);
  const DopVertices vertices = dop_vertices(dop);
  ASSERT_FALSE(vertices.empty()) << label;
  const std::vector<Vec3> brute = brute_force_dop_vertices(dop);
  ASSERT_FALSE(brute.empty()) << label;
  double size = 0;
  for (const Vec3& p : points) size = std::max(size, p.cwiseAbs().maxCoeff());
  for (int k = 0; k < 30; ++k) {
    const RigidTransform pose = random_rigid(rng, k < 15 ? 10.0 : 1e4);
    const Box box = world_box(vertices, pose);
    for (const Vec3& p : points)
      ASSERT_TRUE(box.contains(pose.apply(p)))
          << label << ", pose " << k << ": " << pose.apply(p).transpose();
    Box exact;
    for (const Vec3& v : brute) exact.extend(pose.apply(v));
    const Box lp = world_box(dop, pose);
    const double tolerance = 1e-7 * (size + pose.translation.cwiseAbs().maxCoeff()) + 1e-12;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_NEAR(box.max[axis], exact.max[axis], tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_NEAR(box.min[axis], exact.min[axis], tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_LE(box.max[axis], lp.max[axis] + tolerance) << label << ", pose " << k << ", axis " << axis;
      EXPECT_GE(box.min[axis], lp.min[axis] - tolerance) << label << ", pose " << k << ", axis " << axis;
    }
  }
}

std::vector<std::pair<std::string, std::vector<Vec3>>> dop_test_point_sets() {
  std::vector<std::pair<std::string, std::vector<Vec3>>> sets;
  for (const char* file : {"pinion.off", "jeep1.ms3d", "teapot.obj"})
    sets.emplace_back(file, load_mesh(testing::bundled_mesh(file)).mesh.vertices);
  std::vector<Vec3> torus = generators::make_torus(3, 1, 24, 12).vertices;
  for (auto& v : torus) v += Vec3(7, -2, 1);
  sets.emplace_back("off-centre torus", torus);
  // Degenerate DOPs: flat (equal offsets on the opposite z planes), a tilted triangle, a segment, points.
  sets.emplace_back("flat quad", std::vector<Vec3>{{-1, -2, 0.5}, {3, -2, 0.5}, {3, 1, 0.5}, {-1, 1, 0.5}});
  sets.emplace_back("tilted triangle",
                    std::vector<Vec3>{{0.3, 1.7, -2.2}, {4.1, -0.6, 0.9}, {-1.3, 2.2, 3.5}});
  sets.emplace_back("segment", std::vector<Vec3>{{1, 2, 3}, {-2, 0.5, 7}});
  sets.emplace_back("point", std::vector<Vec3>{{2.5, -1.25, 4}});
  sets.emplace_back("origin", std::vector<Vec3>{Vec3::Zero()});
  return sets;
}

TEST(WorldBox, DopVerticesGiveTheExactSupportOfTheRotatedDop) {
  std::mt19937_64 rng(23);
  for (const auto& [label, points] : dop_test_point_sets()) {
    expect_exact_dop_support<dop_sets::Zachmann24>(points, label + " (24-DOP)", rng);
    // The 14-DOP's corners join more than three planes: many triples meet in one vertex.
    expect_exact_dop_support<dop_sets::Dop14>(points, label + " (14-DOP)", rng);
  }
}

TEST(WorldBox, DopVerticesOnlyForDopRootsAndNoneForAnEmptyDop) {
  const Mesh box = generators::make_box(5, 10, 20);
  EXPECT_FALSE(root_bounds(Bvh<Dop24>::build(box)).dop.empty());
  EXPECT_TRUE(root_bounds(Bvh<Aabb>::build(box)).dop.empty());
  EXPECT_TRUE(dop_vertices(Dop24{}).empty());
  EXPECT_TRUE(world_box(dop_vertices(Dop24{}), RigidTransform{}).empty());
}

TEST(WorldBox, AabbRootUnder45DegreesIsTighterThanTheCubeAroundItsSphere) {
  const auto tree = Bvh<Aabb>::build(generators::make_box(5, 10, 20));
  RigidTransform pose;
  pose.rotation = Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()).toRotationMatrix();
  pose.translation = Vec3(100, -50, 3);
  const Box world = world_box(tree, pose);
  const Box local = tree.root_volume().bounding_box();
  const double radius = local.extent().norm() / 2;  // the box's circumscribed sphere
  for (int k = 0; k < 3; ++k) EXPECT_LT(world.extent()[k], 2 * radius * 0.9) << "axis " << k;
  // A round object in an Aabb tree: its bounding ball cuts the rotated root box down to the sphere's cube.
  const auto round = Bvh<Aabb>::build(generators::make_sphere(30, 16, 16));
  RigidTransform tilted = pose;
  tilted.rotation = Eigen::AngleAxisd(0.6, Vec3(1, 1, 0).normalized()).toRotationMatrix();
  const Box rotated = world_box(round, tilted), balled = world_box(round, tilted, bounding_ball(round));
  for (int k = 0; k < 3; ++k) {
    EXPECT_LE(balled.extent()[k], 60 * (1 + 1e-9)) << "axis " << k;
    EXPECT_GT(rotated.extent()[k], 60 * 1.05) << "axis " << k;
  }
  // And a sphere root really is a sphere: centre and radius, not its rotated bounding box.
  const auto ball = Bvh<Sphere>::build(generators::make_sphere(30, 16, 16));
  const Box ball_box = world_box(ball, pose);
  EXPECT_NEAR(ball_box.extent().x(), 2 * ball.root_volume().radius, 1e-6);
}

}  // namespace
}  // namespace bvhlab
