// Saved-tree format: encoding, validating decoder, atomic file writes. See adb/saved_tree.hpp.
#include "adb/saved_tree.hpp"

#include "adb/file_io.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace bvhlab::saved_tree_detail {
namespace {

static_assert(sizeof(TreeNode) == 8 && std::is_trivially_copyable_v<TreeNode>);

constexpr std::array<char, 8> kMagic = {'B', 'V', 'H', 'L', 'T', 'R', 'E', 'E'};
constexpr std::uint32_t kByteOrderMark = 0x01020304;
constexpr std::uint32_t kFlagTriangleIds = 1, kFlagNormalized = 2;
constexpr std::size_t kNameField = 32, kDensityNameField = 16;
constexpr std::size_t kChecksumOffset = kSavedTreeChecksumOffset;

// Header field offsets.
constexpr std::size_t kVersionAt = 8, kByteOrderAt = 12, kHeaderSizeAt = 16, kFlagsAt = 20, kNameAt = 24,
                      kVolumeSizeAt = 56, kRootSizeAt = 60, kDensityNameAt = 64, kDensityVersionAt = 80,
                      kReservedAt = 84, kNodesAt = 88, kTrianglesAt = 96, kDensityBytesAt = 104,
                      kPayloadAt = 112, kScaleAt = 120, kCentreAt = 128;
static_assert(kCentreAt + 24 == kChecksumOffset && kChecksumOffset + 8 == kSavedTreeHeaderSize);

[[noreturn]] void fail(std::string_view source, const std::string& problem) {
  throw SavedTreeError("saved tree '" + std::string(source) + "': " + problem);
}

void put_le(std::byte* at, std::uint64_t value, int bytes) {
  for (int i = 0; i < bytes; ++i) at[i] = static_cast<std::byte>((value >> (8 * i)) & 0xff);
}
std::uint64_t get_le(const std::byte* at, int bytes) {
  std::uint64_t value = 0;
  for (int i = 0; i < bytes; ++i) value |= std::uint64_t(std::to_integer<std::uint8_t>(at[i])) << (8 * i);
  return value;
}

std::uint64_t checksum_of(std::span<const std::byte> file) {
  const std::uint64_t head = fnv1a64(file.first(kChecksumOffset));
  return fnv1a64(file.subspan(kSavedTreeHeaderSize), head);
}

/// a * b + c, or false on overflow.
bool mul_add(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t& out) {
  if (b != 0 && a > (std::numeric_limits<std::uint64_t>::max() - c) / b) return false;
  out = a * b + c;
  return true;
}

/// Structure checks shared by writer and reader; `problem` receives the first defect.
bool valid_topology(std::span<const TreeNode> nodes, std::uint64_t triangle_count, std::string& problem) {
  const std::size_t n = nodes.size();
  if (n == 0) {
    problem = "the tree has no nodes";
    return false;
  }
  std::vector<std::uint8_t> parents(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const TreeNode& node = nodes[k];
    if (node.is_leaf()) {
      if (node.first > triangle_count || node.count > triangle_count - node.first) {
        problem = "leaf " + std::to_string(k) + " covers triangles [" + std::to_string(node.first) + ", " +
                  std::to_string(std::uint64_t{node.first} + node.count) + ") beyond the " +
                  std::to_string(triangle_count) + " triangles";
        return false;
      }
      continue;
    }
    if (node.first <= k || std::uint64_t{node.first} + 1 >= n) {
      problem = "node " + std::to_string(k) + " has children " + std::to_string(node.first) + " and " +
                std::to_string(std::uint64_t{node.first} + 1) +
                (node.first <= k ? ", not stored after it (out of order)"
                                 : ", out of range of the " + std::to_string(n) + " nodes");
      return false;
    }
    for (const std::uint32_t child : {node.left(), node.right()})
      if (++parents[child] > 1) {
        problem = "node " + std::to_string(child) + " has more than one parent";
        return false;
      }
  }
  for (std::size_t k = 1; k < n; ++k)
    if (parents[k] == 0) {
      problem = "node " + std::to_string(k) + " is not reachable from the root";
      return false;
    }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges;
  try {
    ranges = node_triangle_ranges(nodes);
  } catch (const std::exception& e) {
    problem = e.what();
    return false;
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!nodes[k].is_leaf() && ranges[nodes[k].left()].second != ranges[nodes[k].right()].first) {
      problem = "the children of node " + std::to_string(k) + " do not cover adjacent triangle ranges";
      return false;
    }
  if (ranges[0].first != 0 || ranges[0].second != triangle_count) {
    problem = "the leaves cover triangles [" + std::to_string(ranges[0].first) + ", " +
              std::to_string(ranges[0].second) + "), not all " + std::to_string(triangle_count);
    return false;
  }
  return true;
}

bool is_permutation_of_range(std::span<const std::uint32_t> ids) {
  std::vector<bool> seen(ids.size(), false);
  for (const std::uint32_t id : ids) {
    if (id >= ids.size() || seen[id]) return false;
    seen[id] = true;
  }
  return true;
}

/// A NUL-padded name field: 1 to size-1 characters, then NULs only.
std::string_view name_field(const std::byte* at, std::size_t size) {
  const char* field = reinterpret_cast<const char*>(at);
  const std::size_t length = std::find(field, field + size, '\0') - field;
  if (length == 0 || length == size || std::any_of(field + length, field + size, [](char c) { return c; }))
    return {};
  return {field, length};
}

/// "" when `units` can be recorded: raw units are exactly scale 1 and centre 0 (one encoding per tree, so
/// a loaded tree saves back to the same bytes), normalised ones finite with a positive scale.
std::string units_problem(const TreeUnits& units) {
  if (!units.normalized)
    return units.scale == 1 && units.centre == Vec3::Zero() && !std::signbit(units.centre.x()) &&
                   !std::signbit(units.centre.y()) && !std::signbit(units.centre.z())
               ? ""
               : "units not normalised but with a scale or centre";
  if (!std::isfinite(units.scale) || !(units.scale > 0) || !units.centre.allFinite())
    return "normalisation with a scale that is not finite and positive, or a centre that is not finite";
  return "";
}

void put_double(std::byte* at, double value) {
  put_le(at, std::bit_cast<std::uint64_t>(value), 8);
}
double get_double(const std::byte* at) {
  return std::bit_cast<double>(get_le(at, 8));
}

}  // namespace

