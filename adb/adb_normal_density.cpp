#include "adb/adb_normal_density.hpp"

#include <Eigen/Eigenvalues>

#include <array>
#include <bit>
#include <cstring>
#include <stdexcept>

namespace bvhlab {
namespace {

// The six distinct entries of a symmetric 3x3 matrix, summed over a prefix of the triangles.
using Moments = std::array<double, 6>;

Moments normal_moments(const TrianglePoints& t) {
  const Vec3 cross = (t[1] - t[0]).cross(t[2] - t[0]);
  const double twice_area = cross.norm();
  if (!(twice_area > 0) || !std::isfinite(twice_area)) return {};
  const Vec3 n = cross / twice_area;
  const double area = 0.5 * twice_area;
  return {area * n.x() * n.x(), area * n.x() * n.y(), area * n.x() * n.z(),
          area * n.y() * n.y(), area * n.y() * n.z(), area * n.z() * n.z()};
}

NodeOrientation orientation_of(const Moments& m) {
  Mat3 matrix;
  matrix << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
  const double total = matrix.trace();
  if (!(total > 0)) return {};
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(matrix);
  const Vec3 l = solver.eigenvalues();  // ascending
  NodeOrientation out;
  out.axis = solver.eigenvectors().col(2).normalized().cast<float>();
  out.flatness = static_cast<float>(std::clamp((l[2] - 0.5 * (l[0] + l[1])) / total, 0.0, 1.0));
  return out;
}

constexpr std::size_t kOrientationBytes = 16;

void put_float(std::vector<std::byte>& out, float value) {
  const auto bits = std::bit_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::byte>((bits >> (8 * i)) & 0xff));
}
float get_float(const std::byte* at) {
  std::uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) bits |= std::uint32_t(std::to_integer<std::uint8_t>(at[i])) << (8 * i);
  return std::bit_cast<float>(bits);
}

}  // namespace

std::vector<NodeOrientation> node_orientations(
    std::span<const std::pair<std::uint32_t, std::uint32_t>> ranges,
    std::span<const TrianglePoints> triangles) {
  std::vector<Moments> prefix(triangles.size() + 1, Moments{});
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Moments m = normal_moments(triangles[t]);
    for (int k = 0; k < 6; ++k) prefix[t + 1][k] = prefix[t][k] + m[k];
  }
  std::vector<NodeOrientation> out;
  out.reserve(ranges.size());
  for (const auto& [begin, end] : ranges) {
    if (begin > end || end > triangles.size())
      throw std::invalid_argument("adb_normal: a node's triangle range lies outside the tree's triangles");
    Moments m;
    for (int k = 0; k < 6; ++k) m[k] = prefix[end][k] - prefix[begin][k];
    out.push_back(orientation_of(m));
  }
  return out;
}

std::vector<std::byte> AdbNormalDensity::encode(const Storage& storage) {
  std::vector<std::byte> out = adb_storage::encode(storage.counts);
  out.reserve(out.size() + storage.orientation.size() * kOrientationBytes);
  for (const NodeOrientation& o : storage.orientation) {
    for (int k = 0; k < 3; ++k) put_float(out, o.axis[k]);
    put_float(out, o.flatness);
  }
  return out;
}

AdbNormalDensity::Storage AdbNormalDensity::decode(std::span<const std::byte> bytes, std::size_t node_count) {
  const std::size_t orientation_bytes = node_count * kOrientationBytes;
  if (bytes.size() < orientation_bytes)
    throw std::invalid_argument("adb_normal: " + std::to_string(bytes.size()) + " bytes of annotation for " +
                                std::to_string(node_count) + " nodes");
  Storage storage;
  storage.counts = adb_storage::decode(bytes.first(bytes.size() - orientation_bytes), node_count, name());
  const std::byte* at = bytes.data() + (bytes.size() - orientation_bytes);
  storage.orientation.resize(node_count);
  for (std::size_t i = 0; i < node_count; ++i, at += kOrientationBytes) {
    NodeOrientation& o = storage.orientation[i];
    o.axis = Eigen::Vector3f(get_float(at), get_float(at + 4), get_float(at + 8));
    o.flatness = get_float(at + 12);
    if (!o.axis.allFinite() || std::abs(o.axis.norm() - 1.0f) > 1e-3f ||
        !(o.flatness >= 0 && o.flatness <= 1))
      throw std::invalid_argument("adb_normal: node " + std::to_string(i) +
                                  " has an orientation that is not a unit axis with a flatness in [0, 1]");
  }
  return storage;
}

}  // namespace bvhlab
