// A triangle mesh as plain arrays: the one input type of every builder and tool.
#pragma once

#include "../volumes/geometry.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace bvhlab {

using TriangleIndices = std::array<std::uint32_t, 3>;

struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<TriangleIndices> triangles;
  std::string name;  ///< file stem or caller-given label, used in reports

  [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
  [[nodiscard]] TrianglePoints triangle(std::size_t i) const {
    const auto& t = triangles[i];
    return {vertices[t[0]], vertices[t[1]], vertices[t[2]]};
  }
  [[nodiscard]] Box bounds() const {
    Box b;
    for (const auto& v : vertices) b.extend(v);
    return b;
  }
};

/// A fingerprint of a mesh's topology (vertex count and triangle indices, not positions): equal for two
/// frames of one deforming mesh. FNV-1a over the indices; not cryptographic.
inline std::uint64_t topology_fingerprint(const Mesh& mesh) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  auto mix = [&h](std::uint64_t word) {
    h ^= word;
    h *= 0x100000001b3ULL;
  };
  mix(mesh.vertices.size());
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t) mix(v);
  return h | 1;  // never 0, which stands for "unknown"
}

}  // namespace bvhlab
