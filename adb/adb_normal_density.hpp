// AdbNormalDensity ("adb_normal"): the ADB cell counts plus, per node, the dominant axis of its polygons'
// normals and how concentrated they are around it, so that two nearly parallel sheets stop looking like a
// likely contact (adb/README.md, section 2, "Orientation").
//
// Decisions:
//   * Axis and flatness: M = sum over the node's triangles of area * n n^T (n the unit normal). Its largest
//     eigenvector is the axis (unsigned: a sheet's two sides are one surface); with eigenvalues
//     l1 >= l2 >= l3, flatness = (l1 - (l2 + l3) / 2) / (l1 + l2 + l3) is 1 when every normal lies on the
//     axis and 0 when they spread evenly over all directions. M is additive, so prefix sums over the tree's
//     triangle order give every node's M in O(1).
//   * The estimate: the "adb" estimate times w + (1 - w) g(phi), with w = 1 - flatness_A flatness_B (how
//     little the orientation is known) and g(phi) = clamp(sin(phi) / (pi / 4), kMinParallelFactor, 1) for
//     the angle phi between the axes (B's rotated into A's frame). Two planes at angle phi through a cell
//     meet inside it about in proportion to sin(phi), and pi / 4 is the mean of sin(phi) over random
//     directions, so the factor is about 1 on average and small for parallel sheets. The floor keeps
//     coplanar contact (touching sheets) from the probability 0.
//   * Storage: 16 bytes per node (axis as three floats, flatness as a float) beside the one-byte count.
#pragma once

#include "adb_density.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace bvhlab {

struct NodeOrientation {
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();  ///< unit; the dominant normal direction (unsigned)
  float flatness = 0;                               ///< in [0, 1]: 1 when all normals lie on the axis
};

/// Axis and flatness of every node, from its triangles (header comment). Nodes without area get flatness 0.
std::vector<NodeOrientation> node_orientations(
    std::span<const std::pair<std::uint32_t, std::uint32_t>> ranges,
    std::span<const TrianglePoints> triangles);

struct AdbNormalDensity {
  using Params = AdbParams;
  struct Storage {
    AdbStorage counts;
    std::vector<NodeOrientation> orientation;  ///< same index as the nodes
  };
  /// Below this, the orientation factor does not go: coplanar sheets may still touch.
  static constexpr double kMinParallelFactor = 0.05;

  /// The counts are "adb"'s, in an OBB's own frame too (adb/pair_geometry.hpp).
  static constexpr bool cells_in_node_frames = AdbDensity::cells_in_node_frames;

  static constexpr std::string_view name() { return "adb_normal"; }
  /// Version 2: the counts of "adb" version 2.
  static constexpr std::uint32_t version() { return 2; }
  static std::span<const ParamSpec> parameters() { return adb_storage::parameters(); }
  static Params make_params(const ParamValues& values) { return adb_storage::make_params(values, name()); }

  template <TreeVolume BV>
  static Storage annotate(const Bvh<BV>& bvh, const Params& params, const AnnotationContext& context,
                          AnnotateStats* stats) {
    AdbStorage counts = AdbDensity::annotate(bvh, params, context, stats);
    return {std::move(counts), node_orientations(node_triangle_ranges(bvh.nodes()), bvh.triangles())};
  }

  static std::string describe(const Storage& storage) {
    return adb_storage::describe(storage.counts.params, name());
  }
  static std::vector<std::byte> encode(const Storage& storage);
  static Storage decode(std::span<const std::byte> bytes, std::size_t node_count);
  static std::size_t memory_bytes(const Storage& storage) {
    return storage.counts.possible_collision_cells.size() +
           storage.orientation.size() * sizeof(NodeOrientation);
  }

  /// e(i, box_a, j, box_b, overlap): the "adb" estimate, weighed by the nodes' orientations.
  struct Estimator {
    const AdbModel* model;
    const std::uint8_t* pc_a;
    const std::uint8_t* pc_b;
    const NodeOrientation* orientation_a;
    const NodeOrientation* orientation_b;
    Eigen::Matrix3f b_to_a;  ///< rotates B's axes into A's frame
    bool oriented;           ///< false: no pose given, the orientation is not used
    double operator()(std::uint32_t i, const Box& box_a, std::uint32_t j, const Box& box_b,
                      double overlap) const {
      const double p = model->estimate<kAdbSizedRule>(box_a, box_b, overlap, pc_a[i], pc_b[j]);
      if (p <= 0 || !oriented) return p;
      const NodeOrientation& a = orientation_a[i];
      const NodeOrientation& b = orientation_b[j];
      const float known = a.flatness * b.flatness;
      if (known <= 0) return p;
      const double sine = (a.axis.cross(b_to_a * b.axis)).norm();
      const double parallel = std::clamp(sine / (std::numbers::pi / 4), kMinParallelFactor, 1.0);
      return p * ((1 - known) + known * parallel);
    }
  };
  /// Throws std::invalid_argument when the two trees were annotated with other parameters, or not at all.
  static Estimator estimator(const Storage& a, const Storage& b, const Mat3& b_to_a_rotation) {
    adb_storage::check_combinable(a.counts, b.counts, name());
    return {a.counts.model.get(),
            a.counts.possible_collision_cells.data(),
            b.counts.possible_collision_cells.data(),
            a.orientation.data(),
            b.orientation.data(),
            b_to_a_rotation.cast<float>(),
            true};
  }
  /// Without a pose (the concept's form), the orientation cannot be compared: the estimate is "adb"'s.
  static Estimator estimator(const Storage& a, const Storage& b) {
    Estimator e = estimator(a, b, Mat3::Identity());
    e.oriented = false;
    return e;
  }
};

static_assert(ProbabilityDensity<AdbNormalDensity>);

}  // namespace bvhlab
