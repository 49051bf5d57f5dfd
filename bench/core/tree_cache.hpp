// On-disk cache of preprocessed trees, keyed by the mesh's checksum, what was applied to its coordinates
// (normalisation, scale, placement: bench/prepare.cpp, load_object) and every option that shapes the tree.
//
// Each entry is two files: `<bv>-<key hash>.tree`, a tree in the saved-tree format (adb/saved_tree.hpp,
// without polygons, so `bvhlab query` can read it too; it records the normalisation), and `<same>.meta.json`,
// which records the full key, the payload's size and checksum, and how long the tree took to build and
// annotate. An entry is trusted only if the meta file names the same key, the payload has the recorded size
// and checksum, the saved-tree reader accepts it, and the decoded tree passes structural checks against the
// mesh (triangle ids a permutation, node ranges consistent, every leaf volume containing its triangles,
// annotation sized and in range). Anything else is a stale or corrupt entry: it is reported, rebuilt by the
// caller and overwritten.
#pragma once

#include "adb/saved_tree.hpp"
#include "adb/tree.hpp"
#include "bench/core/content_hash.hpp"
#include "bvh/mesh.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

struct CachedTreeTimes {
  double build_seconds = 0, annotate_seconds = 0;
};

namespace tree_cache_detail {

/// Checks a decoded tree against its mesh and re-attaches the polygons (saved trees carry none).
/// Throws std::runtime_error naming the first defect.
template <class BV, Density D>
Tree<BV, D> attach_polygons(const Tree<BV, D>& saved, const Mesh& mesh) {
  const Bvh<BV>& bvh = saved.bvh;
  const std::size_t n = mesh.triangles.size();
  const auto& ids = bvh.triangle_ids();
  if (bvh.nodes().empty()) throw std::runtime_error("the tree has no nodes");
  if (bvh.volumes().size() != bvh.nodes().size()) throw std::runtime_error("node and volume counts differ");
  if (ids.size() != n)
    throw std::runtime_error("the tree covers " + std::to_string(ids.size()) + " triangles, the mesh has " +
                             std::to_string(n));
  std::vector<bool> seen(n, false);
  for (std::uint32_t id : ids) {
    if (id >= n || seen[id]) throw std::runtime_error("triangle ids are not a permutation of the mesh's");
    seen[id] = true;
  }
  const auto ranges = node_triangle_ranges(bvh.nodes());  // throws on a malformed topology
  if (ranges.front() != std::pair<std::uint32_t, std::uint32_t>{0, static_cast<std::uint32_t>(n)})
    throw std::runtime_error("the root does not cover every triangle");
  std::vector<TrianglePoints> triangles;
  triangles.reserve(n);
  for (std::uint32_t id : ids) triangles.push_back(mesh.triangle(id));
  // Volumes stored relative to their parent (hierarchical BVs) are checked through their decoded boxes.
  const std::vector<Box> boxes = bvh.node_boxes();
  for (std::size_t i = 0; i < bvh.nodes().size(); ++i) {
    const auto node = static_cast<std::uint32_t>(i);
    if (!bvh.node(node).is_leaf()) continue;
    for (std::uint32_t t = ranges[i].first; t < ranges[i].second; ++t)
      for (const Vec3& v : triangles[t]) {
        bool inside = false;
        if constexpr (requires { bvh.volume(node).contains(v); })
          inside = bvh.volume(node).contains(v);
        else
          inside = boxes[i].contains(v);
        if (!inside)
          throw std::runtime_error("leaf " + std::to_string(i) + "'s volume does not contain its triangles");
      }
  }
  Bvh<BV> with_polygons = [&] {
    if constexpr (requires { bvh.root_volume(); })
      return Bvh<BV>::from_parts(bvh.nodes(), bvh.volumes(), ids, std::move(triangles), bvh.root_volume());
    else
      return Bvh<BV>::from_parts(bvh.nodes(), bvh.volumes(), ids, std::move(triangles));
  }();
  // The density's data was validated when the saved tree was decoded (D::decode).
  return Tree<BV, D>{std::move(with_polygons), saved.density};
}

/// adb/file_io.hpp's reader and atomic writer (this one also creates the folder). Throw file_io::FileError.
std::vector<std::byte> read_file_bytes(const std::filesystem::path& file);
void write_file_bytes(const std::filesystem::path& file, std::span<const std::byte> bytes);

}  // namespace tree_cache_detail

class TreeCache {
 public:
  /// `dir` empty: a disabled cache (every load misses, stores do nothing).
  explicit TreeCache(std::filesystem::path dir, std::function<void(const std::string&)> log = {});

  [[nodiscard]] bool enabled() const { return !dir_.empty(); }
  [[nodiscard]] std::filesystem::path tree_file(const std::string& key, std::string_view bv) const;

  struct Counts {
    std::size_t hits = 0, misses = 0, rejected = 0, stored = 0;
  };
  [[nodiscard]] const Counts& counts() const { return counts_; }

  /// The tree stored under `key`, checked and with `mesh`'s polygons re-attached; nullopt on a miss or when
  /// the entry is stale or corrupt (then it is logged and counted as rejected). Its density must describe
  /// itself as `expected_density` (D::describe).
  template <class BV, Density D>
  std::optional<Tree<BV, D>> load(const std::string& key, const Mesh& mesh, CachedTreeTimes* times = nullptr,
                                  std::string_view expected_density = "none") {
    if (!enabled()) return std::nullopt;
    const auto file = tree_file(key, BV::name());
    if (!std::filesystem::exists(file) && !std::filesystem::exists(meta_file(file))) {
      ++counts_.misses;
      return std::nullopt;
    }
    try {
      const std::vector<std::byte> payload = read_checked_payload(key, file, times);
      const Tree<BV, D> saved = load_tree_from_buffer<BV, D>(payload);
      if (const std::string found = D::describe(saved.density); found != expected_density)
        throw std::runtime_error("annotated as '" + found + "', expected '" + std::string(expected_density) +
                                 "'");
      Tree<BV, D> tree = tree_cache_detail::attach_polygons(saved, mesh);
      ++counts_.hits;
      return tree;
    } catch (const std::exception& e) {
      ++counts_.rejected;
      say("tree cache: rejected " + file.filename().string() + " (" + e.what() + "); rebuilding");
      return std::nullopt;
    }
  }

  /// Saves `tree` (without polygons) under `key`, recording its `units`. A failure to write is logged, never
  /// fatal.
  template <class BV, Density D>
  void store(const std::string& key, const Tree<BV, D>& tree, const CachedTreeTimes& times,
             const TreeUnits& units = {}) {
    if (!enabled()) return;
    const auto file = tree_file(key, BV::name());
    try {
      const std::vector<std::byte> payload = save_tree_to_buffer(tree, {.units = units});
      write_entry(key, file, payload, times);
      ++counts_.stored;
    } catch (const std::exception& e) {
      say("tree cache: could not store " + file.string() + " (" + e.what() + ")");
    }
  }

 private:
  static std::filesystem::path meta_file(const std::filesystem::path& tree_file);
  std::vector<std::byte> read_checked_payload(const std::string& key, const std::filesystem::path& file,
                                              CachedTreeTimes* times) const;
  void write_entry(const std::string& key, const std::filesystem::path& file,
                   std::span<const std::byte> payload, const CachedTreeTimes& times) const;
  void say(const std::string& message) const;

  std::filesystem::path dir_;
  std::function<void(const std::string&)> log_;
  Counts counts_;
};

}  // namespace bvhlab
