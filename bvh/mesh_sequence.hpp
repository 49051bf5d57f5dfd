// A deforming mesh given as one mesh file per frame, every frame with the first frame's topology.
#pragma once

#include "mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <vector>

namespace bvhlab {

/// The frames of a deforming mesh from a list of files (any format load_mesh reads). The first file is
/// loaded at once and fixes the topology; frame(i) loads file i and refuses it unless it has the same vertex
/// count and triangle indices and only finite vertices. Note that the loader joins vertices with exactly
/// equal positions, so a frame where two vertices coincide has fewer vertices and is refused too.
class MeshSequence {
 public:
  /// Throws MeshError for an empty list or a first file that does not load.
  explicit MeshSequence(std::vector<std::filesystem::path> files);

  [[nodiscard]] std::size_t size() const { return files_.size(); }
  [[nodiscard]] const std::filesystem::path& file(std::size_t i) const { return files_.at(i); }
  /// The first frame, which fixes the topology.
  [[nodiscard]] const Mesh& first() const { return first_; }
  /// Loads frame i (0 returns the first frame). Throws MeshError "<file>: <difference>" for a frame that does
  /// not load or whose vertex count, triangle indices (the first differing triangle named) or vertices (a
  /// non-finite one named) do not fit the first frame, and std::out_of_range for i >= size().
  [[nodiscard]] Mesh frame(std::size_t i) const;

 private:
  std::vector<std::filesystem::path> files_;
  Mesh first_;
};

/// Every frame of a sequence, loaded and checked (convenience for short sequences).
std::vector<Mesh> load_mesh_sequence(const std::vector<std::filesystem::path>& files);

}  // namespace bvhlab
