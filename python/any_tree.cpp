#include "python/any_tree.hpp"

#include "adb/saved_tree.hpp"
#include "bench/cloud_query.hpp"
#include "bench/core/policies.hpp"
#include "bench/core/registry.hpp"
#include "bench/core/tree_cache.hpp"
#include "bench/prepare.hpp"
#include "traversal/point_leaves.hpp"
#include "traversal/strategies.hpp"

#include <cstdio>
#include <stdexcept>

namespace bvhlab::python {

namespace fs = std::filesystem;

/// The typed tree behind a handle: every operation that needs the tree's type is a virtual here.
struct AnyTree::Model {
  virtual ~Model() = default;
  [[nodiscard]] virtual std::vector<std::byte> save_bytes(const std::string& source) const = 0;
  /// `self` is this model's own shared pointer: the prepared query keeps both trees alive.
  [[nodiscard]] virtual std::unique_ptr<PreparedQuery> prepare(std::shared_ptr<const Model> self,
                                                               std::shared_ptr<const Model> b,
                                                               const StrategyVariant& variant) const = 0;
  TreeInfo info;
};

namespace {

template <class BV, class D>
struct TypedBase;

/// Strategy S on two trees of one type, configured once; with kSurfaces, with the clouds' surface test at
/// the leaves (traversal/point_leaves.hpp), made per pose as query_exact_points and query_adb_points make it.
template <class S, class BV, class D, bool kSurfaces>
class TypedQuery final : public PreparedQuery {
 public:
  TypedQuery(std::shared_ptr<const TypedBase<BV, D>> a, std::shared_ptr<const TypedBase<BV, D>> b,
             typename S::Options options)
      : a_(std::move(a)), b_(std::move(b)), options_(std::move(options)) {}

  void run(std::span<const RigidTransform> poses, const ResultSink& sink) const override {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      if constexpr (kSurfaces) {
        const SurfaceLeaves<BV> leaves(a_->tree.bvh, a_->side(), b_->tree.bvh, b_->side(), poses[i]);
        sink(i, S::query(a_->tree, b_->tree, poses[i], options_, leaves));
      } else {
        sink(i, S::query(a_->tree, b_->tree, poses[i], options_));
      }
    }
  }

 private:
  std::shared_ptr<const TypedBase<BV, D>> a_, b_;
  typename S::Options options_;
};

/// A typed tree, of a mesh or of a point cloud (then with its surface): what a query needs of either.
template <class BV, class D>
struct TypedBase : AnyTree::Model {
  TypedBase(Tree<BV, D> built, const MeshUnits& units, double build_seconds, double annotate_seconds)
      : tree(std::move(built)) {
    ModelInfo size;  // the runner's and `bvhlab info`'s one account of a tree's size
    describe_tree_size(size, tree);
    info.bv = BV::name();
    info.density = D::name();
    info.annotation = D::describe(tree.density);
    info.triangles = tree.bvh.has_points() ? 0 : size.triangles;
    info.points = tree.bvh.point_ids().size();
    info.nodes = size.nodes;
    info.depth = size.depth;
    info.model_bytes = size.model_bytes;
    info.build_seconds = build_seconds;
    info.annotate_seconds = annotate_seconds;
    info.polygons = tree.bvh.has_polygons();
    info.units = units;
  }

  /// A mesh's side of a point query; a cloud's tree gives its surface.
  [[nodiscard]] virtual SurfaceSide side() const { return mesh_side(); }

