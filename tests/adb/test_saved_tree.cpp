// Saved trees: round trips for plain, annotated and hierarchical trees, and every corruption the reader must
// refuse (with a message naming it) instead of crashing or returning a wrong tree.
#include "adb/saved_tree.hpp"

#include "adb/adb_density.hpp"
#include "support/generated_meshes.hpp"
#include "support/volume_lists.hpp"
#include "volumes/aabb.hpp"
#include "volumes/dop24.hpp"
#include "volumes/kdop.hpp"
#include "volumes/obb.hpp"
#include "volumes/restricted_box.hpp"
#include "volumes/sphere.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>

#include <unistd.h>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

namespace bvhlab {
namespace {

using Bytes = std::vector<std::byte>;

const Tree<Aabb, AdbDensity>& annotated_torus() {
  static const Tree<Aabb, AdbDensity> tree = [] {
    AnnotateOptions options;
    options.threads = 1;
    return annotate_adb(Bvh<Aabb>::build(testing::make_torus(1.0, 0.3, 12, 6)), 2, options);
  }();
  return tree;
}

template <class BV>
bool same_volume_bytes(const std::vector<BV>& a, const std::vector<BV>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(BV)) == 0;
}

bool same_nodes(const std::vector<TreeNode>& a, const std::vector<TreeNode>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(TreeNode)) == 0;
}

