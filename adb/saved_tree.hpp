// Saved trees: a Tree<BV, D> without polygons, in a versioned, checksummed binary file.
//
// Format version 3 (every header integer little-endian; the arrays are raw native bytes, so the header also
// records the writer's byte order and a reader on the other order refuses the file):
//
//   offset size
//        0    8  magic "BVHLTREE"
//        8    4  format version (3)
//       12    4  byte-order mark 0x01020304 as written by the machine (raw arrays are in that order)
//       16    4  header size (160)
//       20    4  flags: bit 0 = triangle ids present, bit 1 = normalised coordinates; other bits must be 0
//       24   32  BV::name(), NUL-padded (at most 31 characters)
//       56    4  sizeof(BV) (a stored node volume)
//       60    4  size of the stored root volume: sizeof(BV::Decoded) for volumes stored relative to their
//                parent (HierarchicalVolume), else 0
//       64   16  the density's name (adb/concept.hpp, D::name()), NUL-padded (at most 15 characters)
//       80    4  the density's data version (D::version())
//       84    4  reserved, 0
//       88    8  node count N
//       96    8  triangle count T (what the leaves cover, stored even when the ids are not)
//      104    8  density block size D
//      112    8  payload size in bytes
//      120    8  normalisation scale s (IEEE double bits): finite and > 0 when normalised, else exactly 1
//      128   24  normalisation centre c (3 IEEE doubles): finite when normalised, else exactly 0
//      152    8  checksum: FNV-1a 64 over bytes [0, 152) and the payload
//      160       payload: root volume | N nodes (first, count: 2 x u32) | N volumes | T triangle ids (u32, if
//                flagged) | D bytes of density data (D::encode: its parameters and per-node data)
//
// Units: a tree's coordinates are the mesh file's own, or, when normalised (the benchmark protocol's
// normalisation, adb/README.md section 4), x' = (x - c) * s for every vertex x of the file. (The runner's
// tree cache also stores trees of scene objects scaled or placed after that; its key records those.) Version
// 2 did not record the units, and is refused by name (build the tree again).
//
// A density the reader does not know, or whose data version differs from the reader's, is refused by name;
// the density validates its own block (D::decode).
// Loading checks, before allocating anything, that the file is as long as the header's counts say (a
// corrupt count cannot cause a giant allocation), then the checksum, then the structure: children stored
// after their parent and in range, every node but the root the child of exactly one parent, leaf ranges
// tiling [0, T), triangle ids a permutation, and the density's block (D::decode). The stored volumes
// themselves are opaque bytes: the checksum vouches for them, and a volume model with a `bool valid() const`
// member is asked to check each one (a restricted box's axis, for one, indexes an array when decoded).
//
// Triangle ids are stored by default: they map tree order to the mesh's triangles, which is what re-attaching
// polygons needs (the tree cache, an exact fallback). An ADB-only query needs none of them, so
// SaveOptions::triangle_ids = false drops 4 bytes per triangle.
//
// Files are written to a temporary file in the target's directory, flushed to disk and renamed over the
// target: a failed write leaves the previous file (or none), never a half-written tree.
#pragma once

#include "tree.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Any problem reading or writing a saved tree; what() names the file (or buffer) and the problem.
class SavedTreeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How a tree's coordinates relate to its mesh file's: the file's own units, or the protocol normalisation
/// x' = (x - centre) * scale (bounding-box centre to the origin, longest side 2).
struct TreeUnits {
  bool normalized = false;
  double scale = 1;            ///< 1 unless normalised
  Vec3 centre = Vec3::Zero();  ///< zero unless normalised
  [[nodiscard]] bool operator==(const TreeUnits&) const = default;
  /// "the mesh file's units", or "normalised: scale 0.0123, centre (1, 2, 3)".
  [[nodiscard]] std::string describe() const;
};

struct SaveOptions {
  bool triangle_ids = true;  ///< keep tree order -> mesh triangle (4 bytes per triangle)
  TreeUnits units{};         ///< recorded in the header; the tree's coordinates must already be in them
};

inline constexpr std::uint32_t kSavedTreeVersion = 3;
inline constexpr std::size_t kSavedTreeHeaderSize = 160;
/// Where the checksum sits in the header: it covers the bytes before it and the payload.
inline constexpr std::size_t kSavedTreeChecksumOffset = 152;

