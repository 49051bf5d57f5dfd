// The typed trees behind AnyTree and their operations: included only by the generated translation units
// (engine/volume_slot.cpp.in), each of which instantiates pair_ops<BV, D> for one registered volume and
// density, with every strategy on them. Internal to engine/.
#pragma once

#include "adb/saved_tree.hpp"
#include "adb/update.hpp"
#include "bvh/wide_bvh.hpp"
#include "engine/cloud_trees.hpp"
#include "engine/policies.hpp"
#include "engine/refusals.hpp"
#include "engine/registry.hpp"
#include "engine/tree_model.hpp"
#include "traversal/contact_geometry.hpp"
#include "traversal/frame_schedule.hpp"
#include "traversal/strategies.hpp"

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

/// What a density-free strategy (kDensityFree) reads of a tree: its hierarchy alone, so that one compiled
/// query serves the trees of every density; and its wide layout when the query walks that (owned by the
/// tree's model, which the query keeps alive).
template <class BV>
struct HierarchyOnly {
  const Bvh<BV>& bvh;
  const WideForm<BV>* wide = nullptr;
};

/// A tree as strategy S reads it: `Held` is std::reference_wrapper<const Tree<BV, D>> or HierarchyOnly<BV>.
template <class T>
const T& tree_of(const std::reference_wrapper<const T>& held) {
  return held.get();
}
template <class BV>
const HierarchyOnly<BV>& tree_of(const HierarchyOnly<BV>& held) {
  return held;
}
template <class Held>
using HeldTree = std::remove_cvref_t<decltype(tree_of(std::declval<const Held&>()))>;

/// The two trees of a prepared query as its strategy reads them, their sides of a point query, and their
/// models, kept alive while the query lives.
template <class Held>
struct QueryTrees {
  ModelPtr owner_a, owner_b;
  Held a, b;
  SurfaceSide side_a, side_b;
};

/// Strategy S on two trees of volume BV, configured once; with kSurfaces, with the clouds' surface test at
/// the leaves (traversal/point_leaves.hpp), made per pose as query_exact_points and query_adb_points make it.
template <class S, class BV, class Held, bool kSurfaces>
class TypedQuery final : public PreparedQuery {
 public:
  TypedQuery(QueryTrees<Held> trees, typename S::Options options, bool coherent,
             bool contact_geometry = false)
      : trees_(std::move(trees)), options_(std::move(options)), coherent_(coherent) {
    if (contact_geometry)
      geometry_.emplace(a().bvh.triangles(), a().bvh.triangle_ids(), b().bvh.triangles(),
                        b().bvh.triangle_ids());
  }
  void run(std::span<const RigidTransform> poses, const ResultSink& sink) const override {
    if (coherent_) {
      CoherentState state;
      return run(poses, sink, state);
    }
    for (std::size_t i = 0; i < poses.size(); ++i) sink(i, query(poses[i]));
  }
  void run(std::span<const RigidTransform> poses, const ResultSink& sink,
           CoherentState& state) const override {
    if (!coherent_) throw std::logic_error("a coherent run of a query not prepared coherent");
    for (std::size_t i = 0; i < poses.size(); ++i) sink(i, query(poses[i], state));
  }
  void time(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out) const override {
    if (coherent_) {
      CoherentState state;
      return timed_series(poses, warmup, out, [&](const RigidTransform& pose) { return query(pose, state); });
    }
    timed_series(poses, warmup, out, [this](const RigidTransform& pose) { return query(pose); });
  }
  void time(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
            CoherentState& state) const override {
    if (!coherent_) throw std::logic_error("a coherent run of a query not prepared coherent");
    timed_coherent_series(poses, warmup, out, coherent_query(), state);
  }
  void time_per_pose(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
                     std::span<CoherentState> states) const override {
    if (!coherent_) throw std::logic_error("a coherent run of a query not prepared coherent");
    timed_per_pose_series(poses, warmup, out, coherent_query(), states);
  }
  [[nodiscard]] bool coherent() const override { return coherent_; }

