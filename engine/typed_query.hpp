// The queries of the typed trees (engine/typed_tree.hpp): every strategy prepared on them, and the frame
// budget's schedule. The traversal loops are not included here but by the two kinds of generated query file
// that instantiate them (engine/CMakeLists.txt), so that a change to one loop recompiles one kind:
//   - free_queries.hpp (volume_free_queries.cpp.in): the density-free strategies (exact, all contacts,
//     distance, tolerance, anytime distance), DensityFreeQueries<V>, once per volume;
//   - density_queries.hpp (volume_queries.cpp.in): slot_query_ops<V, D>, every other strategy (the ADB
//     family) and the frame schedule, per volume and pair of densities.
// Internal to engine/.
#pragma once

#include "engine/errors.hpp"
#include "engine/typed_tree.hpp"
#include "traversal/contact_geometry.hpp"
#include "traversal/surface_leaves.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace bvhlab {

/// Strategy S, given two trees of type TreeT (a Tree<BV, D>, or what else it reads a tree as), runs on point
/// clouds: it takes the leaf test as a last argument (S::query(a, b, pose, options, leaves)).
template <class S, class BV, class TreeT>
inline constexpr bool takes_leaf_test_on = requires(const TreeT& tree, const RigidTransform& pose,
                                                    const typename S::Options& options,
                                                    const SurfaceLeaves<BV>& leaves) {
  S::query(tree, tree, pose, options, leaves);
};
/// Why strategy S, configured with `options`, cannot query point clouds on trees of BV read as TreeT; empty
/// when it can: it takes a leaf test (takes_leaf_test_on) and answers something other than triangle pairs
/// (all_contacts).
template <class S, TreeVolume BV, class TreeT>
std::string cloud_query_refusal(const typename S::Options& options, std::string_view name) {
  if constexpr (std::is_same_v<typename S::Options, ContactMode>)
    if (options == ContactMode::All)
      return "strategy " + std::string(name) +
             " lists intersecting triangle pairs, and a point cloud has none";
  if constexpr (!takes_leaf_test_on<S, BV, TreeT>)
    return "strategy " + std::string(name) + " takes no leaf test, so it cannot query point clouds";
  return {};
}

}  // namespace bvhlab

