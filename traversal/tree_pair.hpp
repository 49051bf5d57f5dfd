// The two trees of one query as the pair-traversal driver (driver.hpp) walks them: the budget a query may
// be given, a node pair on the queue, the leaf test of triangle trees, and TreePair, which holds the trees,
// the pose and the counters and runs every BV test and leaf test of a traversal.
#pragma once

#include "../bvh/bvh.hpp"
#include "../bvh/triangle_batch.hpp"
#include "../bvh/triangle_intersection.hpp"
#include "budget.hpp"
#include "result.hpp"
#include "tree_access.hpp"

#include <cstdint>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace bvhlab {

struct NoKey {};
struct NoTag {};

/// A node pair on the queue: A's node, B's node, their walkers' state, the queue key and the strategy's tag.
/// With NoKey and NoTag (and self-contained volumes) it is two indices and nothing else. Built with every
/// member given ({key, a, b, wa, wb, tag}), so the walkers' state is constructed in place.
template <TreeVolume BV, class Key = NoKey, class Tag = NoTag>
struct QueuedPair {
  using Working = typename VolumeWalker<BV>::Working;
  [[no_unique_address]] Key key{};
  std::uint32_t a, b;
  // Not [[no_unique_address]]: with a non-empty state beside an empty key or tag, GCC 12 then clears the
  // whole state before constructing it, on every child pair.
  Working wa;
  Working wb;
  [[no_unique_address]] Tag tag{};
};
/// A side's empty walker state under a type of its own: two members of one empty type cannot share an
/// address, which would pad a pair of two indices to 12 bytes.
template <class Working, int Side>
struct EmptyState {
  EmptyState() = default;
  EmptyState(const Working&) {}            // NOLINT(google-explicit-constructor): stands in for Working
  operator Working() const { return {}; }  // NOLINT(google-explicit-constructor)
};
/// Self-contained volumes: the walkers carry no state, and it takes no room (a pair is 8 bytes).
template <TreeVolume BV, class Key, class Tag>
requires StatelessWalk<BV>
struct QueuedPair<BV, Key, Tag> {
  using Working = typename VolumeWalker<BV>::Working;
  [[no_unique_address]] Key key{};
  std::uint32_t a, b;
  [[no_unique_address]] EmptyState<Working, 0> wa;
  [[no_unique_address]] EmptyState<Working, 1> wb;
  [[no_unique_address]] Tag tag{};
};

enum class Admission { Queue, Drop, Decide };
enum class Step { Continue, Decided };
enum class Ended { QueueEmpty, BudgetExhausted };
/// Where a step-wise traversal stands: pairs left to take, ended (decided, or finished on an empty queue),
/// or stopped by its limit before a BV test (not finished: Traversal::stop gives the best-effort answer).
enum class TraversalState { Running, Done, Stopped };

/// The leaf test of two trees of triangles: the one triangle-pair loop (TreePair::intersecting_triangles).
/// Another leaf test is a class of the same shape whose object the query passes to TreePair; the
/// traversal/point_leaves.hpp one tests the implicit surfaces of point clouds. It has
///   static constexpr bool kTriangles = false;
///   static constexpr bool kTestedByEstimates;  // ADB's leaf pairs run it too (triangles: only guided exact)
///   bool may_touch(std::uint32_t i, std::uint32_t j) const;  // after the volumes overlap: may A's node i
///                                                            // and B's node j still touch? (pruning)
///   bool crossing(std::uint32_t i, std::uint32_t j) const;   // a leaf pair: do the objects touch there?
/// The choice is made at compile time: a tree pair of triangles compiles to what it did before.
struct TriangleLeaves {
  static constexpr bool kTriangles = true;
  static constexpr bool kTestedByEstimates = false;