 private:
  /// Not inlined: both loops call one copy of the traversal (a direct call per query, not a virtual one),
  /// which halves what each combination costs to compile.
  [[gnu::noinline]] Result query(const RigidTransform& pose) const {
    if constexpr (kSurfaces) {
      const SurfaceLeaves<BV> leaves(a().bvh, trees_.side_a, b().bvh, trees_.side_b, pose);
      return S::query(a(), b(), pose, options_, leaves);
    } else {
      if constexpr (kWalksWide)
        if (trees_.a.wide)
          return with_geometry(pose, S::query_wide(a(), *a().wide, b(), *b().wide, pose, options_));
      return with_geometry(pose, S::query(a(), b(), pose, options_));
    }
  }
  /// Whether a prepared query of this type may walk the wide layouts (prepare sets them only for a wide
  /// variant).
  static constexpr bool kWalksWide =
      kRunsWide<S> && HasWideLayout<BV> && std::is_same_v<Held, HierarchyOnly<BV>>;
  Result with_geometry(const RigidTransform& pose, Result r) const {
    if (geometry_) (*geometry_)(pose, r);
    return r;
  }
  /// The coherent query (prepare lets coherent_ be set only for a strategy that has one).
  [[gnu::noinline]] Result query(const RigidTransform& pose, CoherentState& state) const {
    if constexpr (!kRunsCoherent<S>) {
      throw std::logic_error("strategy " + std::string(S::name()) + " prepared coherent");
    } else if constexpr (kSurfaces) {
      const SurfaceLeaves<BV> leaves(a().bvh, trees_.side_a, b().bvh, trees_.side_b, pose);
      return S::query_coherent(a(), b(), pose, options_, state, leaves);
    } else {
      return with_geometry(pose, S::query_coherent(a(), b(), pose, options_, state));
    }
  }
  /// The coherent query as the timing loops call it.
  auto coherent_query() const {
    return [this](const RigidTransform& pose, CoherentState& state) { return query(pose, state); };
  }
  const auto& a() const { return tree_of(trees_.a); }
  const auto& b() const { return tree_of(trees_.b); }

  QueryTrees<Held> trees_;
  typename S::Options options_;
  bool coherent_ = false;
  std::optional<ContactGeometryMaker> geometry_;  ///< when the variant asks for the contacts' geometry
};

/// The prepared query of strategy S (configured as `options`) on `trees`, with the surface test when a side
/// is a cloud (compiled only with kClouds: trees whose density a cloud's tree can carry). The caller checked
/// the variant against the trees.
template <class S, class BV, bool kClouds, class Held>
std::unique_ptr<PreparedQuery> make_query(QueryTrees<Held> trees, typename S::Options options,
                                          const StrategyVariant& variant) {
  if (!trees.side_a.is_cloud() && !trees.side_b.is_cloud())
    return std::make_unique<TypedQuery<S, BV, Held, false>>(std::move(trees), std::move(options),
                                                            variant.coherent, variant.contact_geometry);
  if constexpr (kClouds && takes_leaf_test_on<S, BV, HeldTree<Held>>)
    return std::make_unique<TypedQuery<S, BV, Held, true>>(std::move(trees), std::move(options),
                                                           variant.coherent);
  else
    throw std::logic_error("cloud_query_refusal let strategy " + variant.strategy +
                           " through without a leaf test");
}

/// The queries of the density-free strategies on volume slot V, for trees of any density: compiled in the
/// volume's first slot file only (engine/volume_slot.cpp.in), which every engine with the volume has.
template <std::size_t V, bool = (V < type_list_size(RegisteredVolumes{}))>
struct DensityFreeQueries {
  using BV = TypeAt<V, RegisteredVolumes>;
  /// Throws std::logic_error for a strategy that is not density-free (the caller dispatches those itself).
  static std::unique_ptr<PreparedQuery> prepare(QueryTrees<HierarchyOnly<BV>> trees,
                                                const StrategyVariant& variant);
};
template <std::size_t V>
struct DensityFreeQueries<V, false> {};  ///< a slot beyond the registered volumes