/// Runs `load` and checks that it throws SavedTreeError whose message contains `fragment`.
template <class F>
void expect_rejected(F&& load, const std::string& fragment) {
  try {
    load();
    ADD_FAILURE() << "accepted; expected an error mentioning '" << fragment << "'";
  } catch (const SavedTreeError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

Tree<Aabb, AdbDensity> load_adb(const Bytes& bytes) {
  return load_tree_from_buffer<Aabb, AdbDensity>(bytes, "test.tree");
}

// Header fields, to craft bad files (offsets from the format table in adb/saved_tree.hpp).
void put_u32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = std::byte((v >> (8 * i)) & 0xff);
}
void put_u64(Bytes& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b[at + i] = std::byte((v >> (8 * i)) & 0xff);
}
/// Re-seals a crafted file so that only the structure checks can catch it.
void reseal(Bytes& b) {
  const std::uint64_t head =
      saved_tree_detail::fnv1a64(std::span<const std::byte>(b).first(kSavedTreeChecksumOffset));
  put_u64(b, kSavedTreeChecksumOffset,
          saved_tree_detail::fnv1a64(std::span<const std::byte>(b).subspan(kSavedTreeHeaderSize), head));
}
std::size_t nodes_offset() {
  return kSavedTreeHeaderSize;
}  // Aabb: no root volume before the nodes

TEST(SavedTree, AnnotatedAabbTreeRoundTrips) {
  const auto& tree = annotated_torus();
  const Bytes bytes = save_tree_to_buffer(tree);
  const auto loaded = load_adb(bytes);
  EXPECT_TRUE(same_nodes(loaded.bvh.nodes(), tree.bvh.nodes()));
  EXPECT_TRUE(same_volume_bytes(loaded.bvh.volumes(), tree.bvh.volumes()));
  EXPECT_EQ(loaded.bvh.triangle_ids(), tree.bvh.triangle_ids());
  EXPECT_EQ(loaded.density.possible_collision_cells, tree.density.possible_collision_cells);
  EXPECT_EQ(loaded.density.params, tree.density.params);
  EXPECT_EQ(loaded.density.model, tree.density.model);  // one shared model per (grid, tau)
  EXPECT_FALSE(loaded.bvh.has_polygons());
  EXPECT_EQ(loaded.bvh.stats().leaves, tree.bvh.stats().leaves);
  EXPECT_EQ(loaded.bvh.stats().depth, tree.bvh.stats().depth);
  // Saving the loaded tree gives the same bytes.
  EXPECT_EQ(save_tree_to_buffer(loaded), bytes);
}

TEST(SavedTree, TriangleIdsCanBeLeftOut) {
  const auto& tree = annotated_torus();
  const Bytes with = save_tree_to_buffer(tree);
  const Bytes without = save_tree_to_buffer(tree, SaveOptions{.triangle_ids = false});
  EXPECT_EQ(with.size() - without.size(), 4 * tree.bvh.triangle_ids().size());
  const auto loaded = load_adb(without);
  EXPECT_TRUE(loaded.bvh.triangle_ids().empty());
  EXPECT_TRUE(same_nodes(loaded.bvh.nodes(), tree.bvh.nodes()));
  EXPECT_EQ(loaded.density.possible_collision_cells, tree.density.possible_collision_cells);
}

// Version 3 records the tree's units: the mesh file's own, or the protocol normalisation with its scale and
// centre, read back exactly.
TEST(SavedTree, UnitsRoundTrip) {
  const auto& tree = annotated_torus();
  const Bytes raw = save_tree_to_buffer(tree);
  EXPECT_EQ(saved_tree_units(raw), TreeUnits{});
  const TreeUnits normalized{.normalized = true, .scale = 0.0123, .centre = Vec3(1.5, -2, 1e-300)};
  const Bytes bytes = save_tree_to_buffer(tree, {.units = normalized});
  EXPECT_EQ(saved_tree_units(bytes, "n.tree"), normalized);
  EXPECT_EQ(saved_tree_detail::read_header(bytes, "n.tree").units, normalized);
  EXPECT_EQ(save_tree_to_buffer(load_adb(bytes), {.units = normalized}), bytes);
  EXPECT_NE(bytes, raw);  // the units are part of the file, not only of the caller's memory
  EXPECT_EQ(normalized.describe(), "normalised: scale 0.0123, centre (1.5, -2, 1e-300)");
  EXPECT_EQ(TreeUnits{}.describe(), "the mesh file's units");
}

TEST(SavedTree, UnitsThatCannotBeRecordedAreRefused) {
  const auto& tree = annotated_torus();
  for (const TreeUnits& units :
       {TreeUnits{.normalized = false, .scale = 2}, TreeUnits{.normalized = false, .centre = Vec3(0, 1, 0)},
        TreeUnits{.normalized = false, .centre = Vec3(-0.0, 0, 0)}, TreeUnits{.normalized = true, .scale = 0},
        TreeUnits{.normalized = true, .scale = -1},
        TreeUnits{.normalized = true, .scale = std::numeric_limits<double>::infinity()},
        TreeUnits{.normalized = true, .centre = Vec3(std::nan(""), 0, 0)}})
    expect_rejected([&] { (void)save_tree_to_buffer(tree, {.units = units}, "u.tree"); }, "u.tree");
  // And in a file, behind a valid checksum: a raw tree with a scale, a normalised one with a zero scale.
  const Bytes bytes = save_tree_to_buffer(tree);
  Bytes bad = bytes;
  put_u64(bad, 120, std::bit_cast<std::uint64_t>(2.0));
  reseal(bad);
  expect_rejected([&] { load_adb(bad); },
                  "corrupted header (units not normalised but with a scale or centre)");
  bad = bytes;
  put_u32(bad, 20, 1 | 2);  // flags: triangle ids, normalised
  put_u64(bad, 120, std::bit_cast<std::uint64_t>(0.0));
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "scale that is not finite and positive");
  bad = bytes;
  put_u32(bad, 20, 1 | 4);  // an unknown flag
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "unknown flags 5");
}

TEST(SavedTree, PlainAndHierarchicalTreesRoundTrip) {
  const Mesh mesh = testing::make_torus(1.0, 0.3, 10, 5);
  {
    const Tree<Obb> tree{Bvh<Obb>::build(mesh), {}};
    const auto loaded = load_tree_from_buffer<Obb>(save_tree_to_buffer(tree));
    EXPECT_TRUE(same_nodes(loaded.bvh.nodes(), tree.bvh.nodes()));
    EXPECT_TRUE(same_volume_bytes(loaded.bvh.volumes(), tree.bvh.volumes()));
  }
  {
    // Stored relative to the parent: the root volume travels in the file, and decoding gives the same boxes.
    const Tree<RestrictedBox, AdbDensity> tree = annotate_adb(Bvh<RestrictedBox>::build(mesh), 2);
    const auto loaded = load_tree_from_buffer<RestrictedBox, AdbDensity>(save_tree_to_buffer(tree));
    EXPECT_TRUE(same_volume_bytes(loaded.bvh.volumes(), tree.bvh.volumes()));
    const auto a = loaded.bvh.node_boxes(), b = tree.bvh.node_boxes();
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].min, b[i].min);
      EXPECT_EQ(a[i].max, b[i].max);
    }
    EXPECT_EQ(loaded.density.possible_collision_cells, tree.density.possible_collision_cells);
  }
}

class SavedTreeFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("bvhlab_saved_tree_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  [[nodiscard]] std::size_t files_in_dir() const {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir_), {}));
  }
  std::filesystem::path dir_;
};

TEST_F(SavedTreeFiles, FileRoundTripLeavesNoTemporaryFiles) {
  const auto& tree = annotated_torus();
  const auto file = dir_ / "torus.tree";
  save_tree(tree, file);
  EXPECT_EQ(files_in_dir(), 1u);
  const auto loaded = load_tree<Aabb, AdbDensity>(file);
  EXPECT_EQ(loaded.density.possible_collision_cells, tree.density.possible_collision_cells);
  EXPECT_TRUE(same_volume_bytes(loaded.bvh.volumes(), tree.bvh.volumes()));
  save_tree(tree, file);  // overwrite in place
  EXPECT_EQ(files_in_dir(), 1u);
}

TEST_F(SavedTreeFiles, MissingFileIsNamed) {
  const auto file = dir_ / "absent.tree";
  expect_rejected([&] { load_tree<Aabb, AdbDensity>(file); }, file.string());
}

TEST_F(SavedTreeFiles, FailedWriteLeavesNothingBehind) {
  const auto& tree = annotated_torus();
  // The target is an existing non-empty directory: the rename fails after the data was written.
  const auto target = dir_ / "occupied";
  std::filesystem::create_directories(target / "inside");
  expect_rejected([&] { save_tree(tree, target); }, target.string());
  EXPECT_EQ(files_in_dir(), 1u);  // only the directory itself
  // A directory that does not exist: nothing can be created.
  expect_rejected([&] { save_tree(tree, dir_ / "no" / "such" / "dir.tree"); }, "temporary file");
  EXPECT_EQ(files_in_dir(), 1u);
}

TEST(SavedTree, RejectsEveryTruncation) {
  const Bytes bytes = save_tree_to_buffer(annotated_torus());
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    const Bytes prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length));
    EXPECT_THROW(load_adb(prefix), SavedTreeError) << "prefix of " << length << " bytes";
  }
  expect_rejected([&] { load_adb(Bytes(bytes.begin(), bytes.begin() + 100)); }, "truncated");
  expect_rejected([&] { load_adb(Bytes(bytes.begin(), bytes.end() - 1)); }, "truncated");
  Bytes longer = bytes;
  longer.push_back(std::byte{0});
  expect_rejected([&] { load_adb(longer); }, "trailing");
}

TEST(SavedTree, DetectsAFlippedByteAnywhere) {
  const Bytes bytes = save_tree_to_buffer(annotated_torus());
  for (std::size_t at = 0; at < bytes.size(); ++at) {
    Bytes bad = bytes;
    bad[at] ^= std::byte{0x01};
    EXPECT_THROW(load_adb(bad), SavedTreeError) << "byte " << at;
  }
  // In the payload the checksum is what catches it.
  Bytes bad = bytes;
  bad[bytes.size() / 2] ^= std::byte{0x40};
  expect_rejected([&] { load_adb(bad); }, "checksum");
}

