// Bvh<BV>: a flat, pointer-free bounding-volume hierarchy over one mesh.
#pragma once

#include "../volumes/concept.hpp"
#include "point_cloud.hpp"
#include "topology.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace bvhlab {

struct BvhStats {
  std::size_t nodes = 0;
  std::size_t leaves = 0;
  std::uint32_t depth = 0;
  std::size_t triangles = 0;
  std::size_t points = 0;          ///< of a tree over a point cloud (triangles is then 0)
  std::size_t bytes_per_node = 0;  ///< topology + volume, without polygons
  double bytes_per_triangle = 0;   ///< node bytes / triangles, without polygons
  double build_seconds = 0;
};

/// How refit() bounds an inner node: merging its children's volumes, or fitting its triangles' vertices.
enum class RefitMethod { Merge, Fit };

namespace bvh_detail {
/// Bvh::identity(): one count for every volume type, so that no two trees of a process share a number.
inline std::uint64_t next_identity() {
  static std::atomic<std::uint64_t> last{0};
  return last.fetch_add(1, std::memory_order_relaxed) + 1;
}
}  // namespace bvh_detail

template <TreeVolume BV>
class Bvh {
 public:
  using Volume = BV;
  using Fitted = fitted_volume_t<BV>;  ///< BV itself, or its Decoded form for hierarchical volumes
  static constexpr bool hierarchical = HierarchicalVolume<BV>;
  /// A volume whose orientation is part of the fit (OBB) may offer fit_in_frame_of: refit() then fits
  /// each node in its own orientation instead of merging (see Obb).
  static constexpr bool refits_in_frame = requires(const BV& v, std::span<const TrianglePoints> t) {
    { BV::fit_in_frame_of(v, t) } -> std::same_as<BV>;
  };

  Bvh() = default;

  /// Builds topology, then fits one BV per node. Throws std::invalid_argument on an empty mesh.
  static Bvh build(const Mesh& mesh, const BuildOptions& options = {}) {
    const auto start = std::chrono::steady_clock::now();
    Bvh out;
    Topology topology = build_topology(mesh, split_directions_of<BV>(), options);
    out.nodes_ = std::move(topology.nodes);
    out.identity_ = bvh_detail::next_identity();
    out.triangle_ids_ = std::move(topology.triangle_order);
    out.triangles_.reserve(out.triangle_ids_.size());
    for (std::uint32_t id : out.triangle_ids_) out.triangles_.push_back(mesh.triangle(id));
    out.depth_ = topology.depth;
    out.leaves_ = topology.leaves;
    out.topology_ = topology_fingerprint(mesh);
    out.vertex_count_ = mesh.vertices.size();
    out.fit_volumes(options.threads ? options.threads : std::thread::hardware_concurrency());
    out.built_spread_ = out.spread();
    out.build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  }

  /// A tree over a point cloud: the topology groups the points (options.max_leaf_points per leaf, see
  /// build_topology), and each node's volume is fitted to the points below it. Such a tree holds points,
  /// no polygons (has_points(), points(), point_ids()); refit() refuses it. Throws std::invalid_argument for
  /// an empty cloud or a non-finite point.
  static Bvh build(const PointCloud& cloud, const BuildOptions& options = {}) {
    const auto start = std::chrono::steady_clock::now();
    Bvh out;
    Topology topology = build_topology(cloud.positions, split_directions_of<BV>(), options);
    out.nodes_ = std::move(topology.nodes);
    out.identity_ = bvh_detail::next_identity();
    out.point_ids_ = std::move(topology.triangle_order);
    out.points_.reserve(out.point_ids_.size());
    for (std::uint32_t id : out.point_ids_) out.points_.push_back(cloud.positions[id]);
    out.depth_ = topology.depth;
    out.leaves_ = topology.leaves;
    out.fit_volumes(options.threads ? options.threads : std::thread::hardware_concurrency());
    out.built_spread_ = out.spread();
    out.build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
  }

