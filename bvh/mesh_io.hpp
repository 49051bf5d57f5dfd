// Mesh loading (anything assimp reads), validation, and the benchmark normalisation.
#pragma once

#include "bvh/mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Thrown for any input the library refuses; what() names the file and the problem.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What the loader saw, for reports and the `info` command.
struct LoadReport {
  std::string source;                  ///< file path or caller-given name
  std::size_t submeshes = 0;           ///< merged into one Mesh
  std::size_t input_vertices = 0;      ///< before identical vertices were joined
  std::size_t degenerate_triangles = 0;///< zero area: kept (they can still touch), counted here
  Box bounds;
  std::vector<std::string> warnings;   ///< e.g. coordinates too large for the query precision
};

struct LoadedMesh {
  Mesh mesh;
  LoadReport report;
};

/// Loads and validates a mesh file; throws MeshError.
LoadedMesh load_mesh(const std::filesystem::path& path);
/// Same from a memory buffer; `format_hint` is a file extension such as "obj" or "ply".
LoadedMesh load_mesh_from_memory(std::span<const std::byte> buffer, std::string_view format_hint,
                                 std::string_view name = "<memory>");

/// The protocol normalisation (ADB-METHOD.md section 4): bounding-box centre to the origin, uniform scale
/// so the longest bounding-box side is 2. Returns the applied scale. Throws MeshError on an empty or flat-zero mesh.
double normalize_to_unit_cube(Mesh& mesh);

}  // namespace bvhlab
