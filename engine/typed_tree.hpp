// The typed trees behind AnyTree and their own operations (build, load, annotate, refit, save): included by
// the generated model files (engine/volume_slot.cpp.in), each of which instantiates pair_ops<BV, D> for one
// registered volume and density. Their queries are compiled apart, in the query files
// (engine/typed_query.hpp, engine/volume_queries.cpp.in): this header does not include the traversal loops,
// so a change to a strategy recompiles the query files only. Internal to engine/.
#pragma once

#include "adb/saved_tree.hpp"
#include "adb/update.hpp"
#include "bvh/wide_bvh.hpp"
#include "engine/cloud_trees.hpp"
#include "engine/policies.hpp"
#include "engine/refusals.hpp"
#include "engine/registry.hpp"
#include "engine/tree_model.hpp"
#include "traversal/frame_budget.hpp"

#include <algorithm>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace bvhlab::engine_detail {

/// Checks a decoded tree against its mesh and re-attaches the polygons (saved trees carry none).
/// Throws std::runtime_error naming the first defect.
template <class BV, Density D>
Tree<BV, D> attach_polygons(const Tree<BV, D>& saved, const Mesh& mesh) {
  const Bvh<BV>& bvh = saved.bvh;
  const std::size_t n = mesh.triangles.size();
  const auto& ids = bvh.triangle_ids();
  if (bvh.nodes().empty()) throw std::runtime_error("the tree has no nodes");
  if (bvh.volumes().size() != bvh.nodes().size()) throw std::runtime_error("node and volume counts differ");
  if (ids.size() != n)
    throw std::runtime_error("the tree covers " + std::to_string(ids.size()) + " triangles, the mesh has " +
                             std::to_string(n));
  std::vector<bool> seen(n, false);
  for (std::uint32_t id : ids) {
    if (id >= n || seen[id]) throw std::runtime_error("triangle ids are not a permutation of the mesh's");
    seen[id] = true;
  }
  const auto ranges = node_triangle_ranges(bvh.nodes());  // throws on a malformed topology
  if (ranges.front() != std::pair<std::uint32_t, std::uint32_t>{0, static_cast<std::uint32_t>(n)})
    throw std::runtime_error("the root does not cover every triangle");
  std::vector<TrianglePoints> triangles;
  triangles.reserve(n);
  for (std::uint32_t id : ids) triangles.push_back(mesh.triangle(id));
  // Volumes stored relative to their parent (hierarchical BVs) are checked through their decoded boxes.
  const std::vector<Box> boxes = bvh.node_boxes();
  for (std::size_t i = 0; i < bvh.nodes().size(); ++i) {
    const auto node = static_cast<std::uint32_t>(i);
    if (!bvh.node(node).is_leaf()) continue;
    for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t)
      for (const Vec3& v : triangles[t]) {
        bool inside = false;
        if constexpr (requires { bvh.volume(node).contains(v); })
          inside = bvh.volume(node).contains(v);
        else
          inside = boxes[i].contains(v);
        if (!inside)
          throw std::runtime_error("leaf " + std::to_string(i) + "'s volume does not contain its triangles");
      }
  }
  Bvh<BV> with_polygons = [&] {
    if constexpr (requires { bvh.root_volume(); })
      return Bvh<BV>::from_parts(bvh.nodes(), bvh.volumes(), ids, std::move(triangles), bvh.root_volume());
    else
      return Bvh<BV>::from_parts(bvh.nodes(), bvh.volumes(), ids, std::move(triangles));
  }();
  // The density's data was validated when the saved tree was decoded (D::decode).
  return Tree<BV, D>{std::move(with_polygons), saved.density};
}

/// The densities a tree over points can carry (with_cloud_density): only these compile the surface test.
template <class D>
inline constexpr bool kCloudDensity = std::is_same_v<D, NoDensity> || std::is_same_v<D, AdbDensity>;

/// The wide layout of a tree of volume BV (bvh/wide_bvh.hpp), or NoWideLayout for a volume without one.
struct NoWideLayout {};
template <class BV>
struct WideFormOf {
  using type = NoWideLayout;
};
template <HasWideLayout BV>
struct WideFormOf<BV> {
  using type = WideTreeOf<BV>;
};
template <class BV>
using WideForm = typename WideFormOf<BV>::type;

/// A tree's queries: prepared queries and the frame budget's schedule, compiled in the query files.
struct QueryOps {
  std::unique_ptr<PreparedQuery> (*prepare)(ModelPtr a, ModelPtr b, const StrategyVariant& variant);
  std::vector<PairOutcome> (*schedule)(const TreeModel& a, std::span<const FramePairRef> pairs,
                                       const FrameOptions& options, FrameMemory* memory);
};