  /// Assembles a tree from saved parts (no polygons: triangles may be empty).
  static Bvh from_parts(std::vector<TreeNode> nodes, std::vector<BV> volumes, std::vector<std::uint32_t> ids,
                        std::vector<TrianglePoints> triangles = {}, const Fitted& root = {}) {
    Bvh out;
    out.root_ = root;
    out.nodes_ = std::move(nodes);
    out.identity_ = bvh_detail::next_identity();
    out.volumes_ = std::move(volumes);
    out.triangle_ids_ = std::move(ids);
    out.triangles_ = std::move(triangles);
    out.recount();
    out.derive_from_volumes();
    out.built_spread_ = out.spread();
    return out;
  }

  /// Refits every node to new positions of the same triangles, bottom-up: a leaf is fitted to its triangles'
  /// vertices, an inner node merges its children's volumes (a hierarchical volume then re-encodes each
  /// child against its parent; an OBB is instead fitted, in each node's orientation from the build, to the
  /// node's vertices: O(triangles x depth) but no eigen-solve, see refits_in_frame). O(nodes),
  /// single-threaded. The topology stays; see degradation() for when to rebuild instead. Throws
  /// std::invalid_argument naming the problem (another vertex count, other triangle indices, a non-finite
  /// vertex) and leaves the tree as it was. RefitMethod::Fit fits every node to its vertices instead, as the
  /// build does: O(triangles x depth), tighter for OBBs and spheres, whose merges loosen level by level.
  void refit(const Mesh& deformed, RefitMethod method = RefitMethod::Merge) {
    if (has_points()) throw std::invalid_argument("refit: the tree was built over a point cloud, not a mesh");
    std::vector<TrianglePoints> moved = deformed_triangles(deformed);
    if (method == RefitMethod::Fit) {
      triangles_ = std::move(moved);
      fit_volumes(1);
      return;
    }
    std::vector<Fitted> fitted(nodes_.size(), Fitted{});
    if constexpr (refits_in_frame) {
      // Each node's box in its own orientation around its vertices: merging children's corners would
      // compound their bulges level by level.
      const auto ranges = node_triangle_ranges(nodes_);
      for (std::size_t i = 0; i < nodes_.size(); ++i)
        fitted[i] =
            BV::fit_in_frame_of(volumes_[i], std::span<const TrianglePoints>(moved).subspan(
                                                 ranges[i].first, ranges[i].second - ranges[i].first));
    } else {
      std::vector<Vec3> points;  // reused: no allocation per leaf
      // Children are stored after their parent (build_topology), so a reverse sweep sees them first.
      for (std::size_t i = nodes_.size(); i-- > 0;) {
        const TreeNode& n = nodes_[i];
        if (n.is_leaf()) {
          points.clear();
          for (std::uint32_t t = n.first; t < n.first + n.count; ++t)
            points.insert(points.end(), moved[t].begin(), moved[t].end());
          fitted[i] = Fitted::fit(points);
        } else {
          fitted[i] = Fitted::merge(fitted[n.left()], fitted[n.right()]);
        }
      }
    }
    triangles_ = std::move(moved);
    store_volumes(std::move(fitted));
  }

  /// How much the topology has degraded since the build: its surface-area cost (the summed surface area of
  /// every node's box around its triangles over the root box's), divided by the same cost at build time. It
  /// depends on the triangles only, not on the volume type or the RefitMethod, and is scale-free: a uniform
  /// scaling leaves it at 1 (a rotation changes axis-aligned areas a little), a deformation that drives the
  /// triangles of one subtree apart lets it grow. Rebuild when it passes kRebuildDegradation. O(nodes).
  [[nodiscard]] double degradation() const { return built_spread_ > 0 ? spread() / built_spread_ : 1.0; }

