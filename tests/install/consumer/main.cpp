// Builds two trees over a generated mesh and runs an exact and an ADB query through the installed headers.
#include <bvhlab/adb/adb_density.hpp>
#include <bvhlab/traversal/strategies.hpp>
#include <bvhlab/volumes/aabb.hpp>

#include <cstdio>

int main() {
  using namespace bvhlab;
  Mesh mesh;
  for (int i = 0; i < 64; ++i) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    const double x = i * 0.1;
    mesh.vertices.emplace_back(x, 0, 0);
    mesh.vertices.emplace_back(x + 0.1, 0, 0);
    mesh.vertices.emplace_back(x, 0.1, 0.05);
    mesh.triangles.push_back({base, base + 1, base + 2});
  }
  const auto tree = Bvh<Aabb>::build(mesh);
  const Result touching = query_exact(tree, tree, RigidTransform::translate(Vec3(0.05, 0, 0)));
  const Result apart = query_exact(tree, tree, RigidTransform::translate(Vec3(0, 5, 0)));
  // The ADB strategy through its policy: parameters checked against its table, the model from the trees.
  const auto annotated = annotate_adb(Bvh<Aabb>::build(mesh));
  const auto options = strategy_options<AdbStrategy>({{"p_min", 0.9}});
  const Result adb = AdbStrategy::query(annotated, annotated, RigidTransform::identity(), options);
  std::printf("exact: %d %d, adb: %d (p = %.3f)\n", touching.collides, apart.collides, adb.collides,
              adb.probability);
  return touching.collides && !apart.collides && adb.collides ? 0 : 1;
}