/// The queries of volume V and density D of the registry: defined in engine/typed_query.hpp, instantiated
/// once, in the query file of their slot.
template <std::size_t V, std::size_t D>
const QueryOps& slot_query_ops();

template <class BV, class D>
const QueryOps& query_ops() {
  return slot_query_ops<type_index<BV>(RegisteredVolumes{}), type_index<D>(RegisteredDensities{})>();
}

/// A tree's wide layout, reached apart from its density: the query files call it through this interface,
/// so that the layout's build is compiled in the tree's slot file alone (a virtual call per prepared query).
template <class BV>
class WideLayoutSource {
 public:
  [[nodiscard]] virtual const WideForm<BV>& wide_layout() const = 0;

 protected:
  ~WideLayoutSource() = default;
};

/// A typed tree, of a mesh or of a point cloud (then with its surface): what a query needs of either.
template <class BV, class D>
struct TypedBase : TreeModel, WideLayoutSource<BV> {
  TypedBase(Tree<BV, D> built, const MeshUnits& units, double build_seconds, double annotate_seconds)
      : tree(std::move(built)), bounds(root_bounds(tree.bvh)) {
    const BvhStats s = tree.bvh.stats();
    info.bv = BV::name();
    info.density = D::name();
    info.annotation = D::describe(tree.density);
    info.triangles = tree.bvh.has_points() ? 0 : s.triangles;
    info.points = tree.bvh.point_ids().size();
    info.nodes = s.nodes;
    info.depth = s.depth;
    info.density_bytes = double(D::memory_bytes(tree.density));
    info.model_bytes = double(s.nodes * s.bytes_per_node) + info.density_bytes;
    info.build_seconds = build_seconds;
    info.annotate_seconds = annotate_seconds;
    info.polygons = tree.bvh.has_polygons();
    info.units = units;
  }

  /// A mesh's side of a point query; a cloud's tree gives its surface.
  [[nodiscard]] virtual SurfaceSide side() const { return mesh_side(); }

  /// Prepared by the volume and density's query file (engine/typed_query.hpp), so that a change to a
  /// strategy does not recompile the trees' own operations.
  [[nodiscard]] std::unique_ptr<PreparedQuery> prepare(ModelPtr self, ModelPtr b,
                                                       const StrategyVariant& variant) const override {
    return query_ops<BV, D>().prepare(std::move(self), std::move(b), variant);
  }

  [[nodiscard]] double wide_layout_bytes() const override {
    if (side().is_cloud())
      throw std::invalid_argument("a point cloud's tree has no wide layout (a wide query tests triangles)");
    if constexpr (HasWideLayout<BV>)
      return double(wide_layout().bytes());
    else
      throw std::invalid_argument(wide_layout_refusal(BV::name()));
  }

  [[nodiscard]] Box world_box(const RigidTransform& pose) const override {
    // A refitted tree's bounds are not derived again: that would add a pass over its vertices to a refit.
    return bounds ? bvhlab::world_box(tree.bvh, pose, *bounds)
                  : bvhlab::world_box(tree.bvh, pose, root_bounds(tree.bvh));
  }

  /// The frame budget's schedule (engine/typed_query.hpp), compiled with the queries.
  [[nodiscard]] std::vector<PairOutcome> schedule(std::span<const FramePairRef> pairs,
                                                  const FrameOptions& options,
                                                  FrameMemory* memory) const override {
    return query_ops<BV, D>().schedule(*this, pairs, options, memory);
  }

  double refit(const Mesh& deformed, RefitMethod method) override;
  /// Drops what was derived from the volumes before they changed in place (a refit, or a follower's copy of
  /// refitted volumes): the root's bounds and the wide layout. Only while no query holds the tree.
  void volumes_changed() {
    bounds.reset();
    const std::lock_guard lock(wide_mutex_);
    wide_.reset();
  }
  [[nodiscard]] std::unique_ptr<FollowerModel> follow(const DensityUpdateSpec& spec) const override;

  Tree<BV, D> tree;
  /// The root's bounding ball and DOP vertices (traversal/broad_phase/world_box.hpp); none after a refit.
  std::optional<RootBounds> bounds;