  /// Throws std::invalid_argument when a tree cannot serve triangle tests, naming the tree and why: it
  /// holds a point cloud (a point query passes the clouds' surfaces: traversal/point_leaves.hpp), or it was
  /// loaded without polygons. `who` starts the message.
  template <TreeVolume BV>
  static void require(const Bvh<BV>& a, const Bvh<BV>& b, const char* who) {
    for (const Bvh<BV>* tree : {&a, &b}) {
      // A string is made only for a message: every query runs this check.
      const char* side = tree == &a ? "tree A" : "tree B";
      if (tree->has_points())
        throw std::invalid_argument(std::string(who) + ": " + side +
                                    " holds a point cloud, not triangles; query point trees with their "
                                    "surfaces (query_exact_points, query_adb_points)");
      if (!tree->empty() && !tree->has_polygons())
        throw std::invalid_argument(std::string(who) + ": " + side +
                                    " was loaded without polygons; exact tests need them");
    }
  }
};
inline constexpr TriangleLeaves kTriangleLeaves{};

/// The two trees of one query, the pose, the volumes' pair context (Walker::make_context(b_to_a)), the
/// query's counters and its leaf test. Only references: the context is a separate local of the query, so
/// passing it to an out-of-line overlap test does not make the compiler reload these after every test.
template <TreeVolume BV, class Leaves = TriangleLeaves>
class TreePair {
 public:
  using Walker = VolumeWalker<BV>;
  using Context = typename Walker::Context;
  using LeafTest = Leaves;

  TreePair(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, const Context& context,
           Counters& counters, const Leaves& leaves = kTriangleLeaves)
      : a(a), b(b), b_to_a(b_to_a), context(context), counters(counters), leaves(leaves) {}

  const Bvh<BV>& a;
  const Bvh<BV>& b;
  const RigidTransform& b_to_a;
  const Context& context;
  Counters& counters;
  const Leaves& leaves;

  template <class Pair>
  [[gnu::always_inline]] [[nodiscard]] Pair root() const {
    return Pair{{}, 0, 0, Walker::root_a(a, context), Walker::root_b(b, context), {}};
  }
  /// The BV-pair overlap test, and the leaf test's pruning where it has one; counts one BV test.
  template <class Pair>
  [[gnu::always_inline]] bool overlap(const Pair& p) const {
    ++counters.bv_tests;
    if constexpr (Leaves::kTriangles)
      return Walker::overlap(a, p.a, p.wa, b, p.b, p.wb, context);
    else
      return Walker::overlap(a, p.a, p.wa, b, p.b, p.wb, context) && leaves.may_touch(p.a, p.b);
  }
  /// overlap(p), also writing the volumes' placement (a FramePlacingVolume's test computes it anyway).
  template <class Pair>
  [[gnu::always_inline]] bool overlap(const Pair& p,
                                      PlacedBoxes& placed) const requires FramePlacingVolume<BV> {
    ++counters.bv_tests;
    const bool volumes = BV::overlap(a.tested_volume(p.a), b.tested_volume(p.b), context, placed);
    if constexpr (Leaves::kTriangles)
      return volumes;
    else
      return volumes && leaves.may_touch(p.a, p.b);
  }
  template <class Pair>
  [[gnu::always_inline]] [[nodiscard]] Box box_a(const Pair& p) const {
    return Walker::box(a, p.a, p.wa);
  }
  template <class Pair>
  [[gnu::always_inline]] [[nodiscard]] Box box_b(const Pair& p) const {
    return Walker::box(b, p.b, p.wb);
  }
  template <class Pair>
  [[gnu::always_inline]] [[nodiscard]] bool is_leaf_pair(const Pair& p) const {
    return a.node(p.a).is_leaf() && b.node(p.b).is_leaf();
  }

  /// The test of leaf pair (i, j), whatever the trees hold: on_hit(std::optional<TrianglePair>) is called
  /// per intersecting triangle pair (source-mesh indices), or once with nullopt when another leaf test finds
  /// the objects touching (no triangle pair to name). on_hit returns true to stop; so does this, then.
  /// Triangles count one triangle test per triangle pair; another leaf test one per leaf pair.
  template <class OnHit>
  [[gnu::always_inline]] bool leaf_contact(std::uint32_t i, std::uint32_t j, OnHit&& on_hit) const {
    if constexpr (Leaves::kTriangles) {
      return intersecting_triangles(
          i, j, [&](const TrianglePair& hit) { return on_hit(std::optional<TrianglePair>(hit)); });
    } else {
      ++counters.triangle_tests;
      return leaves.crossing(i, j) && on_hit(std::optional<TrianglePair>());
    }
  }