  [[nodiscard]] std::unique_ptr<PreparedQuery> prepare(std::shared_ptr<const Model> self,
                                                       std::shared_ptr<const Model> b,
                                                       const StrategyVariant& variant) const override {
    auto other = std::dynamic_pointer_cast<const TypedBase>(b);
    if (!other)
      throw std::invalid_argument("the two trees differ in BV or density (" + info.bv + ", " +
                                  info.annotation + " vs " + b->info.bv + ", " + b->info.annotation + ")");
    auto a = std::static_pointer_cast<const TypedBase>(std::move(self));
    const bool points = side().is_cloud() || other->side().is_cloud();
    std::unique_ptr<PreparedQuery> out;
    with_strategy(variant.strategy, [&]<class S>(std::type_identity<S>) {
      if constexpr (S::template accepts<D>) {
        if constexpr (ProbabilityDensity<D>)  // refuses trees annotated with other parameters, before any
                                              // pose
          (void)D::estimator(tree.density, other->tree.density);
        auto options = strategy_options<S>(variant.values, variant.budget);
        if (points) {
          out = prepare_points<S>(std::move(a), std::move(other), std::move(options), variant.strategy);
          return;
        }
        if (S::needs_polygons && !(info.polygons && other->info.polygons))
          throw std::invalid_argument("strategy " + variant.strategy +
                                      " tests triangles, and a tree was loaded without polygons (load it "
                                      "with its mesh)");
        out =
            std::make_unique<TypedQuery<S, BV, D, false>>(std::move(a), std::move(other), std::move(options));
      } else {
        throw std::invalid_argument("strategy " + variant.strategy + " does not run on trees with density '" +
                                    std::string(D::name()) + "' (it runs on: " +
                                    registry_detail::joined(strategy_info(variant.strategy).densities) + ")");
      }
    });
    return out;
  }

  Tree<BV, D> tree;

