// libFuzzer target: the saved-tree reader (adb/saved_tree.hpp).
//
// Input: one selector byte, then the file. The selector's low 3 bits pick the (volume, annotation) the reader
// expects; bit 3 set keeps the file's checksum as it is, clear recomputes it first, so that mutations reach
// the structure checks behind the checksum instead of dying at it.
//
// A SavedTreeError naming the source is the expected way to refuse. Anything else -- another exception, a
// crash, a sanitizer report -- is a finding, and so is an accepted tree that does not save back to the same
// bytes, or whose ADB query misbehaves (a probability outside [0, 1], a budget overrun).
// The committed seeds are saved-tree format 3 (one of them normalised); the regress_* reproducers of format 1
// are now refused at the version field, and stay as reminders of what they once found.
//
// Seeds: run with BVHLAB_FUZZ_WRITE_SEEDS=<dir> to write one saved tree per layout there (and exit).
#include "adb/adb_density.hpp"
#include "adb/saved_tree.hpp"
#include "bench/core/generators.hpp"
#include "traversal/adb.hpp"
#include "volumes/aabb.hpp"
#include "volumes/dop24.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"
#include "volumes/sphere.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <vector>

namespace {

using namespace bvhlab;

constexpr std::size_t kChecksumOffset = kSavedTreeChecksumOffset;

void fix_checksum(std::vector<std::byte>& file) {
  const std::span<const std::byte> all(file);
  const std::uint64_t head = saved_tree_detail::fnv1a64(all.first(kChecksumOffset));
  std::uint64_t sum = saved_tree_detail::fnv1a64(all.subspan(kSavedTreeHeaderSize), head);
  for (std::size_t i = 0; i < 8; ++i, sum >>= 8)
    file[kChecksumOffset + i] = static_cast<std::byte>(sum & 0xff);
}

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_saved_tree: %s\n", what.c_str());
  std::abort();
}

template <class BV, class Density>
void load_and_check(std::span<const std::byte> file) {
  Tree<BV, Density> tree;
  try {
    tree = load_tree_from_buffer<BV, Density>(file, "fuzz.tree");
  } catch (const SavedTreeError& e) {
    if (std::string_view(e.what()).find("fuzz.tree") == std::string_view::npos)
      finding(std::string("refusal does not name the source: ") + e.what());
    return;
  }
  // Accepted: the tree must save back to the bytes it came from (name fields included: the reader refuses
  // anything but NULs after a name; units included: raw ones have a single encoding).
  const std::vector<std::byte> again = save_tree_to_buffer(
      tree, {.triangle_ids = !tree.bvh.triangle_ids().empty(), .units = saved_tree_units(file, "fuzz.tree")},
      "fuzz.tree");
  if (!std::equal(again.begin(), again.end(), file.begin(), file.end()))
    finding("an accepted tree does not save back to the same bytes");
  if constexpr (ProbabilityDensity<Density>) {
    // And it must survive a query against itself: ADB needs no polygons, and the model comes from the tree.
    AdbOptions options;
    options.p_min = 0.99;
    options.budget.max_bv_tests = 4096;
    RigidTransform pose;
    pose.rotation = Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Result r = query_adb(tree, tree, pose, options);
    if (!(r.probability >= 0 && r.probability <= 1)) finding("ADB probability outside [0, 1]");
    if (r.counters.bv_tests > options.budget.max_bv_tests) finding("ADB exceeded its BV-test budget");
  }
}

using Loader = void (*)(std::span<const std::byte>);
constexpr Loader kLayouts[8] = {
    load_and_check<Aabb, NoDensity>,          load_and_check<Aabb, AdbDensity>,
    load_and_check<RestrictedBox, NoDensity>, load_and_check<RestrictedBox, AdbDensity>,
    load_and_check<Obb, AdbDensity>,          load_and_check<Dop24, NoDensity>,
    load_and_check<Sphere, AdbDensity>,       load_and_check<Dop24, AdbDensity>,
};

// --- seeds -------------------------------------------------------------------------------------------------

Mesh seed_mesh() {  // a small torus: enough nodes for every check to matter, few bytes
  return generators::make_torus(0.7, 0.25, 6, 4);
}

/// grid 0: no density; else a stand-in ADB annotation (the reader checks only pc <= g^3).
template <class BV>
std::vector<std::byte> seed_tree(const Mesh& mesh, bool ids, int grid, const TreeUnits& units = {}) {
  Bvh<BV> bvh = Bvh<BV>::build(mesh, {.max_leaf_triangles = 2, .threads = 1});
  if (grid == 0)
    return save_tree_to_buffer(Tree<BV>{std::move(bvh), {}}, {.triangle_ids = ids, .units = units});
  std::vector<std::uint8_t> counts;
  for (std::size_t i = 0; i < bvh.nodes().size(); ++i)
    counts.push_back(static_cast<std::uint8_t>(i % (grid * grid * grid + 1)));
  const Tree<BV, AdbDensity> tree{std::move(bvh), AdbDensity::make_storage({grid, 0.5}, std::move(counts))};
  return save_tree_to_buffer(tree, {.triangle_ids = ids, .units = units});
}

void write_seeds(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const Mesh mesh = seed_mesh();
  const std::vector<std::pair<std::string, std::vector<std::byte>>> seeds = {
      {"aabb_plain", seed_tree<Aabb>(mesh, true, 0)},
      {"aabb_adb2_normalized",
       seed_tree<Aabb>(mesh, true, 2, {.normalized = true, .scale = 1.25, .centre = Vec3(0.5, -2, 3)})},
      {"rbox_plain", seed_tree<RestrictedBox>(mesh, true, 0)},
      {"rbox_adb2_no_ids", seed_tree<RestrictedBox>(mesh, false, 2)},
      {"obb_adb3", seed_tree<Obb>(mesh, true, 3)},
      {"dop24_plain", seed_tree<Dop24>(mesh, true, 0)},
      {"sphere_adb2_no_ids", seed_tree<Sphere>(mesh, false, 2)},
      {"dop24_adb4", seed_tree<Dop24>(mesh, true, 4)},
  };
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    std::ofstream out(dir / seeds[k].first, std::ios::binary);
    const char selector = static_cast<char>(k);
    out.write(&selector, 1);
    out.write(reinterpret_cast<const char*>(seeds[k].second.data()),
              static_cast<std::streamsize>(seeds[k].second.size()));
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  if (const char* dir = std::getenv("BVHLAB_FUZZ_WRITE_SEEDS")) {
    write_seeds(dir);
    std::exit(0);
  }
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t selector = data[0];
  std::vector<std::byte> file(size - 1);
  if (!file.empty()) std::memcpy(file.data(), data + 1, file.size());
  if (!(selector & 8) && file.size() >= kSavedTreeHeaderSize) fix_checksum(file);
  kLayouts[selector & 7](file);
  return 0;
}
