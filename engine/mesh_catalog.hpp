// Finds the project's meshes by name (bundled ones in meshes/, fetched ones in the mesh cache), and the
// protocol normalisation as every run applies it.
#pragma once

#include "adb/saved_tree.hpp"
#include "bvh/mesh.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace bvhlab {

/// Looks for `file_name` in $BVHLAB_MESH_CACHE, the build's mesh cache, and the source tree's meshes/.
std::optional<std::filesystem::path> find_mesh(const std::string& file_name);

/// Loads a mesh found by find_mesh and applies the protocol normalisation; throws if it is missing.
Mesh load_protocol_mesh(const std::string& file_name);

/// Applies the protocol normalisation (centre at the origin, longest side 2) and returns the units, as saved
/// trees record them. Throws MeshError as normalize_to_unit_cube does.
TreeUnits normalize_mesh(Mesh& mesh);

}  // namespace bvhlab