 private:
  /// S with the surface test, after SurfaceLeaves' checks of the two sides (so running cannot fail).
  template <class S>
  static std::unique_ptr<PreparedQuery> prepare_points(std::shared_ptr<const TypedBase> a,
                                                       std::shared_ptr<const TypedBase> b,
                                                       typename S::Options options, const std::string& name) {
    (void)SurfaceLeaves<BV>(a->tree.bvh, a->side(), b->tree.bvh, b->side(), RigidTransform{});
    if (const std::string refusal = cloud_query_refusal<S, BV, D>(options, name); !refusal.empty())
      throw std::invalid_argument(refusal);
    if constexpr (takes_leaf_test<S, BV, D>)
      return std::make_unique<TypedQuery<S, BV, D, true>>(std::move(a), std::move(b), std::move(options));
    else
      throw std::logic_error("cloud_query_refusal let strategy " + name + " through without a leaf test");
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

/// The tree of a cloud: `D` is NoDensity or AdbDensity (counts from the points' areas).
template <class BV, class D>
std::shared_ptr<const AnyTree::Model> build_point_typed(const UnitCloud& cloud, const DensitySpec& density,
                                                        const BuildOptions& options) {
  double annotate_seconds = 0;
  const auto start = Clock::now();
  Tree<BV, D> tree = cloud_tree<BV, D>(cloud, density.values, options, annotate_seconds);
  const double seconds = seconds_since(start);
  return std::make_shared<PointModel<BV, D>>(cloud, std::move(tree), cloud.units, seconds - annotate_seconds,
                                             annotate_seconds);
}

template <class BV, class D>
std::shared_ptr<const AnyTree::Model> build_typed(const UnitMesh& mesh, const DensitySpec& density,
                                                  const BuildOptions& options) {
  Bvh<BV> bvh = Bvh<BV>::build(mesh, options);
  const double build_seconds = bvh.stats().build_seconds;
  AnnotationContext context;
  context.threads = options.threads;
  AnnotateStats stats;  // NoDensity annotates nothing: 0 seconds
  Tree<BV, D> tree = annotate_tree<D>(std::move(bvh), density_params<D>(density.values), context, &stats);
  return std::make_shared<TypedModel<BV, D>>(std::move(tree), mesh.units, build_seconds, stats.seconds);
}

/// The saved tree with `mesh`'s polygons, checked as the tree cache checks its entries.
template <class BV, class D>
Tree<BV, D> with_polygons(const Tree<BV, D>& saved, const Mesh& mesh, const fs::path& file) {
  try {
    return tree_cache_detail::attach_polygons(saved, mesh);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument("saved tree '" + file.string() + "' does not fit mesh '" + mesh.name +
                                "': " + e.what());
  }
}

/// Refuses a mesh in other units than the saved tree's: its polygons would not be where the tree's leaves
/// are.
void check_mesh_units(const MeshUnits& tree, const UnitMesh& mesh, const fs::path& file) {
  if (mesh.units == tree) return;
  throw std::invalid_argument("saved tree '" + file.string() + "' and mesh '" + mesh.name +
                              "' differ in units (tree: " + tree.describe() +
                              "; mesh: " + mesh.units.describe() +
                              "); give the mesh as the tree was built (load_mesh(normalize=...))");
}

/// The CLI's rule for a query: both trees normalised or neither, as one pose cannot be in both units.
void check_same_kind_of_units(const TreeInfo& a, const TreeInfo& b) {
  if (a.units.file.normalized == b.units.file.normalized) return;
  throw std::invalid_argument("the trees are in different units (a: " + a.units.describe() +
                              "; b: " + b.units.describe() + "); normalise both meshes or neither");
}

}  // namespace

std::string MeshUnits::describe() const {
  if (scaled_by == 1) return file.describe();
  char factor[32];
  std::snprintf(factor, sizeof factor, "%.6g", scaled_by);
  return file.describe() + ", then scaled by " + factor;
}

AnyTree AnyTree::build(const UnitMesh& mesh, const std::string& bv, const DensitySpec& density,
                       const BuildOptions& options) {
  std::shared_ptr<const Model> model;
  with_volume(bv, [&]<class BV>(std::type_identity<BV>) {
    with_density(density.name, [&]<class D>(std::type_identity<D>) {
      if constexpr (DensityFor<D, BV>)
        model = build_typed<BV, D>(mesh, density, options);
      else
        throw std::invalid_argument("density " + density.name + " cannot annotate " + bv + " trees");
    });
  });
  return AnyTree(std::move(model));
}

AnyTree AnyTree::build_points(const UnitCloud& cloud, const std::string& bv, const DensitySpec& density,
                              const BuildOptions& options) {
  std::shared_ptr<const Model> model;
  with_volume(bv, [&]<class BV>(std::type_identity<BV>) {
    with_cloud_density<BV>(density.name, bv,
                           [&]<class D>() { model = build_point_typed<BV, D>(cloud, density, options); });
  });
  return AnyTree(std::move(model));
}

AnyTree AnyTree::load(const fs::path& file, const UnitMesh* mesh) {
  const SavedTreeFile saved = read_saved_tree(file);
  const saved_tree_detail::Header& header = saved.header;
  const MeshUnits units{header.units, 1};
  if (mesh) check_mesh_units(units, *mesh, file);
  std::shared_ptr<const Model> model;
  with_volume(header.bv_name, [&]<class BV>(std::type_identity<BV>) {
    with_density(header.density_name, [&]<class D>(std::type_identity<D>) {
      if constexpr (DensityFor<D, BV>) {
        Tree<BV, D> tree = load_tree_from_buffer<BV, D>(saved.bytes, file.string());
        if (mesh) tree = with_polygons(tree, *mesh, file);
        model = std::make_shared<TypedModel<BV, D>>(std::move(tree), units, 0.0, 0.0);
      } else {
        throw SavedTreeError("saved tree '" + file.string() + "': density " + header.density_name +
                             " cannot annotate " + header.bv_name + " trees");
      }
    });
  });
  return AnyTree(std::move(model));
}

void AnyTree::save(const fs::path& file) const {
  const MeshUnits& units = model_->info.units;
  if (units.scaled_by != 1)
    throw std::invalid_argument("cannot save '" + file.string() + "': the tree's units (" + units.describe() +
                                ") include load_mesh's scale, and a saved tree records only the mesh file's "
                                "units or the normalisation; build it from a mesh loaded without scale=");
  saved_tree_detail::write_file_atomically(file, model_->save_bytes(file.string()));
}

const TreeInfo& AnyTree::info() const {
  return model_->info;
}

std::unique_ptr<PreparedQuery> AnyTree::prepare(const AnyTree& b, const StrategyVariant& variant) const {
  check_same_kind_of_units(info(), b.info());
  return model_->prepare(model_, b.model_, variant);
}

DensitySpec density_spec(const std::string& name, const ParamValues& given) {
  DensitySpec density;
  density.name = name;
  density.values = with_density(name, [&]<class D>(std::type_identity<D>) {
    (void)density_params<D>(given);  // the density's own checks of the combination
    return resolve_parameters(D::parameters(), given, D::name());
  });
  return density;
}

StrategyVariant strategy_variant(const std::string& name, const ParamValues& given, const Budget& budget) {
  StrategyVariant variant;
  variant.strategy = name;
  variant.values = resolve_parameters(strategy_info(name).parameters, given, name);
  variant.budget = budget;
  with_strategy(name,
                [&]<class S>(std::type_identity<S>) { (void)strategy_options<S>(variant.values, budget); });
  return variant;
}

}  // namespace bvhlab::python