namespace saved_tree_detail {

/// What the reader expects, from the caller's types.
struct Layout {
  std::string_view bv_name;
  std::uint32_t volume_size = 0;
  std::uint32_t root_volume_size = 0;
  std::string_view density_name = "none";
  std::uint32_t density_version = 1;
};

/// A tree's parts, viewed for writing.
struct View {
  Layout layout;
  std::uint64_t triangle_count = 0;
  std::span<const std::byte> root_volume;  ///< layout.root_volume_size bytes
  std::span<const TreeNode> nodes;
  std::span<const std::byte> volumes;           ///< nodes.size() * layout.volume_size bytes
  std::span<const std::uint32_t> triangle_ids;  ///< empty, or triangle_count ids
  std::span<const std::byte> density;           ///< the density's encoded block
  TreeUnits units;
};

/// A decoded tree. The volume spans point into the buffer that was decoded.
struct Parts {
  std::uint64_t triangle_count = 0;
  std::span<const std::byte> root_volume;
  std::vector<TreeNode> nodes;
  std::span<const std::byte> volumes;
  std::vector<std::uint32_t> triangle_ids;
  std::span<const std::byte> density;  ///< the density's block, for D::decode
};

/// The header's fields, read and checked in this one place.
struct Header {
  std::string bv_name, density_name;
  std::uint32_t density_version = 0;
  std::uint32_t volume_size = 0, root_volume_size = 0;
  bool has_triangle_ids = false;
  std::uint64_t nodes = 0, triangles = 0, density_bytes = 0, payload = 0;
  TreeUnits units;
};
/// Reads the header of a saved-tree image: magic, version, byte order, reserved bytes, names, units, and
/// sizes that agree with each other and with `buffer`'s length (so a corrupt count cannot cause a giant
/// allocation).
/// `buffer` may hold only the header when `whole` is false (then lengths are not checked). Throws
/// SavedTreeError naming `source`.
Header read_header(std::span<const std::byte> buffer, std::string_view source, bool whole = true);

/// Throws SavedTreeError (naming `source`) for a tree that cannot be saved.
std::vector<std::byte> encode(const View& view, std::string_view source = "<buffer>");
/// Throws SavedTreeError naming `source` and the first problem found.
Parts decode(std::span<const std::byte> buffer, const Layout& expected, std::string_view source);
/// FNV-1a 64 of the bytes, continuing from `hash`.
std::uint64_t fnv1a64(std::span<const std::byte> bytes, std::uint64_t hash = 0xcbf29ce484222325ull);

std::vector<std::byte> read_file(const std::filesystem::path& path);
void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

template <TreeVolume BV, Density D>
Layout layout_of() {
  Layout layout;
  layout.bv_name = BV::name();
  layout.volume_size = sizeof(BV);
  if constexpr (HierarchicalVolume<BV>) layout.root_volume_size = sizeof(fitted_volume_t<BV>);
  layout.density_name = D::name();
  layout.density_version = D::version();
  return layout;
}

template <class T>
std::span<const std::byte> bytes_of(std::span<const T> values) {
  return std::as_bytes(values);
}

}  // namespace saved_tree_detail