  /// The wide layout of this tree, built on the first wide query and kept with the tree for the next ones.
  [[nodiscard]] const WideForm<BV>& wide_layout() const override {
    if constexpr (HasWideLayout<BV>) {
      const std::lock_guard lock(wide_mutex_);
      if (!wide_) wide_ = std::make_unique<const WideForm<BV>>(WideForm<BV>::build(tree.bvh));
      return *wide_;
    } else {
      throw std::invalid_argument(wide_layout_refusal(BV::name()));
    }
  }

 private:
  /// The wide layout (wide_layout); a refit drops it. Built under the lock: threads may prepare at once.
  mutable std::mutex wide_mutex_;
  mutable std::unique_ptr<const WideForm<BV>> wide_;
};

/// A mesh's tree.
template <class BV, class D>
struct TypedModel final : TypedBase<BV, D> {
  using TypedBase<BV, D>::TypedBase;

  [[nodiscard]] std::vector<std::byte> save_bytes(const std::string& source) const override {
    SaveOptions options;
    options.units = this->info.units.file;
    return save_tree_to_buffer(this->tree, options, source);
  }
};

/// A point cloud's tree, its surface and the tree's sphere coverings (the cloud's side of a point query).
template <class BV, class D>
struct PointModel final : TypedBase<BV, D> {
  PointModel(const PointCloud& cloud, Tree<BV, D> built, const MeshUnits& units, double build_seconds,
             double annotate_seconds)
      : TypedBase<BV, D>(std::move(built), units, build_seconds, annotate_seconds),
        surface(cloud),
        coverings(sphere_coverings(this->tree.bvh, surface)) {}

  [[nodiscard]] SurfaceSide side() const override { return cloud_side(surface, coverings); }
  [[nodiscard]] std::vector<std::byte> save_bytes(const std::string& source) const override {
    throw std::invalid_argument("cannot save '" + source +
                                "': a tree over a point cloud; the saved-tree format records no points or "
                                "surface (build it again from its cloud)");
  }

  PointSurface surface;
  std::vector<SphereCovering> coverings;
};

/// An adb tree of a mesh whose counts follow a refitted plain tree by density-update policy U.
template <class BV, class U>
class TypedFollower final : public FollowerModel {
 public:
  TypedFollower(const TypedBase<BV, AdbDensity>& rest, const ParamValues& values)
      : params_(update_params<U>(values)),
        state_(U::start(rest.tree.bvh, rest.tree.density, params_)),
        model_(std::make_shared<TypedModel<BV, AdbDensity>>(rest.tree, rest.info.units, 0.0, 0.0)) {}

  void take_volumes(const TreeModel& plain) override {
    const auto* typed = dynamic_cast<const TypedBase<BV, NoDensity>*>(&plain);
    if (!typed)
      throw std::invalid_argument("take_volumes: a plain " + std::string(BV::name()) +
                                  " tree is needed, not " + plain.info.bv + ", " + plain.info.annotation);
    model_->tree.bvh = typed->tree.bvh;
    model_->volumes_changed();
  }
  DensityUpdateStats update() override {
    DensityUpdateStats stats;
    U::update(model_->tree.bvh, model_->tree.density, state_, AnnotationContext{1, {}}, &stats);
    return stats;
  }
  void restart() override {
    Tree<BV, AdbDensity>& t = model_->tree;
    t.density = AdbDensity::annotate(t.bvh, t.density.params, AnnotationContext{1, {}}, nullptr);
    state_ = U::start(t.bvh, t.density, params_);
  }
  [[nodiscard]] CountError count_error(const TreeModel& exact) const override {
    const auto* typed = dynamic_cast<const TypedBase<BV, AdbDensity>*>(&exact);
    if (!typed)
      throw std::invalid_argument("count_error: the exact counts are not of an adb " +
                                  std::string(BV::name()) + " tree");
    return bvhlab::count_error(model_->tree.density, typed->tree.density);
  }
  [[nodiscard]] std::shared_ptr<TreeModel> model() const override { return model_; }

 private:
  typename U::Params params_;
  typename U::State state_;
  std::shared_ptr<TypedModel<BV, AdbDensity>> model_;
};

template <class BV, class D>
double TypedBase<BV, D>::refit(const Mesh& deformed, RefitMethod method) {
  if constexpr (std::is_same_v<D, NoDensity>) {
    tree.bvh.refit(deformed, method);
    volumes_changed();
    return tree.bvh.degradation();
  } else {
    throw std::invalid_argument("refit: a tree with density " + info.density +
                                "; refit its plain tree and keep the counts with a density update "
                                "(FollowingDensity)");
  }
}

