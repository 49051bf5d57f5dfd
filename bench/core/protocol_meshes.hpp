// The benchmarks' loop over their --meshes: each found mesh loaded as the protocol scales it (engine/
// mesh_catalog.hpp), with the label its benchmarks are named by; a mesh not found is skipped, said on stderr.
// And the check of their --volumes against the registry.
#pragma once

#include "engine/mesh_catalog.hpp"
#include "engine/policies.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

/// Calls register_mesh(label, mesh) per found mesh of `files` (label: the file's stem); `program` names the
/// benchmark in the line that skips a missing one.
template <class RegisterMesh>
void for_each_protocol_mesh(const char* program, const std::vector<std::string>& files,
                            RegisterMesh&& register_mesh) {
  for (const std::string& file : files) {
    if (!find_mesh(file)) {
      std::fprintf(stderr, "%s: skipping %s (not found; run meshes/fetch.sh)\n", program, file.c_str());
      continue;
    }
    const auto mesh = std::make_shared<const Mesh>(load_protocol_mesh(file));
    register_mesh(std::filesystem::path(file).stem().string(), mesh);
  }
}

/// False, after a line on stderr naming the known ones, when `volumes` holds a name the registry does not
/// know.
inline bool volumes_known(const char* program, const std::vector<std::string>& volumes) {
  for (const auto& v : volumes) {
    try {
      (void)wide_layout_refusal(v);  // throws for a name the registry does not know
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "%s: --volumes: %s\n", program, e.what());
      return false;
    }
  }
  return true;
}

}  // namespace bvhlab