std::uint64_t fnv1a64(std::span<const std::byte> bytes, std::uint64_t hash) {
  for (const std::byte b : bytes) {
    hash ^= std::to_integer<std::uint8_t>(b);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::vector<std::byte> encode(const View& view, std::string_view source) {
  const Layout& layout = view.layout;
  const std::size_t n = view.nodes.size();
  if (layout.bv_name.empty() || layout.bv_name.size() >= kNameField)
    fail(source, "BV name '" + std::string(layout.bv_name) + "' must have 1 to 31 characters");
  if (layout.density_name.empty() || layout.density_name.size() >= kDensityNameField)
    fail(source, "density name '" + std::string(layout.density_name) + "' must have 1 to 15 characters");
  if (n >= std::numeric_limits<std::uint32_t>::max() ||
      view.triangle_count >= std::numeric_limits<std::uint32_t>::max())
    fail(source, "too many nodes or triangles for 32-bit indices");
  if (view.volumes.size() != n * layout.volume_size) fail(source, "volume bytes do not match the node count");
  if (view.root_volume.size() != layout.root_volume_size) fail(source, "root volume size mismatch");
  std::string problem;
  if (!valid_topology(view.nodes, view.triangle_count, problem)) fail(source, "cannot save: " + problem);
  if (!view.triangle_ids.empty() && view.triangle_ids.size() != view.triangle_count)
    fail(source, "cannot save: " + std::to_string(view.triangle_ids.size()) + " triangle ids for " +
                     std::to_string(view.triangle_count) + " triangles");
  if (const std::string problem = units_problem(view.units); !problem.empty())
    fail(source, "cannot save: " + problem);

  const std::size_t payload = layout.root_volume_size + n * sizeof(TreeNode) + view.volumes.size() +
                              view.triangle_ids.size() * sizeof(std::uint32_t) + view.density.size();
  std::vector<std::byte> out(kSavedTreeHeaderSize + payload, std::byte{0});
  std::byte* h = out.data();
  std::memcpy(h, kMagic.data(), kMagic.size());
  put_le(h + kVersionAt, kSavedTreeVersion, 4);
  std::memcpy(h + kByteOrderAt, &kByteOrderMark, 4);  // native on purpose: it tells the arrays' byte order
  put_le(h + kHeaderSizeAt, kSavedTreeHeaderSize, 4);
  put_le(h + kFlagsAt,
         (view.triangle_ids.empty() ? 0 : kFlagTriangleIds) | (view.units.normalized ? kFlagNormalized : 0),
         4);
  std::memcpy(h + kNameAt, layout.bv_name.data(), layout.bv_name.size());
  put_le(h + kVolumeSizeAt, layout.volume_size, 4);
  put_le(h + kRootSizeAt, layout.root_volume_size, 4);
  std::memcpy(h + kDensityNameAt, layout.density_name.data(), layout.density_name.size());
  put_le(h + kDensityVersionAt, layout.density_version, 4);
  put_le(h + kNodesAt, n, 8);
  put_le(h + kTrianglesAt, view.triangle_count, 8);
  put_le(h + kDensityBytesAt, view.density.size(), 8);
  put_le(h + kPayloadAt, payload, 8);
  put_double(h + kScaleAt, view.units.scale);
  for (int k = 0; k < 3; ++k) put_double(h + kCentreAt + 8 * k, view.units.centre[k]);

  std::byte* at = out.data() + kSavedTreeHeaderSize;
  auto append = [&](std::span<const std::byte> bytes) {
    if (!bytes.empty()) std::memcpy(at, bytes.data(), bytes.size());
    at += bytes.size();
  };
  append(view.root_volume);
  append(std::as_bytes(view.nodes));
  append(view.volumes);
  append(std::as_bytes(view.triangle_ids));
  append(view.density);
  put_le(h + kChecksumOffset, checksum_of(out), 8);
  return out;
}

Header read_header(std::span<const std::byte> buffer, std::string_view source, bool whole) {
  if (buffer.size() < kSavedTreeHeaderSize)
    fail(source, "truncated: " + std::to_string(buffer.size()) + " bytes, shorter than the " +
                     std::to_string(kSavedTreeHeaderSize) + "-byte header");
  const std::byte* h = buffer.data();
  if (std::memcmp(h, kMagic.data(), kMagic.size()) != 0)
    fail(source, "not a bvhlab saved tree (bad magic bytes)");
  const std::uint64_t version = get_le(h + kVersionAt, 4);
  if (version != kSavedTreeVersion)
    fail(source,
         "format version " + std::to_string(version) + ", this build reads version " +
             std::to_string(kSavedTreeVersion) +
             (version < kSavedTreeVersion ? " (older versions do not record the tree's units: build it "
                                            "again with bvhlab build)"
                                          : " (written by a newer bvhlab)"));
  std::uint32_t byte_order = 0;
  std::memcpy(&byte_order, h + kByteOrderAt, 4);
  if (byte_order != kByteOrderMark) fail(source, "written on a machine of another byte order (or corrupted)");
  if (get_le(h + kHeaderSizeAt, 4) != kSavedTreeHeaderSize)
    fail(source, "corrupted header (bad header size)");
  const std::uint64_t flags = get_le(h + kFlagsAt, 4);
  if ((flags & ~std::uint64_t{kFlagTriangleIds | kFlagNormalized}) != 0)
    fail(source, "unknown flags " + std::to_string(flags));
  if (get_le(h + kReservedAt, 4) != 0) fail(source, "corrupted header (reserved bytes are not zero)");

  Header header;
  header.bv_name = name_field(h + kNameAt, kNameField);
  if (header.bv_name.empty()) fail(source, "corrupted header (bad BV name field)");
  header.density_name = name_field(h + kDensityNameAt, kDensityNameField);
  if (header.density_name.empty()) fail(source, "corrupted header (bad density name field)");
  header.density_version = static_cast<std::uint32_t>(get_le(h + kDensityVersionAt, 4));
  header.volume_size = static_cast<std::uint32_t>(get_le(h + kVolumeSizeAt, 4));
  header.root_volume_size = static_cast<std::uint32_t>(get_le(h + kRootSizeAt, 4));
  header.has_triangle_ids = (flags & kFlagTriangleIds) != 0;
  header.nodes = get_le(h + kNodesAt, 8);
  header.triangles = get_le(h + kTrianglesAt, 8);
  header.density_bytes = get_le(h + kDensityBytesAt, 8);
  header.payload = get_le(h + kPayloadAt, 8);
  header.units.normalized = (flags & kFlagNormalized) != 0;
  header.units.scale = get_double(h + kScaleAt);
  for (int k = 0; k < 3; ++k) header.units.centre[k] = get_double(h + kCentreAt + 8 * k);
  if (const std::string problem = units_problem(header.units); !problem.empty())
    fail(source, "corrupted header (" + problem + ")");

  // Sizes, against each other and the buffer's real length, before any allocation.
  const std::uint64_t n = header.nodes, triangles = header.triangles;
  std::uint64_t expected_payload = 0;
  if (n == 0 || n >= std::numeric_limits<std::uint32_t>::max() ||
      triangles >= std::numeric_limits<std::uint32_t>::max() ||
      !mul_add(n, sizeof(TreeNode) + std::uint64_t{header.volume_size}, header.root_volume_size,
               expected_payload) ||
      !mul_add(header.has_triangle_ids ? triangles : 0, sizeof(std::uint32_t), expected_payload,
               expected_payload) ||
      !mul_add(1, header.density_bytes, expected_payload, expected_payload))
    fail(source, "corrupted header (absurd counts: " + std::to_string(n) + " nodes, " +
                     std::to_string(triangles) + " triangles)");
  if (header.payload != expected_payload)
    fail(source, "corrupted header (payload size " + std::to_string(header.payload) + " does not match " +
                     std::to_string(n) + " nodes, " + std::to_string(triangles) + " triangles and " +
                     std::to_string(header.density_bytes) + " bytes of density data)");
  if (!whole) return header;
  const std::uint64_t available = buffer.size() - kSavedTreeHeaderSize;
  if (available < header.payload)
    fail(source, "truncated: the payload has " + std::to_string(available) + " of " +
                     std::to_string(header.payload) + " bytes");
  if (available > header.payload)
    fail(source, std::to_string(available - header.payload) + " trailing bytes after the payload");
  if (get_le(h + kChecksumOffset, 8) != checksum_of(buffer))
    fail(source, "checksum mismatch: the file is corrupted");
  return header;
}

Parts decode(std::span<const std::byte> buffer, const Layout& expected, std::string_view source) {
  const Header header = read_header(buffer, source);
  if (header.bv_name != expected.bv_name)
    fail(source, "holds '" + header.bv_name + "' volumes, expected '" + std::string(expected.bv_name) + "'");
  if (header.volume_size != expected.volume_size || header.root_volume_size != expected.root_volume_size)
    fail(source, "'" + header.bv_name + "' volumes of " + std::to_string(header.volume_size) +
                     " bytes (root " + std::to_string(header.root_volume_size) + "), this build's are " +
                     std::to_string(expected.volume_size) + " (root " +
                     std::to_string(expected.root_volume_size) + ")");
  if (header.density_name != expected.density_name)
    fail(source, "holds a tree with density '" + header.density_name + "', expected '" +
                     std::string(expected.density_name) + "'");
  if (header.density_version != expected.density_version)
    fail(source, "density '" + header.density_name + "' data of version " +
                     std::to_string(header.density_version) + ", this build reads version " +
                     std::to_string(expected.density_version));

  const std::uint64_t n = header.nodes, triangles = header.triangles;
  Parts parts;
  parts.triangle_count = triangles;
  const std::byte* at = buffer.data() + kSavedTreeHeaderSize;
  parts.root_volume = {at, static_cast<std::size_t>(header.root_volume_size)};
  at += header.root_volume_size;
  parts.nodes.resize(n);
  std::memcpy(parts.nodes.data(), at, n * sizeof(TreeNode));
  at += n * sizeof(TreeNode);
  parts.volumes = {at, static_cast<std::size_t>(n * header.volume_size)};
  at += n * header.volume_size;
  if (header.has_triangle_ids) {
    parts.triangle_ids.resize(triangles);
    std::memcpy(parts.triangle_ids.data(), at, triangles * sizeof(std::uint32_t));
    at += triangles * sizeof(std::uint32_t);
  }
  parts.density = {at, static_cast<std::size_t>(header.density_bytes)};

  std::string problem;
  if (!valid_topology(parts.nodes, triangles, problem)) fail(source, "bad topology: " + problem);
  if (header.has_triangle_ids && !is_permutation_of_range(parts.triangle_ids))
    fail(source, "the triangle ids are not a permutation of 0.." + std::to_string(triangles - 1));
  return parts;
}

std::vector<std::byte> read_file(const std::filesystem::path& path) {
  try {
    return file_io::read_all(path);
  } catch (const file_io::FileError& e) {
    fail(path.string(), e.problem());
  }
}

void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  try {
    file_io::write_atomically(path, bytes);
  } catch (const file_io::FileError& e) {
    fail(path.string(), e.problem());
  }
}

}  // namespace bvhlab::saved_tree_detail

namespace bvhlab {

std::string TreeUnits::describe() const {
  if (!normalized) return "the mesh file's units";
  char text[160];
  std::snprintf(text, sizeof text, "normalised: scale %.6g, centre (%.6g, %.6g, %.6g)", scale, centre.x(),
                centre.y(), centre.z());
  return text;
}

TreeUnits saved_tree_units(std::span<const std::byte> buffer, std::string_view source) {
  return saved_tree_detail::read_header(buffer, source).units;
}

}  // namespace bvhlab