template <std::size_t V, bool kRegistered>
std::unique_ptr<PreparedQuery> DensityFreeQueries<V, kRegistered>::prepare(
    QueryTrees<HierarchyOnly<BV>> trees, const StrategyVariant& variant) {
  // The strategy is looked up by name again and its options made again (the caller checked them): a member
  // template per strategy would not be covered by the class's extern declaration.
  return with_strategy(
      variant.strategy, [&]<class S>(std::type_identity<S>) -> std::unique_ptr<PreparedQuery> {
        if constexpr (kDensityFree<S> && kAcceptsVolume<S, BV>)
          return make_query<S, BV, true>(std::move(trees),
                                         strategy_options<S>(variant.values, variant.budget), variant);
        else
          throw std::logic_error("strategy " + variant.strategy + " reached the density-free queries");
      });
}

/// A typed tree, of a mesh or of a point cloud (then with its surface): what a query needs of either.
template <class BV, class D>
struct TypedBase : TreeModel {
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

  [[nodiscard]] std::unique_ptr<PreparedQuery> prepare(ModelPtr self, ModelPtr b,
                                                       const StrategyVariant& variant) const override {
    auto other = std::dynamic_pointer_cast<const TypedBase>(b);
    if (!other)
      throw std::invalid_argument("the two trees differ in BV or density (" + info.bv + ", " +
                                  info.annotation + " vs " + b->info.bv + ", " + b->info.annotation + ")");
    auto a = std::static_pointer_cast<const TypedBase>(std::move(self));
    std::unique_ptr<PreparedQuery> out;
    with_strategy(variant.strategy, [&]<class S>(std::type_identity<S>) {
      if constexpr (!kAcceptsVolume<S, BV>)
        throw std::invalid_argument(strategy_info(variant.strategy).volume_refusal(BV::name()));
      else if constexpr (S::template accepts<D>)
        out = prepare_typed<S>(std::move(a), std::move(other), variant);
      else
        throw std::invalid_argument(strategy_info(variant.strategy).refusal(D::name()));
    });
    return out;
  }

  [[nodiscard]] double wide_layout_bytes() const override {
    if (side().is_cloud())
      throw std::invalid_argument("a point cloud's tree has no wide layout (a wide query tests triangles)");
    if constexpr (HasWideLayout<BV>)
      return double(wide_of(*this).bytes());
    else
      throw std::invalid_argument(wide_layout_refusal(BV::name()));
  }

  [[nodiscard]] Box world_box(const RigidTransform& pose) const override {
    // A refitted tree's bounds are not derived again: that would add a pass over its vertices to a refit.
    return bounds ? bvhlab::world_box(tree.bvh, pose, *bounds)
                  : bvhlab::world_box(tree.bvh, pose, root_bounds(tree.bvh));
  }

