#include "mesh_sequence.hpp"

#include "deform.hpp"
#include "mesh_io.hpp"

#include <stdexcept>

namespace bvhlab {

MeshSequence::MeshSequence(std::vector<std::filesystem::path> files) : files_(std::move(files)) {
  if (files_.empty()) throw MeshError("mesh sequence: no files given");
  first_ = load_mesh(files_.front()).mesh;
}

Mesh MeshSequence::frame(std::size_t i) const {
  if (i >= files_.size())
    throw std::out_of_range("mesh sequence: frame " + std::to_string(i) + " of " + std::to_string(size()));
  if (i == 0) return first_;
  Mesh mesh = load_mesh(files_[i]).mesh;
  try {
    check_same_topology(first_, mesh, files_[i].string());
  } catch (const std::invalid_argument& e) {
    throw MeshError(std::string(e.what()) + " (first frame: " + files_.front().string() + ")");
  }
  return mesh;
}

std::vector<Mesh> load_mesh_sequence(const std::vector<std::filesystem::path>& files) {
  const MeshSequence sequence(files);
  std::vector<Mesh> frames;
  frames.reserve(sequence.size());
  for (std::size_t i = 0; i < sequence.size(); ++i) frames.push_back(sequence.frame(i));
  return frames;
}

}  // namespace bvhlab