  [[nodiscard]] const std::vector<TreeNode>& nodes() const { return nodes_; }
  /// Names this tree's topology within the process: a new number for each build and each from_parts (a
  /// load), kept by copies and by refit(), 0 for a default-constructed one. What a coherent query's state is
  /// bound to (traversal/coherent_state.hpp): its stored node pairs mean something only in the topology they
  /// came from, and a new tree may be given the address of one that is gone.
  [[nodiscard]] std::uint64_t identity() const { return identity_; }
  /// Names this tree's volumes within the process: a new number whenever they are (re)computed (a build, a
  /// load, every refit), kept by copies. What a structure derived from the volumes is bound to (a wide
  /// tree, bvh/wide_bvh.hpp), where identity() would survive a refit that moved them.
  [[nodiscard]] std::uint64_t volumes_revision() const { return volumes_revision_; }
  [[nodiscard]] const std::vector<BV>& volumes() const { return volumes_; }
  [[nodiscard]] const TreeNode& node(std::uint32_t i) const { return nodes_[i]; }
  [[nodiscard]] const BV& volume(std::uint32_t i) const { return volumes_[i]; }
  /// Node i's volume in the form the traversals test: its unpacked form for an UnpackedVolume, else as
  /// stored.
  [[nodiscard]] const auto& tested_volume(std::uint32_t i) const {
    if constexpr (UnpackedVolume<BV>)
      return unpacked_[i];
    else
      return volumes_[i];
  }
  /// The root's full volume (hierarchical volumes store every other node relative to its parent).
  [[nodiscard]] const Fitted& root_volume() const { return root_; }
  /// Every node's bounding box in the tree's own frame, decoding hierarchical volumes top-down.
  [[nodiscard]] std::vector<Box> node_boxes() const {
    std::vector<Box> boxes(nodes_.size());
    if constexpr (hierarchical) {
      for_each_decoded([&](std::uint32_t i, const Fitted& v) { boxes[i] = v.bounding_box(); });
    } else {
      for (std::size_t i = 0; i < nodes_.size(); ++i) boxes[i] = volumes_[i].bounding_box();
    }
    return boxes;
  }
  /// Volume of node i's bounding box, cached: traversals descend into the larger of two nodes. The box, not
  /// the BV's own volume(), because a DOP's exact volume costs a polytope clipping per node.
  [[nodiscard]] float size(std::uint32_t i) const { return sizes_[i]; }
  /// Triangle vertices in tree order; empty for a tree loaded without polygons.
  [[nodiscard]] const std::vector<TrianglePoints>& triangles() const { return triangles_; }
  [[nodiscard]] bool has_polygons() const { return !triangles_.empty(); }
  /// Tree order -> index of the triangle in the source mesh.
  [[nodiscard]] const std::vector<std::uint32_t>& triangle_ids() const { return triangle_ids_; }
  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  /// A tree over a point cloud: its points in tree order (a leaf's range indexes them), and tree order ->
  /// index of the point in the cloud. Both empty for a tree over a mesh.
  [[nodiscard]] bool has_points() const { return !points_.empty(); }
  [[nodiscard]] const std::vector<Vec3>& points() const { return points_; }
  [[nodiscard]] const std::vector<std::uint32_t>& point_ids() const { return point_ids_; }

  [[nodiscard]] BvhStats stats() const {
    BvhStats s;
    s.nodes = nodes_.size();
    s.leaves = leaves_;
    s.depth = depth_;
    s.triangles = triangle_ids_.size();
    s.points = point_ids_.size();
    s.bytes_per_node =
        sizeof(TreeNode) + sizeof(BV) + (UnpackedVolume<BV> ? sizeof(unpacked_volume_t<BV>) : 0);
    s.bytes_per_triangle = s.triangles ? double(s.nodes * s.bytes_per_node) / double(s.triangles) : 0;
    s.build_seconds = build_seconds_;
    return s;
  }