TEST(SavedTree, RejectsForeignFilesAndTypes) {
  const Bytes bytes = save_tree_to_buffer(annotated_torus());
  Bytes bad = bytes;
  bad[0] = std::byte{'X'};
  expect_rejected([&] { load_adb(bad); }, "magic");
  bad = bytes;
  put_u32(bad, 8, 2);
  expect_rejected([&] { load_adb(bad); },
                  "format version 2, this build reads version 3 (older versions do not "
                  "record the tree's units");
  // Another BV type, another volume size, another density, another density version.
  expect_rejected([&] { load_tree_from_buffer<Obb, AdbDensity>(bytes); }, "'aabb' volumes, expected 'obb'");
  bad = bytes;
  put_u32(bad, 56, sizeof(Aabb) + 8);
  expect_rejected([&] { load_adb(bad); }, "bytes");
  expect_rejected([&] { load_tree_from_buffer<Aabb, NoDensity>(bytes); }, "density 'adb', expected 'none'");
  const Bytes plain = save_tree_to_buffer(Tree<Aabb>{annotated_torus().bvh, {}});
  expect_rejected([&] { load_adb(plain); }, "density 'none', expected 'adb'");
  bad = bytes;
  put_u32(bad, 80, 7);
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "density 'adb' data of version 7, this build reads version 2");
  // Version 1 counted an OBB's cells on its bounding box: such a file is refused, not misread.
  bad = bytes;
  put_u32(bad, 80, 1);
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "density 'adb' data of version 1, this build reads version 2");
  bad = bytes;
  std::memcpy(bad.data() + 64, "foo\0", 4);
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "density 'foo', expected 'adb'");
  bad = bytes;
  std::memcpy(bad.data() + 64, "adbadbadbadbadba", 16);  // no terminating NUL in the field
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "bad density name field");
  // The error names the source.
  expect_rejected([&] { load_tree_from_buffer<Obb, AdbDensity>(bytes, "somewhere/model.tree"); },
                  "somewhere/model.tree");
}

TEST(SavedTree, AbsurdCountsAreRejectedBeforeAllocating) {
  const Bytes bytes = save_tree_to_buffer(annotated_torus());
  Bytes bad = bytes;
  put_u64(bad, 88, std::uint64_t{1} << 60);  // node count
  expect_rejected([&] { load_adb(bad); }, "absurd");
  bad = bytes;
  put_u64(bad, 104, std::uint64_t{1} << 63);  // density block size, beyond what the payload could hold
  expect_rejected([&] { load_adb(bad); }, "does not match");
  bad = bytes;  // a density block of 1 TB, the payload size agreeing: the file is far too short for it
  const std::uint64_t density_bytes = 12 + annotated_torus().bvh.nodes().size();
  std::uint64_t payload = 0;
  for (int i = 7; i >= 0; --i) payload = (payload << 8) | std::to_integer<std::uint64_t>(bytes[112 + i]);
  put_u64(bad, 104, std::uint64_t{1} << 40);
  put_u64(bad, 112, payload - density_bytes + (std::uint64_t{1} << 40));
  expect_rejected([&] { load_adb(bad); }, "truncated");
  bad = bytes;
  put_u64(bad, 88, 100'000'000);  // plausible count, but the file is far too short for it
  put_u64(bad, 112,
          100'000'000ull * (8 + sizeof(Aabb)) + 4 * annotated_torus().bvh.triangle_ids().size() +
              (12 + annotated_torus().bvh.nodes().size()));
  expect_rejected([&] { load_adb(bad); }, "truncated");
  bad = bytes;
  put_u64(bad, 112, 12345);  // payload size disagreeing with the counts
  expect_rejected([&] { load_adb(bad); }, "payload size");
}