/// The tree as a saved-tree byte image (no polygons). Throws SavedTreeError for an empty tree or an
/// annotation that does not match its nodes.
template <TreeVolume BV, Density D>
std::vector<std::byte> save_tree_to_buffer(const Tree<BV, D>& tree, const SaveOptions& options = {},
                                           std::string_view source = "<buffer>") {
  static_assert(std::is_trivially_copyable_v<BV>, "volumes are saved as raw bytes");
  using Root = fitted_volume_t<BV>;
  const Bvh<BV>& bvh = tree.bvh;
  saved_tree_detail::View view;
  view.layout = saved_tree_detail::layout_of<BV, D>();
  const auto ranges_end = [&]() -> std::uint64_t {
    // The triangle count is what the leaves cover; the ids, when present, must agree (checked in encode).
    std::uint64_t end = 0;
    for (const TreeNode& n : bvh.nodes())
      if (n.is_leaf()) end = std::max<std::uint64_t>(end, std::uint64_t{n.first} + n.count);
    return end;
  }();
  view.triangle_count = ranges_end;
  Root root{};
  if constexpr (HierarchicalVolume<BV>) root = bvh.root_volume();
  if constexpr (HierarchicalVolume<BV>) view.root_volume = std::as_bytes(std::span<const Root>(&root, 1));
  view.nodes = bvh.nodes();
  view.volumes = saved_tree_detail::bytes_of(std::span<const BV>(bvh.volumes()));
  if (options.triangle_ids) view.triangle_ids = bvh.triangle_ids();
  view.units = options.units;
  const std::vector<std::byte> density = D::encode(tree.density);
  try {  // what is saved must load: the density checks its bytes against the node count as a reader would
    (void)D::decode(density, bvh.nodes().size());
  } catch (const std::invalid_argument& e) {
    throw SavedTreeError("saved tree '" + std::string(source) + "': cannot save: " + e.what());
  }
  view.density = density;
  return saved_tree_detail::encode(view, source);
}

/// Reads a saved-tree byte image into a Tree<BV, D> without polygons (and without triangle ids when
/// the file has none). Throws SavedTreeError naming `source` and the problem.
template <TreeVolume BV, Density D = NoDensity>
Tree<BV, D> load_tree_from_buffer(std::span<const std::byte> buffer, std::string_view source = "<buffer>") {
  using Root = fitted_volume_t<BV>;
  saved_tree_detail::Parts parts =
      saved_tree_detail::decode(buffer, saved_tree_detail::layout_of<BV, D>(), source);
  std::vector<BV> volumes(parts.nodes.size());
  std::memcpy(volumes.data(), parts.volumes.data(), parts.volumes.size());
  Root root{};
  if constexpr (HierarchicalVolume<BV>)
    std::memcpy(&root, parts.root_volume.data(), sizeof(Root));
  else
    root = volumes.front();
  // Volume bytes are opaque to the format; a model that can check its own invariants (say, an axis index
  // that decoding uses to index an array) gets the chance to refuse a crafted file here.
  if constexpr (requires(const BV& v) {
                  { v.valid() } -> std::convertible_to<bool>;
                }) {
    for (std::size_t i = 0; i < volumes.size(); ++i)
      if (!volumes[i].valid())
        throw SavedTreeError("saved tree '" + std::string(source) + "': node " + std::to_string(i) +
                             " has an invalid volume");
  }
  if constexpr (HierarchicalVolume<BV> && requires(const Root& v) {
                  { v.valid() } -> std::convertible_to<bool>;
                }) {
    if (!root.valid()) throw SavedTreeError("saved tree '" + std::string(source) + "': invalid root volume");
  }
  typename D::Storage density;
  try {
    density = D::decode(parts.density, parts.nodes.size());
  } catch (const std::invalid_argument& e) {
    throw SavedTreeError("saved tree '" + std::string(source) + "': bad '" + std::string(D::name()) +
                         "' density data: " + e.what());
  }
  return Tree<BV, D>{Bvh<BV>::from_parts(std::move(parts.nodes), std::move(volumes),
                                         std::move(parts.triangle_ids), {}, root),
                     std::move(density)};
}

/// Saves to `path` atomically (temporary file + rename). Throws SavedTreeError naming the file.
template <TreeVolume BV, Density D>
void save_tree(const Tree<BV, D>& tree, const std::filesystem::path& path, const SaveOptions& options = {}) {
  saved_tree_detail::write_file_atomically(path, save_tree_to_buffer(tree, options, path.string()));
}

/// Loads from `path`. Throws SavedTreeError naming the file.
template <TreeVolume BV, Density D = NoDensity>
Tree<BV, D> load_tree(const std::filesystem::path& path) {
  const std::vector<std::byte> bytes = saved_tree_detail::read_file(path);
  return load_tree_from_buffer<BV, D>(bytes, path.string());
}

/// The units a saved-tree image records (its header, checked). Throws SavedTreeError naming `source`.
TreeUnits saved_tree_units(std::span<const std::byte> buffer, std::string_view source = "<buffer>");

}  // namespace bvhlab