namespace bvhlab::engine_detail {

/// What a density-free strategy (kDensityFree) reads of a tree: its hierarchy alone, so that one compiled
/// query serves the trees of every density; and its wide layout when the query walks that (owned by the
/// tree's model, which the query keeps alive).
template <class BV>
struct HierarchyOnly {
  const Bvh<BV>& bvh;
  const WideForm<BV>* wide = nullptr;
};

/// What a strategy that reads the density (ADB's) holds of a tree: the tree, and its wide layout when the
/// query walks that.
template <class BV, class D>
struct AnnotatedTree {
  const Tree<BV, D>& tree;
  const WideForm<BV>* wide = nullptr;
};

/// A tree as strategy S reads it: `Held` is AnnotatedTree<BV, D> or HierarchyOnly<BV>.
template <class BV, class D>
const Tree<BV, D>& tree_of(const AnnotatedTree<BV, D>& held) {
  return held.tree;
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
    const CoherentState::InUse held(state);  // once for the run, not per query
    for (std::size_t i = 0; i < poses.size(); ++i) sink(i, query(poses[i], state));
  }
  void time(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out) const override {
    if (coherent_) {
      CoherentState state;
      const CoherentState::InUse held(state);
      return timed_series(poses, warmup, out, [&](const RigidTransform& pose) { return query(pose, state); });
    }
    timed_series(poses, warmup, out, [this](const RigidTransform& pose) { return query(pose); });
  }
  void time(std::span<const RigidTransform> poses, int warmup, std::vector<QueryRecord>& out,
            CoherentState& state) const override {
    if (!coherent_) throw std::logic_error("a coherent run of a query not prepared coherent");
    const CoherentState::InUse held(state);
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
      Result result = walk(pose);  // returned in place: a Result is too large to move per query
      add_geometry(pose, result);
      return result;
    }
  }
  /// The walk of a query without surfaces: the wide layouts' when prepared with them.
  Result walk(const RigidTransform& pose) const {
    if constexpr (kWalksWide)
      if (trees_.a.wide) return S::query_wide(a(), *trees_.a.wide, b(), *trees_.b.wide, pose, options_);
    return S::query(a(), b(), pose, options_);
  }
  /// Whether a prepared query of this type may walk the wide layouts (prepare sets them only for a wide
  /// variant).
  static constexpr bool kWalksWide = kRunsWide<S> && HasWideLayout<BV> && kWalksWideOn<S, BV>;
  void add_geometry(const RigidTransform& pose, Result& r) const {
    if (geometry_) (*geometry_)(pose, r);
  }
  /// The coherent query (prepare lets coherent_ be set only for a strategy that has one).
  [[gnu::noinline]] Result query(const RigidTransform& pose, CoherentState& state) const {
    if constexpr (!kRunsCoherent<S>) {
      throw_logic_error({"strategy ", S::name(), " prepared coherent"});
    } else if constexpr (kSurfaces) {
      const SurfaceLeaves<BV> leaves(a().bvh, trees_.side_a, b().bvh, trees_.side_b, pose);
      return S::query_coherent(a(), b(), pose, options_, state, leaves);
    } else {
      Result result = S::query_coherent(a(), b(), pose, options_, state);
      add_geometry(pose, result);
      return result;
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
/// the rest of the variant against the trees (TreeQueries::check_variant); a strategy that cannot query
/// clouds is refused here, where its options are known.
template <class S, class BV, bool kClouds, class Held>
std::unique_ptr<PreparedQuery> make_query(QueryTrees<Held> trees, typename S::Options options,
                                          const StrategyVariant& variant) {
  if (!trees.side_a.is_cloud() && !trees.side_b.is_cloud())
    return std::make_unique<TypedQuery<S, BV, Held, false>>(std::move(trees), std::move(options),
                                                            variant.coherent, variant.contact_geometry);
  if (const std::string refusal = cloud_query_refusal<S, BV, HeldTree<Held>>(options, variant.strategy);
      !refusal.empty())
    throw std::invalid_argument(refusal);
  if constexpr (kClouds && takes_leaf_test_on<S, BV, HeldTree<Held>>)
    return std::make_unique<TypedQuery<S, BV, Held, true>>(std::move(trees), std::move(options),
                                                           variant.coherent);
  else
    throw_logic_error({"check_variant let a point cloud's tree through to strategy ", variant.strategy});
}

/// The queries of the density-free strategies on volume slot V, for trees of any density: compiled in the
/// volume's free query file (engine/volume_free_queries.cpp.in), declared compiled there in the others.
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
  // The strategy is looked up by name again (the caller checked the variant against the trees, all but the
  // options): a member template per strategy would not be covered by the class's extern declaration.
  return with_strategy(
      variant.strategy, [&]<class S>(std::type_identity<S>) -> std::unique_ptr<PreparedQuery> {
        if constexpr (kDensityFree<S> && kAcceptsVolume<S, BV>)
          return make_query<S, BV, true>(std::move(trees),
                                         strategy_options<S>(variant.values, variant.budget), variant);
        else
          throw_logic_error({"strategy ", variant.strategy, " reached the density-free queries"});
      });
}

/// The queries on two trees of volume BV and density D (their models TypedBase<BV, D>).
template <class BV, class D>
struct TreeQueries {
  using Base = TypedBase<BV, D>;

  /// Strategy `variant.strategy` on `self` and `b`, checked against both; QueryOps::prepare. The checks and
  /// the density-free strategies' queries are compiled once per volume and density, not once per strategy.
  static std::unique_ptr<PreparedQuery> prepare(ModelPtr self, ModelPtr b, const StrategyVariant& variant) {
    auto other = std::dynamic_pointer_cast<const Base>(b);
    if (!other)
      throw std::invalid_argument("the two trees differ in BV or density (" + self->info.bv + ", " +
                                  self->info.annotation + " vs " + b->info.bv + ", " + b->info.annotation +
                                  ")");
    auto a = std::static_pointer_cast<const Base>(std::move(self));
    const StrategyInfo& info = strategy_info(variant.strategy);
    check_variant(info, *a, *other, variant);
    if (info.density_free) return prepare_density_free(std::move(a), std::move(other), variant);
    std::unique_ptr<PreparedQuery> out;
    with_strategy(variant.strategy, [&]<class S>(std::type_identity<S>) {
      if constexpr (!kDensityFree<S> && kAcceptsVolume<S, BV> && S::template accepts<D>)
        out = prepare_typed<S>(std::move(a), std::move(other), variant);
      else
        throw_logic_error(
            {"check_variant let strategy ", variant.strategy, " through on ", BV::name(), ", ", D::name()});
    });
    return out;
  }

  /// The frame budget over `pairs` (every tree a TypedBase<BV, D>); QueryOps::schedule.
  static std::vector<PairOutcome> schedule(const TreeModel& self, std::span<const FramePairRef> pairs,
                                           const FrameOptions& options, FrameMemory* memory) {
    if constexpr (ProbabilityDensity<D>) {
      std::vector<FramePair<BV, D>> typed;
      typed.reserve(pairs.size());
      for (const FramePairRef& p : pairs) {
        const auto* a = dynamic_cast<const Base*>(p.a->model().get());
        const auto* b = dynamic_cast<const Base*>(p.b->model().get());
        if (!a || !b)
          throw std::invalid_argument("a frame budget runs on trees of one volume and density; " +
                                      self.info.bv + ", " + self.info.annotation + " met another");
        typed.push_back({&a->tree, &b->tree, p.b_to_a, p.identity});
      }
      return schedule_frame<BV, D>(std::span<const FramePair<BV, D>>(typed), options, memory);
    } else {
      throw std::invalid_argument("frame budgets need a density with probabilities; the trees carry " +
                                  self.info.density);
    }
  }

 private:
  /// Throws std::invalid_argument with a StrategyInfo refusal, unless it is empty (nothing refused).
  static void refuse_if(const std::string& refusal) {
    if (!refusal.empty()) throw std::invalid_argument(refusal);
  }

  /// Every check of `variant` on trees `a` and `b` that the strategy's row (`info`) answers, in this order:
  /// the volume, the density and its parameters, coherent, contact geometry, wide, the point clouds' sides
  /// or the polygons. The strategy's options and, on clouds, its leaf test follow (make_query).
  static void check_variant(const StrategyInfo& info, const Base& a, const Base& b,
                            const StrategyVariant& variant) {
    refuse_if(info.volume_refusal(BV::name()));
    refuse_if(info.refusal(D::name()));
    if constexpr (ProbabilityDensity<D>)  // refuses trees annotated with other parameters, before any pose
      (void)D::estimator(a.tree.density, b.tree.density);
    if (variant.coherent) refuse_if(info.coherent_refusal());
    if (variant.contact_geometry) refuse_if(info.contact_geometry_refusal());
    const bool cloud = a.side().is_cloud() || b.side().is_cloud();
    if (variant.wide) check_wide(info, variant, cloud);
    if (cloud) {
      if (variant.contact_geometry)
        throw std::invalid_argument("contact geometry needs triangles; a point cloud's tree has none");
      if constexpr (!kCloudDensity<D>)
        throw std::logic_error("a tree over points with density " + a.info.density);
      (void)SurfaceLeaves<BV>(a.tree.bvh, a.side(), b.tree.bvh, b.side(), RigidTransform{});
    } else if (info.needs_polygons && !(a.info.polygons && b.info.polygons)) {
      throw std::invalid_argument(
          "strategy " + variant.strategy +
          " tests triangles, and a tree was loaded without polygons (load it with its mesh)");
    }
  }

  /// The refusals of a wide variant: a strategy without a wide walk, a volume without a wide layout or one
  /// the strategy's wide walk does not take, a coherent walk, point leaves.
  static void check_wide(const StrategyInfo& info, const StrategyVariant& variant, bool cloud) {
    refuse_if(info.wide_walk_refusal(BV::name()));
    if (variant.coherent)
      throw std::invalid_argument(
          "a coherent query walks the binary trees; ask for coherent or wide, not both");
    if (cloud)
      throw std::invalid_argument(
          "a wide query tests triangles at the leaves; a point cloud's tree has none");
  }

  /// A density-free strategy (checked): its query reads the hierarchies (and the wide layouts when asked),
  /// compiled once for the volume (DensityFreeQueries).
  static std::unique_ptr<PreparedQuery> prepare_density_free(std::shared_ptr<const Base> a,
                                                             std::shared_ptr<const Base> b,
                                                             const StrategyVariant& variant) {
    const Bvh<BV>& bvh_a = a->tree.bvh;
    const Bvh<BV>& bvh_b = b->tree.bvh;
    const SurfaceSide side_a = a->side(), side_b = b->side();
    const WideLayoutSource<BV>& a_tree = *a;  // not Base: the layout's build stays in the slot file
    const WideLayoutSource<BV>& b_tree = *b;
    QueryTrees<HierarchyOnly<BV>> trees{std::move(a), std::move(b), {bvh_a}, {bvh_b}, side_a, side_b};
    if constexpr (HasWideLayout<BV>)
      if (variant.wide) {
        trees.a.wide = &a_tree.wide_layout();
        trees.b.wide = &b_tree.wide_layout();
      }
    return DensityFreeQueries<type_index<BV>(RegisteredVolumes{})>::prepare(std::move(trees), variant);
  }

  /// Strategy S, which reads the density (checked), configured.
  template <class S>
  static std::unique_ptr<PreparedQuery> prepare_typed(std::shared_ptr<const Base> a,
                                                      std::shared_ptr<const Base> b,
                                                      const StrategyVariant& variant) {
    auto options = strategy_options<S>(variant.values, variant.budget);
    const SurfaceSide side_a = a->side(), side_b = b->side();
    const Tree<BV, D>& tree_a = a->tree;
    const Tree<BV, D>& tree_b = b->tree;
    const WideLayoutSource<BV>& a_tree = *a;  // not Base: the layout's build stays in the slot file
    const WideLayoutSource<BV>& b_tree = *b;
    QueryTrees<AnnotatedTree<BV, D>> trees{std::move(a), std::move(b), {tree_a}, {tree_b}, side_a, side_b};
    if constexpr (HasWideLayout<BV>)
      if (variant.wide) {
        trees.a.wide = &a_tree.wide_layout();
        trees.b.wide = &b_tree.wide_layout();
      }
    return make_query<S, BV, kCloudDensity<D>>(std::move(trees), std::move(options), variant);
  }
};

template <std::size_t V, std::size_t D>
const QueryOps& slot_query_ops() {
  if constexpr (V < type_list_size(RegisteredVolumes{}) && D < type_list_size(RegisteredDensities{})) {
    using BV = TypeAt<V, RegisteredVolumes>;
    using Dn = TypeAt<D, RegisteredDensities>;
    if constexpr (DensityFor<Dn, BV>) {
      static const QueryOps ops{&TreeQueries<BV, Dn>::prepare, &TreeQueries<BV, Dn>::schedule};
      return ops;
    }
  }
  // pair_ops refuses these combinations before a tree exists, so no tree asks for their queries.
  throw std::logic_error("no queries compiled for engine slot " + std::to_string(V) + ", " +
                         std::to_string(D));
}

}  // namespace bvhlab::engine_detail