TEST(SavedTree, RejectsBadStructureEvenWithAValidChecksum) {
  const auto& tree = annotated_torus();
  const Bytes bytes = save_tree_to_buffer(tree);
  const auto& nodes = tree.bvh.nodes();
  ASSERT_FALSE(nodes[0].is_leaf());
  auto with_node = [&](std::size_t k, TreeNode node) {
    Bytes b = bytes;
    std::memcpy(b.data() + nodes_offset() + k * sizeof(TreeNode), &node, sizeof(TreeNode));
    reseal(b);
    return b;
  };
  const auto n = static_cast<std::uint32_t>(nodes.size());
  expect_rejected([&] { load_adb(with_node(0, TreeNode{n - 1, 0})); }, "out of range");
  expect_rejected([&] { load_adb(with_node(0, TreeNode{0, 0})); }, "out of order");
  // Two parents for one child: the root takes over the children of another inner node (its own become
  // unreachable, but the shared child is found first).
  std::size_t inner = 1;
  while (nodes[inner].is_leaf()) ++inner;
  expect_rejected([&] { load_adb(with_node(0, TreeNode{nodes[inner].first, 0})); }, "more than one parent");
  // A leaf covering triangles past the end.
  std::size_t leaf = 0;
  while (!nodes[leaf].is_leaf()) ++leaf;
  const auto triangles = static_cast<std::uint32_t>(tree.bvh.triangle_ids().size());
  expect_rejected([&] { load_adb(with_node(leaf, TreeNode{triangles, 1})); }, "beyond");
  // A left-child leaf overlapping its sibling: the ranges no longer tile.
  std::size_t parent = 0;
  while (nodes[parent].is_leaf() || !nodes[nodes[parent].left()].is_leaf()) ++parent;
  const TreeNode left = nodes[nodes[parent].left()];
  expect_rejected(
      [&] {
        load_adb(with_node(nodes[parent].left(), TreeNode{left.first, left.count + 1}));
      },
      "adjacent");
  // The density's own block: pc above g^3, a grid or tau outside the parameters' ranges.
  Bytes bad = bytes;
  bad[bad.size() - 1] = std::byte{9};
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "exceeds the grid's 8 cells");
  const std::size_t density_at = bytes.size() - nodes.size() - 12;
  bad = bytes;
  put_u32(bad, density_at, 9);
  reseal(bad);
  expect_rejected([&] { load_adb(bad); },
                  "bad 'adb' density data: adb: grid must be an integer in [2, 4], got 9");
  for (const double tau : {1.5, -0.0, -0.01, std::numeric_limits<double>::quiet_NaN()}) {
    bad = bytes;
    put_u64(bad, density_at + 4, std::bit_cast<std::uint64_t>(tau));
    reseal(bad);
    expect_rejected([&] { load_adb(bad); }, "adb: tau must be a number in [0, 1]");
  }
  // Triangle ids that are not a permutation.
  bad = bytes;
  const std::size_t ids_at = nodes_offset() + nodes.size() * (sizeof(TreeNode) + sizeof(Aabb));
  std::memcpy(bad.data() + ids_at, bad.data() + ids_at + 4, 4);
  reseal(bad);
  expect_rejected([&] { load_adb(bad); }, "permutation");
}

// A volume model that can check its own bytes: the reader must ask it.
struct CheckedBox {
  Aabb box;
  std::uint32_t tag = 1;
  using PairContext = Aabb::PairContext;
  static constexpr std::string_view name() { return "checked_box"; }
  static CheckedBox fit(std::span<const Vec3> points) { return {Aabb::fit(points), 1}; }
  static CheckedBox merge(const CheckedBox& a, const CheckedBox& b) { return {Aabb::merge(a.box, b.box), 1}; }
  static PairContext make_context(const RigidTransform& pose) { return Aabb::make_context(pose); }
  static bool overlap(const CheckedBox& a, const CheckedBox& b, const PairContext& c) {
    return Aabb::overlap(a.box, b.box, c);
  }
  [[nodiscard]] Scalar volume() const { return box.volume(); }
  [[nodiscard]] Box bounding_box() const { return box.bounding_box(); }
  [[nodiscard]] bool contains(const Vec3& p) const { return box.contains(p); }
  [[nodiscard]] bool valid() const { return tag == 1; }
};
static_assert(BoundingVolume<CheckedBox>);

TEST(SavedTree, AVolumeModelCanRefuseItsOwnBytes) {
  const Tree<CheckedBox> tree{Bvh<CheckedBox>::build(testing::make_torus(1.0, 0.3, 8, 4)), {}};
  Bytes bytes = save_tree_to_buffer(tree);
  EXPECT_NO_THROW(load_tree_from_buffer<CheckedBox>(bytes));
  const std::size_t third_tag = nodes_offset() + tree.bvh.nodes().size() * sizeof(TreeNode) +
                                3 * sizeof(CheckedBox) + offsetof(CheckedBox, tag);
  put_u32(bytes, third_tag, 7);
  reseal(bytes);
  expect_rejected([&] { load_tree_from_buffer<CheckedBox>(bytes); }, "node 3 has an invalid volume");
}

