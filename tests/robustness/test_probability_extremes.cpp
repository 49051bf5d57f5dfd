// The ADB probability model at its extremes: counts up to 10^4 and at the edges 0, 1, s-1, s; LB at 0, 1e-12,
// 1-1e-12, 1; every lookup-table entry of every grid the trees support; the monotonicity the model promises
// (more possible collision cells never lower the estimate for a fixed s); the size mapping of AdbModel with a
// size ratio of 1e4; p_min at 0 and 1 in a traversal.
#include "adb/adb_paper_density.hpp"
#include "adb/lb_table.hpp"
#include "adb/probability.hpp"
#include "bench/core/ground_truth.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/protocol.hpp"
#include "robust_support.hpp"
#include "support/generated_meshes.hpp"
#include "support/meshes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace bvhlab::robust {
namespace {

const std::vector<double> kExtremeLb = {0.0, 1e-12, 1.0 - 1e-12, 1.0};

std::vector<int> edges(int s) {
  std::vector<int> out{0, 1, s - 1, s, s / 2};
  std::erase_if(out, [s](int c) { return c < 0 || c > s; });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

TEST(ProbabilityExtremes, EdgeCountsUpToTenThousandCellsStayProbabilities) {
  for (int s : {0, 1, 2, 7, 8, 27, 64, 216, 1000, 9999, 10'000}) {
    for (int s_a : edges(s))
      for (int s_b : edges(s)) {
        for (int x : {0, 1, 2, s / 2, s - 1, s, s + 1}) {
          const double tail = pr_collision_cells_at_least(s, s_a, s_b, x);
          ASSERT_TRUE(std::isfinite(tail) && tail >= 0 && tail <= 1)
              << "s " << s << " s_a " << s_a << " s_b " << s_b << " x " << x << " -> " << tail;
        }
        for (double lb : kExtremeLb) {
          const ProbabilityEstimate e = estimate_probability_detailed(s, s_a, s_b, lb);
          ASSERT_TRUE(std::isfinite(e.probability) && e.probability >= 0 && e.probability <= 1)
              << "s " << s << " s_a " << s_a << " s_b " << s_b << " lb " << lb << " -> " << e.probability;
          // Certain cases: LB = 0 never collides; with LB = 1 the estimate is Pr[cc >= 1] exactly.
          if (lb == 0) {
            ASSERT_EQ(e.probability, 0.0);
          }
          if (lb == 1) {
            ASSERT_EQ(e.probability, pr_collision_cells_at_least(s, s_a, s_b, 1));
          }
          // All of B's cells possible for A (s_a = s): a collision cell is certain whenever s_b > 0.
          if (lb == 1 && s_a == s && s_b > 0) {
            ASSERT_EQ(e.probability, 1.0);
          }
        }
      }
  }
}

// For a fixed s, adding a possible collision cell to either object never lowers the estimate: balls into bins
// with one more red (or blue) ball can only raise Pr[cc >= x] for every x, hence the maximum over x.
TEST(ProbabilityExtremes, MoreCellsNeverLowerTheEstimateUpToTenThousand) {
  for (double lb : {1e-12, 0.3, 1.0 - 1e-12}) {
    for (int s : {8, 27, 64, 1000, 10'000}) {
      const int step = std::max(1, s / 40);
      for (int s_a = 0; s_a <= s; s_a += step) {
        double previous = -1;
        for (int s_b = 0; s_b <= s; s_b += step) {
          const double p = estimate_probability(s, s_a, s_b, lb);
          ASSERT_GE(p, previous) << "lb " << lb << " s " << s << " s_a " << s_a << " s_b " << s_b;
          previous = p;
        }
      }
    }
  }
}

// Every entry of the table of every grid a tree can carry (g = 2..6, s_max = 8..216), for every tabulated LB
// and the extreme ones: finite, in [0, 1], monotone in both counts at fixed s up to rounding. Measured: the
// only decreases are single ulps at estimates within 2e-16 of 1 (g = 6, LB = 1 and 1 - 1e-12: 35 entries of
// 1.7 million, worst 1.1e-16), where the tail ratio of two sums near 1 rounds either way.
TEST(ProbabilityExtremes, EveryTableEntryIsAProbabilityAndMonotone) {
  constexpr double kRounding = 4 * std::numeric_limits<double>::epsilon();
  std::vector<double> lbs = kExtremeLb;
  for (const LbTableRow& row : lb_table()) lbs.push_back(row.lb());
  std::size_t entries = 0;
  for (int g = 2; g <= 6; ++g) {
    const int s_max = g * g * g;
    // The big grids only at the LBs the annotation can produce and at the ends, to bound the run time.
    for (double lb : lbs) {
      if (g >= 5 && lb != 0.0 && lb != 1.0 && lb != lb_for_tau(kDefaultAdbTau)) continue;
      const ProbabilityTable table(s_max, lb);
      for (int s = 0; s <= s_max; ++s)
        for (int s_a = 0; s_a <= s; ++s_a)
          for (int s_b = 0; s_b <= s; ++s_b) {
            const double p = table.lookup(s, s_a, s_b);
            ASSERT_TRUE(std::isfinite(p) && p >= 0 && p <= 1)
                << "g " << g << " lb " << lb << " (" << s << ", " << s_a << ", " << s_b << ") -> " << p;
            if (s_a > 0) {
              ASSERT_GE(p, table.lookup(s, s_a - 1, s_b) - kRounding) << "g " << g << " lb " << lb;
            }
            if (s_b > 0) {
              ASSERT_GE(p, table.lookup(s, s_a, s_b - 1) - kRounding) << "g " << g << " lb " << lb;
            }
            ++entries;
          }
    }
  }
  EXPECT_GT(entries, 1'000'000u);
}

// AdbModel::estimate maps differently sized BVs onto the coarser cells. With size ratios up to 1e4 (volume
// ratios up to 1e12), flat and needle-shaped boxes, overlaps from nothing to everything and every pc, the
// estimate stays a probability, and more possible collision cells on either side never lower it.
TEST(ProbabilityExtremes, SizeMappingWithRatioTenThousand) {
  auto box = [](const Vec3& extent) { return Box{-0.5 * extent, 0.5 * extent}; };
  const std::vector<Box> boxes = {
      box(Vec3(1, 1, 1)),       box(Vec3(1e-4, 1e-4, 1e-4)), box(Vec3(1e-2, 1e-2, 1e-2)), box(Vec3(1, 1, 0)),
      box(Vec3(1, 1e-6, 1e-6)), box(Vec3(1e4, 1e4, 1e4)),    box(Vec3(1e-4, 1, 1)),       box(Vec3(0, 0, 0))};
  for (int g : {2, 3, 4}) {
    const AdbModel model(g, kDefaultAdbTau);
    const int cells = g * g * g;
    for (const Box& a : boxes)
      for (const Box& b : boxes) {
        const double smaller = std::min(a.volume(), b.volume());
        for (double overlap : {0.0, 1e-300, 1e-12 * smaller, 0.5 * smaller, smaller, 1e-9, 1.0}) {
          for (int pc_a = 0; pc_a <= cells; ++pc_a) {
            double previous = -1;
            for (int pc_b = 0; pc_b <= cells; ++pc_b) {
              const double p = model.estimate(a, b, overlap, pc_a, pc_b);
              ASSERT_TRUE(std::isfinite(p) && p >= 0 && p <= 1)
                  << "g " << g << " extents " << a.extent().transpose() << " / " << b.extent().transpose()
                  << " overlap " << overlap << " pc " << pc_a << "," << pc_b << " -> " << p;
              ASSERT_GE(p, previous) << "g " << g << " pc_a " << pc_a << " pc_b " << pc_b;
              previous = p;
              if (pc_a > 0) {
                ASSERT_GE(p, model.estimate(a, b, overlap, pc_a - 1, pc_b));
              }
            }
          }
        }
      }
    // Equal sizes reduce to the paper's case: full overlap reads the table at (g^3, pc_a, pc_b).
    EXPECT_DOUBLE_EQ(model.estimate(boxes[0], boxes[0], 1.0, 1, cells),
                     model.table().lookup(cells, 1, cells));
  }
}

// A tiny object (size 2e-4) against a huge one (size 2): the differently-sized-BV case on real trees.
// Probabilities of all node pairs the traversal could meet stay in [0, 1]; every strategy terminates with an
// honest answer, for p_min at 0 and 1 as well as in between.
TEST(ProbabilityExtremes, TinyAgainstHugeTreesTerminateHonestly) {
  const Mesh huge = testing::make_torus(0.7, 0.25, 40, 20);
  Mesh tiny = testing::make_torus(0.7, 0.25, 12, 6);
  for (auto& v : tiny.vertices) v *= 1e-4;
  const CgalGroundTruth truth(huge, tiny);
  const auto tree_huge = annotated<Aabb>(huge);
  const auto tree_tiny = annotated<Aabb>(tiny);
  // Node-pair estimates, straight from the model, for every pair of a huge node and a tiny node at one pose.
  const RigidTransform on_surface = RigidTransform::translate(huge.vertices[7]);
  const Mat3 abs_rotation = on_surface.rotation.cwiseAbs();
  for (std::size_t i = 0; i < tree_huge.bvh.nodes().size(); i += 7)
    for (std::size_t j = 0; j < tree_tiny.bvh.nodes().size(); ++j) {
      const Box a = tree_huge.bvh.volume(i).bounding_box(), b = tree_tiny.bvh.volume(j).bounding_box();
      const double overlap = detail::overlap_volume(a, b, on_surface, abs_rotation);
      const double p = shared_model().estimate(a, b, overlap, tree_huge.density.possible_collision_cells[i],
                                               tree_tiny.density.possible_collision_cells[j]);
      ASSERT_TRUE(std::isfinite(p) && p >= 0 && p <= 1) << i << " " << j << " -> " << p;
    }
  // Whole queries, both ways round, at poses that put the tiny torus on, near and off the huge one's surface.
  std::mt19937_64 rng(44);
  int colliding = 0, total = 0;
  for (std::size_t k = 0; k < huge.vertices.size(); k += 37) {
    for (double offset : {0.0, 1e-4, 3e-4, 1e-2}) {
      RigidTransform pose = testing::random_pose(rng, 0.0);
      pose.translation = huge.vertices[k] * (1 + offset);
      const bool expected = truth.collides(pose);
      colliding += expected;
      ++total;
      for (Strategy s : kAllStrategies)
        for (double p_min : {0.0, 0.5, 1.0}) {
          const Result r = run<Aabb>(s, tree_huge, tree_tiny, pose, p_min, 200);
          ASSERT_TRUE(honest(r, expected)) << to_string(s) << " p_min " << p_min << " vertex " << k;
          if (is_exact(s)) {
            ASSERT_EQ(r.collides, expected) << to_string(s);
          }
          const Result flipped = run<Aabb>(s, tree_tiny, tree_huge, pose.inverse(), p_min, 200);
          ASSERT_TRUE(honest(flipped, expected)) << to_string(s) << " flipped, p_min " << p_min;
        }
    }
  }
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, total);
}

// p_min = 1 can never be exceeded: the query must end by draining its queue (or its budget), never loop.
TEST(ProbabilityExtremes, PMinOneDrainsAndPMinZeroDecidesOnAnyEvidence) {
  const Mesh mesh = testing::make_torus(0.7, 0.25, 30, 15);
  const auto tree = annotated<Aabb>(mesh);
  const CgalGroundTruth truth(mesh, mesh);
  for (double d : {0.0, 0.5, 1.0, 1.3, 1.8, 2.5}) {
    const RigidTransform pose = protocol_pose(d, 3, 40);
    const bool expected = truth.collides(pose);
    AdbOptions never;
    never.p_min = 1.0;
    const Result drained = query_adb(tree, tree, pose, never);
    EXPECT_TRUE(honest(drained, expected)) << "d " << d;
    AdbOptions eager;
    eager.p_min = 0.0;
    const Result decided = query_adb(tree, tree, pose, eager);
    EXPECT_TRUE(honest(decided, expected)) << "d " << d;
    if (decided.collides) {
      EXPECT_GT(decided.probability, 0.0);
    }
  }
}

// Objects of very different size in their own units (bench/scenes/size_pair.json's set-up, on bundled
// meshes): the jeep (longest side 16.6) and the gear scaled to a hundredth of that. At random poses around
// the jeep's vertices, ADB at p_min 0.9 misses at most 1% of the collisions. The paper's rule, which counts
// a small node on the large node's cells, misses more: the test shows the default rule is what holds.
TEST(ProbabilityExtremes, SizeRatioHundredMissesAtMostOnePercentOfCollisions) {
  const Mesh jeep = load_mesh(testing::bundled_mesh("jeep1.ms3d")).mesh;
  Mesh gear = load_mesh(testing::bundled_mesh("pinion.off")).mesh;
  const auto longest = [](const Mesh& m) { return m.bounds().extent().maxCoeff(); };
  const double scale = longest(jeep) / (100 * longest(gear));
  for (auto& v : gear.vertices) v *= scale;
  AnnotateOptions options;
  options.threads = 1;
  const auto sized_jeep = annotate_adb(Bvh<Aabb>::build(jeep), kGrid, options);
  const auto sized_gear = annotate_adb(Bvh<Aabb>::build(gear), kGrid, options);
  const auto paper = [](const Tree<Aabb, AdbDensity>& t) {
    return Tree<Aabb, AdbPaperDensity>{
        t.bvh, AdbPaperDensity::make_storage(t.density.params, t.density.possible_collision_cells)};
  };
  const auto paper_jeep = paper(sized_jeep), paper_gear = paper(sized_gear);
  AdbOptions adb;
  adb.p_min = 0.9;
  std::mt19937_64 rng(12);
  std::uniform_int_distribution<std::size_t> vertex(0, jeep.vertices.size() - 1);
  int colliding = 0, sized_missed = 0, paper_missed = 0;
  for (int k = 0; k < 400; ++k) {
    RigidTransform pose = testing::random_pose(rng, 0.1);
    pose.translation += jeep.vertices[vertex(rng)];
    if (!query_exact(sized_jeep.bvh, sized_gear.bvh, pose).collides) continue;
    ++colliding;
    sized_missed += !query_adb(sized_jeep, sized_gear, pose, adb).collides;
    paper_missed += !query_adb(paper_jeep, paper_gear, pose, adb).collides;
  }
  ASSERT_GE(colliding, 50);  // enough collisions for a 1% bound to mean something
  EXPECT_LE(sized_missed, colliding / 100) << "of " << colliding;
  EXPECT_GT(paper_missed, sized_missed) << "of " << colliding;
}

}  // namespace
}  // namespace bvhlab::robust
