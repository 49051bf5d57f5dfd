// On-disk cache of preprocessed trees, keyed by the mesh's checksum, what was applied to its coordinates
// (normalisation, scale, placement: the runner's load_object) and every option that shapes the tree.
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

#include "bvh/mesh.hpp"
#include "engine/any_tree.hpp"
#include "engine/content_hash.hpp"

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

  /// The tree of volume `bv` stored under `key`, checked and with `mesh`'s polygons re-attached; nullopt on
  /// a miss or when the entry is stale or corrupt (then it is logged and counted as rejected). Its density
  /// must describe itself as `expected_density` (D::describe).
  std::optional<AnyTree> load(const std::string& key, std::string_view bv, const Mesh& mesh,
                              CachedTreeTimes* times = nullptr, std::string_view expected_density = "none");

  /// Saves `tree` (without polygons, with the units it records) under `key`. A failure to write is logged,
  /// never fatal.
  void store(const std::string& key, const AnyTree& tree, const CachedTreeTimes& times);

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
