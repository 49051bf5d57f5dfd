// glTF input, checked and reduced to what the loader reads, before assimp sees it. Internal to the loader
// (bvh/io/mesh_load.cpp); declared here so that it can be read and tested on its own.
//
// Why: assimp 5.2's glTF importer trusts the file. A line loop whose first segment has a bad index makes it
// dereference null (found by tests/fuzz), a triangle fan of two indices writes past its face array, an
// accessor's byteOffset lets it read past its buffer, deep JSON overflows its recursive parser, and skins and
// animations index arrays with counts it never compares. Rather than chase each of these, the loader hands
// assimp a new glTF holding only the default scene's node trees, their meshes' positions and indices, and the
// accessors, buffer views and buffers those use, each checked against the glTF 2.0 rules first.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab::detail {

/// A glTF input the loader refuses; what() names the problem (the caller adds the source).
class GltfRefused : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Limits of the reduced glTF, beyond the glTF 2.0 rules.
struct GltfLimits {
  /// JSON nesting: glTF needs about 8 levels; assimp's JSON parser recurses once per level.
  static constexpr int max_json_depth = 64;
  /// Node tree depth: assimp builds its scene graph recursively, one call per level.
  static constexpr std::size_t max_node_depth = 256;
};

struct ReducedGltf {
  std::string bytes;                  ///< a glTF 2.0 file (JSON text, or GLB) with only what the loader reads
  std::string format;                 ///< "gltf" or "glb": the format hint for assimp
  std::vector<std::string> warnings;  ///< primitives left out, for the load report
  std::size_t dropped_line_segments = 0;  ///< segments of the line loops and strips left out
};

/// `input` reduced as described above when it is glTF: a GLB when `format` is "glb" (as assimp decides), else
/// any input whose first non-blank character is '{' (assimp tries JSON input as glTF whatever its name).
/// nullopt for other input. `asset_directory` is where a file's external buffers are looked up (prefixed to
/// their URI as assimp does, so with a trailing separator, or empty for the working directory); nullopt for
/// input from memory, whose external buffers are refused. Throws GltfRefused naming the problem.
std::optional<ReducedGltf> reduce_gltf(std::string_view input, std::string_view format,
                                       const std::optional<std::string>& asset_directory);

}  // namespace bvhlab::detail
