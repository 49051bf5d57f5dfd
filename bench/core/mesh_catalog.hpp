// Finds the project's meshes by name: bundled ones in meshes/, fetched ones in the mesh cache.
#pragma once

#include "bvh/mesh.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace bvhlab {

/// Looks for `file_name` in $BVHLAB_MESH_CACHE, the build's mesh cache, and the source tree's meshes/.
std::optional<std::filesystem::path> find_mesh(const std::string& file_name);

/// Loads a mesh found by find_mesh and applies the protocol normalisation; throws if it is missing.
Mesh load_protocol_mesh(const std::string& file_name);

}  // namespace bvhlab
