// Shared pieces of the robustness suite: small exact meshes, frame changes, annotation, and every strategy.
#pragma once

#include "adb/adb_density.hpp"
#include "adb/tree.hpp"
#include "bvh/bvh.hpp"
#include "engine/protocol.hpp"
#include "traversal/adb.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"
#include "volumes/shipped.hpp"

#include <gtest/gtest.h>

#include <array>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

namespace bvhlab::robust {

/// The cube [-h, h]^3 as 12 triangles over 8 shared corners (every coordinate exactly representable).
inline Mesh make_cube(double h = 1.0) {
  Mesh m;
  m.name = "cube";
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  const std::array<std::array<std::uint32_t, 4>, 6> faces = {
      {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

/// x -> scale * x + offset applied to every vertex: the same object described in another frame.
inline Mesh reframe(Mesh m, double scale, const Vec3& offset) {
  for (auto& v : m.vertices) v = scale * v + offset;
  return m;
}

/// The pose that places reframed B against reframed A exactly as `pose` placed B against A:
/// F pose F^-1 with F(x) = scale x + offset, i.e. rotation R and translation scale t + offset - R offset.
inline RigidTransform reframe(const RigidTransform& pose, double scale, const Vec3& offset) {
  return {pose.rotation, scale * pose.translation + offset - pose.rotation * offset};
}

/// The triangles of `m` moved by `pose` (for checks against CGAL outside a tree).
inline Mesh moved(Mesh m, const RigidTransform& pose) {
  for (auto& v : m.vertices) v = pose.apply(v);
  return m;
}

/// A pose of the tumbling protocol and the distance it was drawn at.
struct Query {
  double distance;
  RigidTransform pose;
};

/// `steps` protocol poses at each distance (the protocol's own distances when none are given).
inline std::vector<Query> protocol_queries(int steps, std::vector<double> distances = {}) {
  if (distances.empty()) distances = ProtocolOptions{}.distances;
  std::vector<Query> out;
  for (double d : distances)
    for (int k = 0; k < steps; ++k) out.push_back({d, protocol_pose(d, k, steps)});
  return out;
}

constexpr int kGrid = 2;

/// pc = min(g^3, triangles below the node): a stand-in annotation for tests whose point is not the counts.
template <class BV>
Tree<BV, AdbDensity> with_stand_in_annotation(Bvh<BV> bvh) {
  std::vector<std::uint8_t> counts;
  for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
    counts.push_back(static_cast<std::uint8_t>(std::min<std::uint32_t>(kGrid * kGrid * kGrid, end - begin)));
  return {std::move(bvh), AdbDensity::make_storage({kGrid, kDefaultAdbTau}, std::move(counts))};
}
template <class BV>
using Annotated = Tree<BV, AdbDensity>;

/// The real ADB annotation (adb/annotate.hpp), single-threaded so the tests stay deterministic in cost.
/// Where annotate does not (yet) accept a volume model, a crude stand-in keeps the traversal tests running:
/// pc = min(g^3, triangles below the node) -- the ADB answers then differ, but every promise checked here
/// (honest exactness, probabilities in [0, 1], termination) must hold for any annotation.
template <class BV>
Annotated<BV> annotated(const Mesh& mesh, const BuildOptions& build = {}) {
  AnnotateOptions options;
  options.threads = 1;
  if constexpr (requires { annotate_adb(Bvh<BV>::build(mesh, build), kGrid, options); }) {
    return annotate_adb(Bvh<BV>::build(mesh, build), kGrid, options);
  } else {
    return with_stand_in_annotation(Bvh<BV>::build(mesh, build));
  }
}

/// The model every annotated tree of the suite shares: grid 2, the default tau.
inline const AdbModel& shared_model() {
  return *shared_adb_model(kGrid, kDefaultAdbTau);
}

/// Every strategy the library offers, by name, so a test can run all of them on one pose.
enum class Strategy { ExactFirst, ExactAll, AdbPmin, AdbBudget, GuidedExact };
inline constexpr std::array<Strategy, 5> kAllStrategies = {
    Strategy::ExactFirst, Strategy::ExactAll, Strategy::AdbPmin, Strategy::AdbBudget, Strategy::GuidedExact};
inline std::string to_string(Strategy s) {
  switch (s) {
    case Strategy::ExactFirst:
      return "exact-first";
    case Strategy::ExactAll:
      return "exact-all";
    case Strategy::AdbPmin:
      return "adb-pmin";
    case Strategy::AdbBudget:
      return "adb-budget";
    case Strategy::GuidedExact:
      return "guided-exact";
  }
  return "?";
}
inline bool is_exact(Strategy s) {
  return s == Strategy::ExactFirst || s == Strategy::ExactAll || s == Strategy::GuidedExact;
}

/// Runs one strategy. The ADB variants use p_min = 0.9; the budget variant caps BV tests only (a deadline
/// would make answers depend on timing).
template <class BV>
Result run(Strategy s, const Annotated<BV>& a, const Annotated<BV>& b, const RigidTransform& pose,
           double p_min = 0.9, std::uint64_t max_bv_tests = 64) {
  AdbOptions options;
  options.p_min = p_min;
  switch (s) {
    case Strategy::ExactFirst:
      return query_exact(a.bvh, b.bvh, pose, ContactMode::First);
    case Strategy::ExactAll:
      return query_exact(a.bvh, b.bvh, pose, ContactMode::All);
    case Strategy::AdbPmin:
      return query_adb(a, b, pose, options);
    case Strategy::AdbBudget:
      options.budget.max_bv_tests = max_bv_tests;
      return query_adb(a, b, pose, options);
    case Strategy::GuidedExact:
      options.exact_leaves = true;
      return query_adb(a, b, pose, options);
  }
  throw std::logic_error("unknown strategy");
}

// Compiled once, in robust_support.cpp, for every shipped volume: each test file of the suite only calls
// them (instantiating the five strategies and the annotation per volume in every file cost minutes of CI).
// The sanitizer builds (BVHLAB_LEAN_VOLUMES) compile only the lean registry's volumes there, the ones their
// tests of this suite use (the file compiled under ASan in 20 s instead of 30 s, side by side); a file that
// uses another volume in such a build instantiates it itself.
#define BVHLAB_ROBUST_INSTANTIATIONS(PREFIX, BV)                                       \
  PREFIX template Result run<BV>(Strategy, const Annotated<BV>&, const Annotated<BV>&, \
                                 const RigidTransform&, double, std::uint64_t);        \
  PREFIX template Annotated<BV> annotated<BV>(const Mesh&, const BuildOptions&);
#ifdef BVHLAB_LEAN_VOLUMES
#define BVHLAB_ROBUST_FOR_EACH_VOLUME(X) X(Aabb) X(Dop24) X(Obb) X(Sphere) X(RestrictedBox)
// Explicit instantiations need the names, so the lean list is spelled out here: it must stay the one in
// volumes/shipped.hpp.
template <class List>
struct RobustWithVoidFirst;
template <class... BV>
struct RobustWithVoidFirst<TypeList<BV...>> {
  using type = TypeList<void, BV...>;
};
#define BVHLAB_ROBUST_LIST_ITEM(BV) , BV
static_assert(std::is_same_v<TypeList<void BVHLAB_ROBUST_FOR_EACH_VOLUME(BVHLAB_ROBUST_LIST_ITEM)>,
                             RobustWithVoidFirst<LeanVolumes>::type>,
              "BVHLAB_ROBUST_FOR_EACH_VOLUME must list LeanVolumes (volumes/shipped.hpp)");
#undef BVHLAB_ROBUST_LIST_ITEM
#else
#define BVHLAB_ROBUST_FOR_EACH_VOLUME(X) \
  X(Aabb) X(Dop<6>) X(Dop<14>) X(Dop<18>) X(Dop24) X(Dop<26>) X(Obb) X(Sphere) X(RestrictedBox)
#endif
#define BVHLAB_ROBUST_EXTERN(BV) BVHLAB_ROBUST_INSTANTIATIONS(extern, BV)
BVHLAB_ROBUST_FOR_EACH_VOLUME(BVHLAB_ROBUST_EXTERN)
#undef BVHLAB_ROBUST_EXTERN

/// The one promise every strategy keeps: an answer marked exact is right, probabilities are probabilities.
inline ::testing::AssertionResult honest(const Result& r, bool truth) {
  if (!(r.probability >= 0 && r.probability <= 1))
    return ::testing::AssertionFailure() << "probability " << r.probability << " outside [0, 1]";
  if (r.exact && r.collides != truth)
    return ::testing::AssertionFailure() << "claims an exact " << (r.collides ? "collision" : "no collision")
                                         << " but the truth is " << (truth ? "collision" : "no collision");
  return ::testing::AssertionSuccess();
}

}  // namespace bvhlab::robust