  [[nodiscard]] std::vector<PairOutcome> schedule(std::span<const FramePairRef> pairs,
                                                  const FrameOptions& options,
                                                  FrameMemory* memory) const override {
    if constexpr (ProbabilityDensity<D>) {
      std::vector<FramePair<BV, D>> typed;
      typed.reserve(pairs.size());
      for (const FramePairRef& p : pairs) {
        const auto* a = dynamic_cast<const TypedBase*>(p.a->model().get());
        const auto* b = dynamic_cast<const TypedBase*>(p.b->model().get());
        if (!a || !b)
          throw std::invalid_argument("a frame budget runs on trees of one volume and density; " + info.bv +
                                      ", " + info.annotation + " met another");
        typed.push_back({&a->tree, &b->tree, p.b_to_a, p.identity});
      }
      return schedule_frame<BV, D>(std::span<const FramePair<BV, D>>(typed), options, memory);
    } else {
      throw std::invalid_argument("frame budgets need a density with probabilities; the trees carry " +
                                  info.density);
    }
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

 private:
  /// S configured, checked against both trees, with the surface test when either is a cloud's.
  template <class S>
  std::unique_ptr<PreparedQuery> prepare_typed(std::shared_ptr<const TypedBase> a,
                                               std::shared_ptr<const TypedBase> b,
                                               const StrategyVariant& variant) const {
    if constexpr (ProbabilityDensity<D>)  // refuses trees annotated with other parameters, before any pose
      (void)D::estimator(tree.density, b->tree.density);
    auto options = strategy_options<S>(variant.values, variant.budget);
    if (variant.coherent && !kRunsCoherent<S>)
      throw std::invalid_argument(strategy_info(variant.strategy).coherent_refusal());
    if (variant.contact_geometry && !S::needs_polygons)
      throw std::invalid_argument(strategy_info(variant.strategy).contact_geometry_refusal());
    if (variant.wide) check_wide<S>(variant, side().is_cloud() || b->side().is_cloud());
    if (side().is_cloud() || b->side().is_cloud()) {
      if (variant.contact_geometry)
        throw std::invalid_argument("contact geometry needs triangles; a point cloud's tree has none");
      if constexpr (kCloudDensity<D>)
        check_points<S>(*a, *b, options, variant);
      else
        throw std::logic_error("a tree over points with density " + info.density);
    } else if (S::needs_polygons && !(info.polygons && b->info.polygons)) {
      throw std::invalid_argument(
          "strategy " + variant.strategy +
          " tests triangles, and a tree was loaded without polygons (load it with its "
          "mesh)");
    }
    const SurfaceSide side_a = a->side(), side_b = b->side();
    const Bvh<BV>& bvh_a = a->tree.bvh;
    const Bvh<BV>& bvh_b = b->tree.bvh;
    if constexpr (kDensityFree<S>) {
      QueryTrees<HierarchyOnly<BV>> trees{std::move(a), std::move(b), {bvh_a}, {bvh_b}, side_a, side_b};
      if constexpr (HasWideLayout<BV>)
        if (variant.wide) {
          trees.a.wide = &wide_of(*trees.owner_a);
          trees.b.wide = &wide_of(*trees.owner_b);
        }
      return DensityFreeQueries<type_index<BV>(RegisteredVolumes{})>::prepare(std::move(trees), variant);
    } else {
      const Tree<BV, D>& tree_a = a->tree;
      const Tree<BV, D>& tree_b = b->tree;
      QueryTrees<std::reference_wrapper<const Tree<BV, D>>> trees{
          std::move(a), std::move(b), std::cref(tree_a), std::cref(tree_b), side_a, side_b};
      return make_query<S, BV, kCloudDensity<D>>(std::move(trees), std::move(options), variant);
    }
  }

  /// The refusals of a wide variant: a strategy without a wide walk, a volume without a wide layout, point
  /// leaves, a coherent walk.
  template <class S>
  static void check_wide(const StrategyVariant& variant, bool cloud) {
    if (!kRunsWide<S>) throw std::invalid_argument(strategy_info(variant.strategy).wide_refusal());
    if (!HasWideLayout<BV>) throw std::invalid_argument(wide_layout_refusal(BV::name()));
    if (variant.coherent)
      throw std::invalid_argument(
          "a coherent query walks the binary trees; ask for coherent or wide, not both");
    if (cloud)
      throw std::invalid_argument(
          "a wide query tests triangles at the leaves; a point cloud's tree has none");
  }

  /// The wide layout of `model` (a TypedBase of this volume and density: the caller checked), built on the
  /// first wide query and kept with the tree for the next ones.
  static const WideForm<BV>& wide_of(const TreeModel& model) {
    const auto& typed = static_cast<const TypedBase&>(model);
    const std::lock_guard lock(typed.wide_mutex_);
    if (!typed.wide_) typed.wide_ = std::make_unique<const WideForm<BV>>(WideForm<BV>::build(typed.tree.bvh));
    return *typed.wide_;
  }

  /// The wide layout (wide_of); a refit drops it. Built under the lock: threads may prepare queries at once.
  mutable std::mutex wide_mutex_;
  mutable std::unique_ptr<const WideForm<BV>> wide_;

  /// SurfaceLeaves' checks of the two sides and the strategy's (so running cannot fail).
  template <class S>
  static void check_points(const TypedBase& a, const TypedBase& b, const typename S::Options& options,
                           const StrategyVariant& variant) {
    (void)SurfaceLeaves<BV>(a.tree.bvh, a.side(), b.tree.bvh, b.side(), RigidTransform{});
    if (const std::string refusal = cloud_query_refusal<S, BV, D>(options, variant.strategy);
        !refusal.empty())
      throw std::invalid_argument(refusal);
  }
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
