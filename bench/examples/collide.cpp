// bvhlab as a library: two meshes in their own units, one pose, an exact and an ADB query, every field of
// the answer printed. Built with the project (target example_collide) and run by ctest.
//
//   build/release/bench/examples/example_collide MESH_A MESH_B TX TY TZ [P_MIN]
//
// B is moved by the translation (TX, TY, TZ) into A's frame; P_MIN (default 0.9) is ADB's stopping rule.
// Written against the installed package (cmake --install; find_package(bvhlab)): the headers take the
// bvhlab/ prefix. The build offers the same spelling, so this file compiles unchanged in both.
#include <bvhlab/adb/adb_density.hpp>
#include <bvhlab/bvh/mesh_io.hpp>
#include <bvhlab/traversal/strategies.hpp>
#include <bvhlab/volumes/aabb.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <stdexcept>
#include <string>

namespace {

using namespace bvhlab;

void print(const char* title, const Result& r) {
  std::printf("%s\n  collides %s, probability %.3f, exact %s, budget exhausted %s\n", title,
              r.collides ? "yes" : "no", r.probability, r.exact ? "yes" : "no",
              r.budget_exhausted ? "yes" : "no");
  if (r.witness)
    std::printf("  witness: triangle %u of A and %u of B intersect\n", r.witness->a, r.witness->b);
  std::printf("  work: %llu BV tests, %llu triangle tests, %llu node pairs, %llu estimates\n",
              static_cast<unsigned long long>(r.counters.bv_tests),
              static_cast<unsigned long long>(r.counters.triangle_tests),
              static_cast<unsigned long long>(r.counters.nodes_visited),
              static_cast<unsigned long long>(r.counters.probability_evaluations));
}

double number(const char* text, const char* what) {
  char* end = nullptr;
  const double value = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(value))
    throw std::invalid_argument(std::string(what) + ": '" + text + "' is not a finite number");
  return value;
}

int run(int argc, char** argv) {
  const Mesh a = load_mesh(argv[1]).mesh;  // throws MeshError naming the file and the problem
  const Mesh b = load_mesh(argv[2]).mesh;
  const Vec3 translation(number(argv[3], "TX"), number(argv[4], "TY"), number(argv[5], "TZ"));
  const RigidTransform pose = RigidTransform::translate(translation);
  // ADB's options, checked against the strategy's parameter table before any work.
  const auto options = strategy_options<AdbStrategy>({{"p_min", argc > 6 ? number(argv[6], "P_MIN") : 0.9}});

  // Exact: a hierarchy of AABBs over each mesh; the answer agrees with exact-predicate ground truth.
  const auto tree_a = Bvh<Aabb>::build(a), tree_b = Bvh<Aabb>::build(b);
  print("exact", query_exact(tree_a, tree_b, pose));

  // ADB: the same hierarchies annotated with grid cell counts (grid 2); the answer is a probability.
  const auto adb_a = annotate_adb(Bvh<Aabb>::build(a)), adb_b = annotate_adb(Bvh<Aabb>::build(b));
  print("adb", AdbStrategy::query(adb_a, adb_b, pose, options));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: %s MESH_A MESH_B TX TY TZ [P_MIN]\n", argv[0]);
    return 2;
  }
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "example_collide: %s\n", e.what());
    return 1;
  }
}