TEST(SavedTree, ARestrictedBoxWithAnImpossibleAxisIsRefused) {
  // A crafted file past the checksum: an axis >= 3 would make decode write outside the box.
  const Tree<RestrictedBox> tree{Bvh<RestrictedBox>::build(testing::make_torus(1.0, 0.3, 8, 4)), {}};
  Bytes bytes = save_tree_to_buffer(tree);
  EXPECT_NO_THROW(load_tree_from_buffer<RestrictedBox>(bytes));
  // Find node 3's stored bytes in the file rather than assuming the layout.
  const auto* node3 = reinterpret_cast<const std::byte*>(&tree.bvh.volumes()[3]);
  const auto at = std::search(bytes.begin(), bytes.end(), node3, node3 + sizeof(RestrictedBox));
  ASSERT_NE(at, bytes.end());
  put_u32(bytes, static_cast<std::size_t>(at - bytes.begin()) + offsetof(RestrictedBox, axis), 7);
  reseal(bytes);
  expect_rejected([&] { load_tree_from_buffer<RestrictedBox>(bytes); }, "invalid volume");
}

// Every shipped volume model checks its own bytes: a NaN or infinite coordinate behind a valid checksum is
// refused by name (found by tests/fuzz: an infinite 24-DOP slab reached the ADB estimate as a NaN).
template <class BV>
class SavedVolumeBytes : public ::testing::Test {};
TYPED_TEST_SUITE(SavedVolumeBytes, testing::ShippedBoundingVolumes);

TYPED_TEST(SavedVolumeBytes, NonFiniteCoordinatesAreRefused) {
  using BV = TypeParam;
  const Tree<BV> tree{Bvh<BV>::build(testing::make_torus(1.0, 0.3, 8, 4)), {}};
  const Bytes bytes = save_tree_to_buffer(tree);
  EXPECT_NO_THROW(load_tree_from_buffer<BV>(bytes));
  const auto* node3 = reinterpret_cast<const std::byte*>(&tree.bvh.volumes()[3]);
  const auto at = std::search(bytes.begin(), bytes.end(), node3, node3 + sizeof(BV));
  ASSERT_NE(at, bytes.end());
  for (const float bad : {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                          std::numeric_limits<float>::quiet_NaN()}) {
    for (std::size_t k = 0; k < sizeof(BV) / sizeof(float); ++k) {
      Bytes crafted = bytes;
      std::memcpy(crafted.data() + (at - bytes.begin()) + k * sizeof(float), &bad, sizeof(float));
      reseal(crafted);
      expect_rejected([&] { load_tree_from_buffer<BV>(crafted); }, "node 3 has an invalid volume");
    }
  }
}

TEST(SavedTree, RandomGarbageNeverCrashes) {
  std::mt19937_64 rng(3);
  const Bytes bytes = save_tree_to_buffer(annotated_torus());
  for (int i = 0; i < 2000; ++i) {
    Bytes bad = bytes;
    const int flips = 1 + static_cast<int>(rng() % 8);
    for (int f = 0; f < flips; ++f) bad[rng() % bad.size()] = std::byte(rng() & 0xff);
    if (i % 2 == 0) reseal(bad);  // past the checksum: only the structure checks stand between
    try {
      const auto t = load_adb(bad);
      // Accepted: it must then be a tree the library can walk.
      const auto ranges = node_triangle_ranges(t.bvh.nodes());
      EXPECT_EQ(ranges.size(), t.bvh.nodes().size());
    } catch (const SavedTreeError&) {
    }
  }
}

TEST(SavedTree, RefusesToSaveInconsistentTrees) {
  Tree<Aabb, AdbDensity> tree = annotated_torus();
  tree.density.possible_collision_cells.pop_back();
  expect_rejected([&] { save_tree_to_buffer(tree); }, "bytes of annotation for");
  Tree<Aabb, AdbDensity> empty;
  expect_rejected([&] { save_tree_to_buffer(empty); }, "no nodes");
}

}  // namespace
}  // namespace bvhlab
