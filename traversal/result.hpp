// Result: the one currency of every strategy. Tests, benchmarks and the report read only this.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace bvhlab {

/// Work done by one query. All strategies fill what applies to them.
struct Counters {
  std::uint64_t bv_tests = 0;        ///< BV-pair overlap tests
  std::uint64_t triangle_tests = 0;  ///< exact triangle-pair tests (point queries: leaf-pair surface tests)
  std::uint64_t nodes_visited = 0;   ///< node pairs taken off the stack or queue
  std::uint64_t probability_evaluations = 0;

  Counters& operator+=(const Counters& o) {
    bv_tests += o.bv_tests;
    triangle_tests += o.triangle_tests;
    nodes_visited += o.nodes_visited;
    probability_evaluations += o.probability_evaluations;
    return *this;
  }
};

/// A pair of intersecting triangles, as indices into the source meshes of A and B.
struct TrianglePair {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  friend bool operator==(const TrianglePair&, const TrianglePair&) = default;
  friend auto operator<=>(const TrianglePair&, const TrianglePair&) = default;
};

/// What the distance strategies answer (traversal/distance.hpp): the exact distance lies in
/// [lower_bound, distance], both equal unless a budget stopped the query. `distance` is that of the nearest
/// triangle pair found, `triangles` (source-mesh indices); its points are in A's frame.
struct Proximity {
  double distance = std::numeric_limits<double>::infinity();
  double lower_bound = 0;
  std::array<double, 3> on_a{}, on_b{};
  std::optional<TrianglePair> triangles;  ///< empty when no triangle pair was reached
};

/// Where an intersecting triangle pair meets (bvh/triangle_contact.hpp), in A's frame: the segment common to
/// both triangles (from == to at a single point), its midpoint, and a unit normal from A into B (the
/// difference of the two faces' normals, whose sides the vertex order decides). Penetration depth is not
/// measured.
struct ContactGeometry {
  TrianglePair triangles;
  std::array<double, 3> from{}, to{}, point{}, normal{};
  bool coplanar = false;  ///< the triangles overlap in an area; from and to are its two farthest corners
};

struct Result {
  bool collides = false;
  /// Estimated probability of collision; exactly 1 or 0 when `exact`.
  double probability = 0;
  /// True when the answer is decided by exact triangle tests (or by exhausting all overlapping pairs). Point
  /// queries (traversal/point_leaves.hpp): by the surfaces' leaf tests, exact on the surfaces only.
  bool exact = true;
  /// True when the deadline or the BV-test cap was reached before the traversal finished. Stopped by it,
  /// the answer is a best effort (not exact). A traversal that finished (queue empty, or a pair decided) in
  /// the step during which its deadline passed keeps its answer, which may be exact, and is flagged all the
  /// same: it came late. A BV-test cap flags only a traversal it stopped.
  bool budget_exhausted = false;
  std::optional<TrianglePair> witness;  ///< set by exact strategies when collides
  std::vector<TrianglePair> contacts;   ///< all-contacts mode only
  std::optional<Proximity> proximity;   ///< the distance strategies only
  /// Asked for (StrategyVariant::contact_geometry): one entry per contact in all-contacts mode, else one for
  /// the witness, if any, and if its triangles intersect (the tolerance strategy's may lie apart).
  std::vector<ContactGeometry> contact_geometry;
  Counters counters;
};

}  // namespace bvhlab
