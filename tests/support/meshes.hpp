// Where tests find real meshes: bundled ones in the source tree, fetched ones in the mesh cache.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace bvhlab::testing {

namespace detail {
// A missing mesh is a broken setup, never a skip: throwing fails the calling test with this message.
inline std::filesystem::path mesh_in(const char* env_var, const std::string& name, const std::string& hint) {
  const char* dir = std::getenv(env_var);
  if (dir == nullptr || *dir == '\0')
    throw std::runtime_error(std::string(env_var) + " is not set, so mesh '" + name +
                             "' cannot be found (run the test through ctest, which sets it)");
  std::filesystem::path path = std::filesystem::path(dir) / name;
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("mesh '" + name + "' not found at " + path.string() + hint);
  return path;
}
}  // namespace detail

/// A mesh committed under meshes/ (pinion.off, jeep1.ms3d, teapot.obj), via $BVHLAB_SOURCE_DIR.
inline std::filesystem::path bundled_mesh(const std::string& name) {
  const std::filesystem::path path = detail::mesh_in("BVHLAB_SOURCE_DIR", "meshes/" + name, "");
  return path;
}

/// A mesh fetched by meshes/fetch.sh into $BVHLAB_MESH_CACHE. The test must be registered with
/// `bvhlab_add_test(... NEEDS_MESHES)` so ctest runs the `fetch_meshes` fixture first.
inline std::filesystem::path fetched_mesh(const std::string& name) {
  return detail::mesh_in("BVHLAB_MESH_CACHE", name,
                         " (was the test registered with NEEDS_MESHES? fetch by hand with meshes/fetch.sh "
                         "<cache dir> " +
                             name + ")");
}

}  // namespace bvhlab::testing
