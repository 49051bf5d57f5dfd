// The "points" section of a scene: clouds sampled from each pair's meshes at several densities, B tumbling
// about A on the protocol (format: bench/scenes/README.md; the measuring: bench/points/points.hpp).
#include "bench/core/scene_json.hpp"

namespace bvhlab::scene_json {

namespace {

/// The fewest points a cloud may have: the surface's kernel radius is each point's 10th neighbour distance
/// (PointSurfaceOptions::k), so a cloud needs 11.
constexpr long long kMinPoints = 11;
constexpr long long kMaxPoints = 10'000'000;

std::vector<double> densities(const Node& node) {
  std::vector<double> out;
  for (std::size_t k = 0, n = node.array_size(); k < n; ++k) {
    const long long count = node.child(k).integer(1, kMaxPoints);
    if (count < kMinPoints)
      node.child(k).fail("a cloud needs at least " + std::to_string(kMinPoints) +
                         " points (the surface's kernel radius is each point's 10th neighbour distance); " +
                         node.child(k).got());
    out.push_back(static_cast<double>(count));
  }
  return out;
}

std::vector<double> p_mins(const Node& node) {
  std::vector<double> out;
  for (std::size_t k = 0, n = node.array_size(true); k < n; ++k) {
    const double p = node.child(k).number(0, 1);
    if (!(p > 0)) node.child(k).fail("expected a p_min in (0, 1]; " + node.child(k).got());
    out.push_back(p);
  }
  return out;
}

std::vector<double> whole_numbers(const Node& node, long long lo, long long hi) {
  std::vector<double> out;
  for (std::size_t k = 0, n = node.array_size(true); k < n; ++k)
    out.push_back(static_cast<double>(node.child(k).integer(lo, hi)));
  return out;
}

std::vector<double> octree_resolutions(const Node& node, bool fcl) {
  if (!fcl) node.fail("FCL's octree needs a build with FCL (configure with -DBVHLAB_WITH_FCL=ON)");
  std::vector<double> out;
  for (std::size_t k = 0, n = node.array_size(true); k < n; ++k) {
    const double r = node.child(k).number(0, 1000);
    if (!(r > 0))
      node.child(k).fail("expected a voxel side in (0, 1000] point spacings; " + node.child(k).got());
    out.push_back(r);
  }
  return out;
}

void parse_sampling(const Node& p, PointsSpec& points) {
  if (p.has("sampling")) points.varying = p.child("sampling").choice({"uniform", "varying"}) == "varying";
  if (!p.has("ratio")) return;
  if (!points.varying) p.child("ratio").fail("applies to \"sampling\": \"varying\" only");
  points.ratio = p.child("ratio").number(1, 1000);
}

}  // namespace

void parse_points(const Node& root, Scene& scene, bool fcl) {
  const Node p = root.child("points");
  p.expect_object({"densities", "seed", "sampling", "ratio", "distances", "steps", "band", "leaf", "grid",
                   "p_min", "confirm_levels", "confirm_p_min", "bv_tests", "octree_res", "cgal_sample"});
  PointsSpec points;
  if (p.has("densities")) points.densities = densities(p.child("densities"));
  if (p.has("seed")) points.seed = static_cast<std::uint64_t>(p.child("seed").integer(0, 1LL << 53));
  parse_sampling(p, points);
  if (p.has("distances")) {
    const Node d = p.child("distances");
    (void)d.array_size();  // refuses an empty list
    points.distances = d.numbers(0, limits::kDistance.min, limits::kDistance.max);
  }
  if (p.has("steps"))
    points.steps = static_cast<int>(p.child("steps").integer(static_cast<long long>(limits::kSteps.min),
                                                             static_cast<long long>(limits::kSteps.max)));
  check_pose_count(
      p, double(points.distances.size()) * points.steps,
      std::to_string(points.distances.size()) + " distances of " + std::to_string(points.steps) + " steps");
  if (p.has("band")) points.band = p.child("band").number(0, 100);
  if (p.has("leaf")) points.leaf = static_cast<std::uint32_t>(p.child("leaf").integer(1, 255));
  if (p.has("grid")) points.grid = static_cast<int>(p.child("grid").integer(2, 4));
  if (p.has("p_min")) points.p_mins = p_mins(p.child("p_min"));
  if (p.has("confirm_levels")) points.confirm_levels = whole_numbers(p.child("confirm_levels"), 1, 255);
  if (p.has("confirm_p_min")) {
    if (!p.has("confirm_levels")) p.child("confirm_p_min").fail("applies with \"confirm_levels\" only");
    points.confirm_p_mins = p_mins(p.child("confirm_p_min"));
  }
  if (p.has("bv_tests")) points.bv_tests = whole_numbers(p.child("bv_tests"), 1, 1'000'000'000);
  if (p.has("octree_res"))
    points.octree_res = octree_resolutions(p.child("octree_res"), fcl);
  else if (fcl)
    points.octree_res = {1, 2};
  else
    scene.notes.push_back("FCL's octree series left out: this build has no FCL (BVHLAB_WITH_FCL=OFF)");
  if (p.has("cgal_sample"))
    points.cgal_sample = static_cast<int>(p.child("cgal_sample").integer(0, 1'000'000));
  scene.points = std::move(points);
}

}  // namespace bvhlab::scene_json
