#include "bench/cloud_query.hpp"

#include "bench/core/registry.hpp"
#include "bench/measure.hpp"
#include "bench/prepare.hpp"
#include "bvh/mesh_io.hpp"
#include "traversal/strategies.hpp"

#include <memory>
#include <optional>

namespace bvhlab {

namespace {

/// One side's tree, with its surface and coverings when it is a cloud.
template <TreeVolume BV, class D>
struct Side {
  Side(const QueryObject& object, const DensitySpec& density) {
    model.object = object.file.filename().string();
    model.bv = model.hierarchy = BV::name();
    const auto start = Clock::now();
    if (object.cloud) {
      PointCloud cloud = load_point_cloud(object.file);
      if constexpr (!std::is_same_v<D, NoDensity>) assign_knn_areas(cloud, 10);
      tree = cloud_tree<BV, D>(cloud, density.values, BuildOptions{}, model.annotate_seconds);
      surface.emplace(cloud);
      coverings = sphere_coverings(tree.bvh, *surface);
    } else {
      tree = annotate_tree<D>(Bvh<BV>::build(load_mesh(object.file).mesh, BuildOptions{}),
                              density_params<D>(density.values));
    }
    model.build_seconds = seconds_since(start);
    describe_tree_size(model, tree);
    model.annotation = D::describe(tree.density);
  }
  [[nodiscard]] SurfaceSide side() const { return surface ? cloud_side(*surface, coverings) : mesh_side(); }

  Tree<BV, D> tree;
  std::optional<PointSurface> surface;
  std::vector<SphereCovering> coverings;
  ModelInfo model;
};

template <TreeVolume BV, class D>
void run_on(const QueryObject& a, const QueryObject& b, const DensitySpec& density,
            const StrategyVariant& strategy, std::span<const RigidTransform> poses, int repeat,
            QueryOutcome& outcome) {
  const Side<BV, D> side_a(a, density), side_b(b, density);
  with_strategy(strategy.strategy, [&]<class S>(std::type_identity<S>) {
    if constexpr (!S::template accepts<D>) {
      throw std::invalid_argument("strategy " + strategy.strategy + " does not run on trees with density '" +
                                  std::string(D::name()) + "'");
    } else {
      const auto options = strategy_options<S>(strategy.values, strategy.budget);
      // SurfaceLeaves checks the two sides once here, so the timed queries cannot fail on them.
      (void)SurfaceLeaves<BV>(side_a.tree.bvh, side_a.side(), side_b.tree.bvh, side_b.side(),
                              RigidTransform{});
      if (const std::string refusal = cloud_query_refusal<S, BV, D>(options, strategy.strategy);
          !refusal.empty())
        throw std::invalid_argument(refusal);
      if constexpr (takes_leaf_test<S, BV, D>) {
        const auto query = [&](const RigidTransform& pose) {
          const SurfaceLeaves<BV> leaves(side_a.tree.bvh, side_a.side(), side_b.tree.bvh, side_b.side(),
                                         pose);
          return S::query(side_a.tree, side_b.tree, pose, options, leaves);
        };
        const double overhead = repeat > 0 ? clock_overhead_us() : 0;
        outcome.answers =
            answer_poses(poses, repeat, overhead, query,
                         [&](std::span<const RigidTransform> all, std::vector<QueryRecord>& records) {
                           timed_series(all, 0, records, query);
                         });
      } else {
        throw std::logic_error("cloud_query_refusal let strategy " + strategy.strategy +
                               " through without a leaf test");
      }
    }
  });
  outcome.model_a = side_a.model;
  outcome.model_b = side_b.model;
}

}  // namespace

QueryOutcome run_cloud_query(const QueryObject& a, const QueryObject& b, const std::string& bv,
                             const DensitySpec& density, const StrategyVariant& strategy,
                             std::span<const RigidTransform> poses, int repeat) {
  if (poses.empty()) throw std::invalid_argument("query: no pose given");
  if (!a.cloud && !b.cloud) throw std::invalid_argument("a point-cloud query needs a cloud on one side");
  QueryOutcome outcome;
  with_volume(bv, [&]<class BV>(std::type_identity<BV>) {
    with_cloud_density<BV>(
        density.name, bv, [&]<class D>() { run_on<BV, D>(a, b, density, strategy, poses, repeat, outcome); });
  });
  return outcome;
}

}  // namespace bvhlab