 private:
  // Each node's BV is fitted to the vertices of all triangles below it (a contiguous range in tree
  // order), which is tighter than merging children for non-box volumes. Both root subtrees in parallel.
  void fit_volumes(unsigned threads) {
    std::vector<Fitted> fitted(nodes_.size(), Fitted{});
    const auto ranges = node_triangle_ranges(nodes_);
    auto fit_range = [this, &ranges](std::uint32_t i) {
      if (!points_.empty())
        return Fitted::fit(
            std::span<const Vec3>(points_).subspan(ranges[i].first, ranges[i].second - ranges[i].first));
      std::vector<Vec3> points;
      points.reserve(3 * (ranges[i].second - ranges[i].first));
      for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t)
        for (const auto& v : triangles_[t]) points.push_back(v);
      return Fitted::fit(points);
    };
    auto fit_subtree = [&](std::uint32_t root) {
      std::vector<std::uint32_t> stack{root};
      while (!stack.empty()) {
        const std::uint32_t i = stack.back();
        stack.pop_back();
        fitted[i] = fit_range(i);
        if (!nodes_[i].is_leaf()) {
          stack.push_back(nodes_[i].left());
          stack.push_back(nodes_[i].right());
        }
      }
    };
    if (threads >= 2 && !nodes_[0].is_leaf() && triangles_.size() + points_.size() / 4 > 20'000) {
      fitted[0] = fit_range(0);
      std::thread worker(fit_subtree, nodes_[0].left());
      fit_subtree(nodes_[0].right());
      worker.join();
    } else {
      fit_subtree(0);
    }
    store_volumes(std::move(fitted));
  }

  // The fitted volumes become the stored ones: as they are, or re-encoded child by child for a
  // hierarchical volume.
  void store_volumes(std::vector<Fitted> fitted) {
    root_ = fitted[0];
    if constexpr (hierarchical) {
      // Children are encoded against the parent's *decoded* volume, the one the traversal will see.
      volumes_.assign(nodes_.size(), BV{});
      std::vector<Fitted> decoded(nodes_.size());
      decoded[0] = fitted[0];
      for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
        if (nodes_[i].is_leaf()) continue;
        for (std::uint32_t c : {nodes_[i].left(), nodes_[i].right()}) {
          volumes_[c] = BV::encode(decoded[i], fitted[c]);
          decoded[c] = BV::decode(decoded[i], volumes_[c]);
        }
      }
    } else {
      volumes_ = std::move(fitted);
    }
    derive_from_volumes();
  }

  // Calls f(index, decoded volume) for every node, parents before children.
  template <class F>
  void for_each_decoded(F&& f) const {
    if (nodes_.empty()) return;
    std::vector<std::pair<std::uint32_t, Fitted>> stack{{0, root_}};
    while (!stack.empty()) {
      const auto [i, v] = stack.back();
      stack.pop_back();
      f(i, v);
      if (!nodes_[i].is_leaf())
        for (std::uint32_t c : {nodes_[i].left(), nodes_[i].right()})
          stack.emplace_back(c, BV::decode(v, volumes_[c]));
    }
  }

  // The volumes' derived data: each node's box volume (sizes_) and, for an UnpackedVolume, its unpacked form.
  void derive_from_volumes() {
    volumes_revision_ = bvh_detail::next_identity();
    if constexpr (UnpackedVolume<BV>) {
      unpacked_.clear();
      unpacked_.reserve(volumes_.size());
      for (const BV& v : volumes_) unpacked_.push_back(BV::unpack(v));
    }
    sizes_.resize(volumes_.size());
    if constexpr (hierarchical) {
      if (!nodes_.empty() && volumes_.size() == nodes_.size())
        for_each_decoded([&](std::uint32_t i, const Fitted& v) {
          sizes_[i] = static_cast<float>(v.bounding_box().volume());
        });
    } else {
      for (std::size_t i = 0; i < volumes_.size(); ++i)
        sizes_[i] = static_cast<float>(volumes_[i].bounding_box().volume());
    }
  }

  // The tree's surface-area cost: the summed surface area of the node boxes over the root box's (the
  // expected number of nodes a random line through the root box meets, as in the SAH the builder uses).
  // Scale-free. The boxes are those of the triangles below each node (merged bottom-up), or, for a tree
  // without polygons, the stored volumes' boxes.
  [[nodiscard]] double spread() const {
    if (nodes_.empty()) return 0;
    std::vector<Box> boxes;
    if (triangles_.size() == triangle_ids_.size() && !triangles_.empty()) {
      boxes.resize(nodes_.size());
      for (std::size_t i = nodes_.size(); i-- > 0;) {
        const TreeNode& n = nodes_[i];
        if (n.is_leaf()) {
          if (std::size_t(n.first) + n.count > triangles_.size()) return 0;
          for (std::uint32_t t = n.first; t < n.first + n.count; ++t)
            for (const Vec3& v : triangles_[t]) boxes[i].extend(v);
        } else {
          if (n.left() <= i || std::size_t(n.right()) >= nodes_.size())
            return 0;  // not children-after-parent
          boxes[i] = boxes[n.left()];
          boxes[i].extend(boxes[n.right()]);
        }
      }
    } else if (volumes_.size() == nodes_.size()) {
      boxes = node_boxes();
    } else {
      return 0;
    }
    auto area = [](const Box& b) {
      const Vec3 e = b.extent();
      return b.empty() ? 0.0 : double(e.x()) * e.y() + double(e.y()) * e.z() + double(e.z()) * e.x();
    };
    double all = 0;
    for (const Box& b : boxes) all += area(b);
    const double root = area(boxes[0]);
    return root > 0 ? all / root : 0;
  }

  // The tree's triangles, in tree order, at the vertex positions of `deformed`; checked first, so a refused
  // mesh changes nothing.
  [[nodiscard]] std::vector<TrianglePoints> deformed_triangles(const Mesh& deformed) const {
    if (vertex_count_ != 0 && deformed.vertices.size() != vertex_count_)
      throw std::invalid_argument("refit: the mesh has " + std::to_string(deformed.vertices.size()) +
                                  " vertices, the tree was built over a mesh of " +
                                  std::to_string(vertex_count_));
    if (deformed.triangle_count() != triangle_ids_.size())
      throw std::invalid_argument("refit: the mesh has " + std::to_string(deformed.triangle_count()) +
                                  " triangles, the tree was built over " +
                                  std::to_string(triangle_ids_.size()));
    if (topology_ != 0 && topology_fingerprint(deformed) != topology_)
      throw std::invalid_argument(
          "refit: the mesh's triangle indices differ from those of the mesh the tree was built from (a "
          "deformation must keep the topology)");
    for (std::size_t v = 0; v < deformed.vertices.size(); ++v)
      if (!deformed.vertices[v].allFinite())
        throw std::invalid_argument("refit: vertex " + std::to_string(v) + " is not finite");
    std::vector<TrianglePoints> out;
    out.reserve(triangle_ids_.size());
    for (std::uint32_t id : triangle_ids_) {
      for (std::uint32_t v : deformed.triangles[id])
        if (v >= deformed.vertices.size())
          throw std::invalid_argument("refit: triangle " + std::to_string(id) + " names a missing vertex");
      out.push_back(deformed.triangle(id));
    }
    return out;
  }

  void recount() {
    leaves_ = 0;
    depth_ = 0;
    if (nodes_.empty()) return;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 0}};
    while (!stack.empty()) {
      const auto [i, d] = stack.back();
      stack.pop_back();
      depth_ = std::max(depth_, d);
      if (nodes_[i].is_leaf()) {
        ++leaves_;
      } else {
        stack.push_back({nodes_[i].left(), d + 1});
        stack.push_back({nodes_[i].right(), d + 1});
      }
    }
  }

  std::vector<TreeNode> nodes_;
  std::vector<BV> volumes_;
  std::vector<unpacked_volume_t<BV>> unpacked_;  ///< an UnpackedVolume's, else empty
  Fitted root_{};
  std::vector<float> sizes_;
  std::vector<std::uint32_t> triangle_ids_;
  std::vector<TrianglePoints> triangles_;
  std::vector<Vec3> points_;              ///< tree order; a tree over a point cloud only
  std::vector<std::uint32_t> point_ids_;  ///< tree order -> cloud index
  std::uint32_t depth_ = 0;
  std::size_t leaves_ = 0;
  double build_seconds_ = 0;
  std::uint64_t topology_ = 0;    ///< topology_fingerprint of the source mesh; 0 for a tree from saved parts
  std::size_t vertex_count_ = 0;  ///< of the source mesh; 0 for a tree from saved parts
  std::uint64_t identity_ = 0;    ///< identity()
  std::uint64_t volumes_revision_ = 0;  ///< volumes_revision()
  double built_spread_ = 0;
};

/// A degradation() past which queries on a refitted tree are measurably slower than on a rebuilt one (1.3 to
/// 3 times on the twisted bunny: bvh/README.md, "Deforming objects: refit", bench_refit --crossover). Whether
/// a rebuild pays depends on how many queries follow it.
inline constexpr double kRebuildDegradation = 2.0;

}  // namespace bvhlab
