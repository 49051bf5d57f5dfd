#include "bench/cloud_query.hpp"

#include "bench/pairs/measure.hpp"
#include "bench/pairs/prepare.hpp"
#include "bvh/mesh_io.hpp"
#include "engine/any_tree.hpp"

namespace bvhlab {

namespace {

/// One side's tree: a cloud's (with k-NN areas when it is annotated, as files carry none) or a mesh's.
AnyTree side_tree(const QueryObject& object, const std::string& bv, const DensitySpec& density) {
  if (!object.cloud) {
    check_cloud_density(density.name);  // before the mesh's tree is built
    return AnyTree::build(load_mesh(object.file).mesh, MeshUnits{}, bv, density, BuildOptions{});
  }
  UnitCloud cloud;
  static_cast<PointCloud&>(cloud) = load_point_cloud(object.file);
  if (density.name != "none") assign_knn_areas(cloud, 10);
  return AnyTree::build_points(cloud, bv, density, BuildOptions{});
}

ModelInfo describe_side(const AnyTree& tree, const QueryObject& object, double seconds) {
  ModelInfo model;
  describe_tree(model, tree.info());
  model.object = object.file.filename().string();
  model.hierarchy = tree.info().bv;
  model.build_seconds = seconds - tree.info().annotate_seconds;
  return model;
}

}  // namespace

QueryOutcome run_cloud_query(const QueryObject& a, const QueryObject& b, const std::string& bv,
                             const DensitySpec& density, const StrategyVariant& strategy,
                             std::span<const RigidTransform> poses, int repeat) {
  if (poses.empty()) throw std::invalid_argument("query: no pose given");
  if (!a.cloud && !b.cloud) throw std::invalid_argument("a point-cloud query needs a cloud on one side");
  QueryOutcome outcome;
  auto start = Clock::now();
  const AnyTree tree_a = side_tree(a, bv, density);
  outcome.model_a = describe_side(tree_a, a, seconds_since(start));
  start = Clock::now();
  const AnyTree tree_b = side_tree(b, bv, density);
  outcome.model_b = describe_side(tree_b, b, seconds_since(start));
  outcome.answers = answer_prepared(*tree_a.prepare(tree_b, strategy), poses, repeat);
  return outcome;
}

}  // namespace bvhlab
