// Internal to the mesh loader (bvh/io/), not installed: what its parts give one another. mesh_load.cpp runs a
// load: the checks of format_checks.cpp on the input, then assimp through assimp_import.cpp.
#pragma once

#include "bvh/mesh_io.hpp"

#include <string>
#include <string_view>

namespace bvhlab::io {

// The formats the loader reads: those whose input it checks before assimp does (format_checks.cpp and
// bvh/gltf_reduce.hpp) and that tests/fuzz covers.
inline constexpr std::string_view kReadFormats[] = {"obj", "ply", "stl", "off", "ms3d", "gltf", "glb"};
inline constexpr const char* kReadFormatList = "OBJ, PLY, STL, OFF, MS3D, glTF 2 and GLB";

/// Whether `text` starts with the PLY magic (either case), where every PLY check starts reading.
bool has_ply_magic(std::string_view text);
/// assimp 5.2's PLY reader never returns when the header ends without an `end_header` line (any truncated
/// header; found by tests/fuzz): whether `text` is PLY with such a header.
bool ply_header_unterminated(std::string_view text);
/// The format `bytes` are read as, one of kReadFormats. A hint naming a read format decides (assimp then
/// picks that importer by name alone); otherwise the content does, much as assimp would guess it. "" when it
/// is none of them.
std::string read_format(std::string_view bytes, const std::string& hint);
/// The first problem the per-format checks find in `bytes`, read as `format` (from read_format); "" when
/// none. Each check refuses what made assimp crash, hang or allocate without bound (found by tests/fuzz).
std::string input_problem(std::string_view bytes, const std::string& format);

/// What assimp reads: the file at `file` when that is set (so that side files such as OBJ's .mtl resolve),
/// else `bytes` from memory with `hint` naming their format.
struct AssimpInput {
  std::string_view bytes;
  std::string hint;
  std::string file;
};

/// Reads `input` with the importer(s) of `format` only, checks the scene and merges it into one welded mesh
/// (bvh/mesh_io.hpp, load_mesh). `source` names the input in messages and the report, `name` becomes
/// Mesh::name. Throws MeshError.
LoadedMesh import_with_assimp(const std::string& source, std::string name, std::string_view format,
                              const AssimpInput& input);

}  // namespace bvhlab::io