template <class BV, class D>
std::unique_ptr<FollowerModel> TypedBase<BV, D>::follow(const DensityUpdateSpec& spec) const {
  if constexpr (std::is_same_v<D, AdbDensity>) {
    if (!info.polygons) throw std::invalid_argument("a density update needs a tree of a mesh, with polygons");
    return with_density_update(spec.name,
                               [&]<class U>(std::type_identity<U>) -> std::unique_ptr<FollowerModel> {
                                 return std::make_unique<TypedFollower<BV, U>>(*this, spec.values);
                               });
  } else {
    throw std::invalid_argument("density updates keep adb counts; this tree carries " + info.density);
  }
}

/// The tree of `mesh` with density D.
template <class BV, class D>
ModelPtr build_mesh_tree(const Mesh& mesh, const MeshUnits& units, const DensitySpec& density,
                         const BuildOptions& options) {
  Bvh<BV> bvh = Bvh<BV>::build(mesh, options);
  const double build_seconds = bvh.stats().build_seconds;
  AnnotationContext context;
  context.threads = options.threads;
  context.progress = options.progress;  // the caller hears the annotation too (and may stop it there)
  AnnotateStats stats;                  // NoDensity annotates nothing: 0 seconds
  Tree<BV, D> tree = annotate_tree<D>(std::move(bvh), density_params<D>(density.values), context, &stats);
  return std::make_shared<TypedModel<BV, D>>(std::move(tree), units, build_seconds, stats.seconds);
}

/// The tree of a cloud: NoDensity, or AdbDensity with counts from the points' areas (with_cloud_density
/// refuses the others).
template <class BV, class D>
ModelPtr build_cloud_tree(const UnitCloud& cloud, const DensitySpec& density, const BuildOptions& options) {
  ModelPtr out;
  with_cloud_density<BV>(density.name, std::string(BV::name()), [&]<class Cloud>() {
    if constexpr (std::is_same_v<Cloud, D>) {
      double annotate_seconds = 0;
      const auto start = Clock::now();
      Tree<BV, D> tree = cloud_tree<BV, D>(cloud, density.values, options, annotate_seconds);
      const double seconds = seconds_since(start);
      out = std::make_shared<PointModel<BV, D>>(cloud, std::move(tree), cloud.units,
                                                seconds - annotate_seconds, annotate_seconds);
    } else {
      throw std::logic_error("build_points: density " + density.name + " reached another density's slot");
    }
  });
  return out;
}

template <class BV, class D>
ModelPtr load_tree(std::span<const std::byte> bytes, const std::string& source, const Mesh* mesh,
                   const MeshUnits& units) {
  Tree<BV, D> tree = load_tree_from_buffer<BV, D>(bytes, source);
  if (mesh) tree = attach_polygons(tree, *mesh);
  return std::make_shared<TypedModel<BV, D>>(std::move(tree), units, 0.0, 0.0);
}

/// A copy of the plain tree `plain` (a TypedModel<BV, NoDensity>, checked by the caller) annotated with D.
template <class BV, class D>
ModelPtr annotate_plain(const TreeModel& plain, const DensitySpec& density, const AnnotationContext& context,
                        AnnotateStats* stats) {
  const auto& typed = static_cast<const TypedBase<BV, NoDensity>&>(plain);
  AnnotateStats local;
  Tree<BV, D> annotated =
      annotate_tree<D>(Bvh<BV>(typed.tree.bvh), density_params<D>(density.values), context, &local);
  if (stats) *stats = local;
  return std::make_shared<TypedModel<BV, D>>(std::move(annotated), plain.info.units, plain.info.build_seconds,
                                             local.seconds);
}

template <class BV, class D>
const PairOps& pair_ops() {
  if constexpr (DensityFor<D, BV>) {
    static const PairOps ops{&build_mesh_tree<BV, D>, &build_cloud_tree<BV, D>, &load_tree<BV, D>,
                             &annotate_plain<BV, D>};
    return ops;
  } else {
    return refusing_ops<CannotAnnotate<BV, D>>();
  }
}

/// The operations of volume V and density D of the registry; beyond either list, a stub (its slot's file
/// compiles to nothing of substance).
template <std::size_t V, std::size_t D>
const PairOps& slot_ops() {
  if constexpr (V < type_list_size(RegisteredVolumes{}) && D < type_list_size(RegisteredDensities{}))
    return pair_ops<TypeAt<V, RegisteredVolumes>, TypeAt<D, RegisteredDensities>>();
  else
    throw std::logic_error("engine slot beyond the registered volumes and densities");
}

}  // namespace bvhlab::engine_detail