  /// The one triangle-pair loop: B's triangles of leaf j moved into A's frame, each tested against A's of
  /// leaf i. on_hit(TrianglePair) (source-mesh indices) returns true to stop; so does this, then.
  template <class OnHit>
  [[gnu::always_inline]] bool intersecting_triangles(std::uint32_t i, std::uint32_t j, OnHit&& on_hit) const {
    const TreeNode& na = a.node(i);
    const TreeNode& nb = b.node(j);
    const auto& tri_a = a.triangles();
    for (std::uint32_t tb = nb.first; tb < nb.first + nb.count; ++tb) {
      const TrianglePoints moved = b_triangle_in_a(tb);
      for (std::uint32_t ta = na.first; ta < na.first + na.count; ++ta) {
        ++counters.triangle_tests;
        if (triangles_intersect(tri_a[ta], moved) &&
            on_hit(TrianglePair{a.triangle_ids()[ta], b.triangle_ids()[tb]}))
          return true;
      }
    }
    return false;
  }

  /// intersecting_triangles on leaf pairs (i[k], j[k]), k < n <= 4, in that order: the same tests, hits and
  /// counts. Where each of these leaves holds one triangle, the pairs' plane tests run first, four at once
  /// (bvh/triangle_batch.hpp), and a pair they prove apart skips its exact test. before(k) is called before
  /// pair k is tested (a walk counts its visit there).
  template <class OnHit, class Before>
  [[gnu::always_inline]] bool intersecting_triangles4(const std::uint32_t* i, const std::uint32_t* j, int n,
                                                      OnHit&& on_hit, Before&& before) const {
    bool single = true;
    for (int k = 0; k < n; ++k) single &= a.node(i[k]).count == 1 && b.node(j[k]).count == 1;
    if (!single || n == 1) {  // one pair: the exact test's own plane tests cost no more
      for (int k = 0; k < n; ++k) {
        before(k);
        if (intersecting_triangles(i[k], j[k], on_hit)) return true;
      }
      return false;
    }
    return intersecting_triangles_batch(i, j, n, on_hit, before);
  }

 private:
  /// B's triangle tb (its index in B's tree order) moved into A's frame.
  [[gnu::always_inline]] TrianglePoints b_triangle_in_a(std::uint32_t tb) const {
    const TrianglePoints& t = b.triangles()[tb];
    return {b_to_a.apply(t[0]), b_to_a.apply(t[1]), b_to_a.apply(t[2])};
  }

  /// intersecting_triangles4's pairs of single triangles.
  template <class OnHit, class Before>
  [[gnu::always_inline]] bool intersecting_triangles_batch(const std::uint32_t* i, const std::uint32_t* j,
                                                           int n, OnHit& on_hit, Before& before) const {
    const auto& tri_a = a.triangles();
    std::uint32_t ta[4], tb[4];
    TrianglePairs4 batch;
    for (int k = 0; k < n; ++k) {
      ta[k] = a.node(i[k]).first;
      tb[k] = b.node(j[k]).first;
      batch.set_p(k, tri_a[ta[k]]);
      if (k > 0 && tb[k] == tb[k - 1])  // A's side was split: B's triangle is moved once
        batch.copy_q(k, k - 1);
      else
        batch.set_q(k, b_triangle_in_a(tb[k]));
    }
    if (n % 2) batch.copy(n, 0);  // the odd lane of the last two repeats the first
    const unsigned apart = triangle_pairs_apart(batch, n);
    for (int k = 0; k < n; ++k) {
      before(k);
      ++counters.triangle_tests;
      if (!(apart & (1u << k)) && triangles_intersect(tri_a[ta[k]], batch.q_triangle(k)) &&
          on_hit(TrianglePair{a.triangle_ids()[ta[k]], b.triangle_ids()[tb[k]]}))
        return true;
    }
    return false;
  }
};

}  // namespace bvhlab
