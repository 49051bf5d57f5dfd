// Point clouds as objects: the data, its validation, loading (PLY, XYZ) and deterministic sampling from
// meshes. A cloud is what Bvh<BV>::build(const PointCloud&) groups into leaves (bvh/bvh.hpp) and what a
// PointSurface (bvh/point_surface.hpp) turns into an implicit surface.
#pragma once

#include "mesh.hpp"

#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab {

/// Points with optional per-point normals and areas (empty vectors when absent, else one per point).
/// `areas[i]` is the surface area point i stands for (sampling fills it; see assign_knn_areas).
struct PointCloud {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<double> areas;
  std::string name;  ///< file stem or caller-given label

  [[nodiscard]] std::size_t size() const { return positions.size(); }
  [[nodiscard]] bool has_normals() const { return !normals.empty(); }
  [[nodiscard]] bool has_areas() const { return !areas.empty(); }
  [[nodiscard]] Box bounds() const {
    Box b;
    for (const Vec3& p : positions) b.extend(p);
    return b;
  }
};

/// A refused cloud or cloud file; the message names the file (or cloud) and the problem.
class PointCloudError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws PointCloudError naming the cloud and the first problem: no points; fewer than `min_points` points
/// (a kernel over k neighbours needs k + 1); a non-finite position, normal or area, or a negative area (with
/// its index); a coordinate beyond 1e15 (MeshPrecisionLimits, as for meshes); normals or areas whose count
/// differs from the points'; all points at one position.
void validate(const PointCloud& cloud, std::size_t min_points = 1);

/// Loads a cloud by extension:
/// - `.ply`: ascii, binary_little_endian or binary_big_endian. The element `vertex` must come first and
///   have float or double (or integer) properties x, y, z, optionally nx, ny, nz (all three or none); other
///   vertex properties are skipped. Later elements (faces, edges) are not read: a mesh PLY loads as the
///   cloud of its vertices.
/// - `.xyz`: text, one point per line, 3 numbers (x y z) or 6 (x y z nx ny nz), the same count on every
///   line; blank lines and lines starting with '#' are skipped.
/// The result is validated (validate(cloud)). Throws PointCloudError naming the file and the problem (for
/// text, the line number): an unreadable file, an unknown extension, a bad header, a truncated body, a
/// line that is not 3 or 6 numbers.
PointCloud load_point_cloud(const std::filesystem::path& path);
/// The same from text in memory; `format` is "ply" or "xyz"; `name` is used in messages.
PointCloud load_point_cloud_from_memory(std::span<const std::byte> bytes, std::string_view format,
                                        std::string_view name = "<memory>");

/// Whether `path` holds a point cloud rather than a mesh: an .xyz file, or a PLY whose header declares no
/// faces (no face element, or one of 0 faces). Reads only the header; false for any other file and for a PLY
/// whose header cannot be read in its first 64 KiB (the mesh loader then names the problem).
bool is_point_cloud_file(const std::filesystem::path& path);
/// Writes an ascii PLY of the positions (and normals when present).
void save_point_cloud_ply(const PointCloud& cloud, const std::filesystem::path& path);

/// The total area of the mesh's triangles: what sample_uniform's points share (each the area / n), and
/// the square of the point spacing times n.
double surface_area(const Mesh& mesh);

/// `n` points uniform by area on the mesh: a triangle chosen with probability proportional to its area, a
/// uniform point in it, the triangle's normal (right-hand rule of its indices). Each point's area is the
/// mesh's area / n. The same for a seed on every platform (own integer generator, no std distributions).
/// Throws std::invalid_argument for n == 0 or a mesh of zero area.
PointCloud sample_uniform(const Mesh& mesh, std::size_t n, std::uint64_t seed);

/// `n` points whose density grows linearly along the mesh's longest bounding-box axis, from 1 at the low
/// end to `ratio` times that at the high end (rejection from the uniform sampling), with the triangles'
/// normals. Areas are left empty: the density is not known per point, estimate it with assign_knn_areas.
/// Deterministic like sample_uniform. Throws std::invalid_argument for n == 0, ratio < 1 or not finite, a
/// mesh of zero area.
PointCloud sample_varying(const Mesh& mesh, std::size_t n, std::uint64_t seed, double ratio = 4.0);

/// Per point, the distance to its k-th nearest other point (CGAL's k-neighbour search on a kd-tree).
/// Throws PointCloudError for an invalid cloud or fewer than k + 1 points, std::invalid_argument for k == 0.
std::vector<double> kth_neighbour_distances(std::span<const Vec3> points, std::size_t k);

/// Sets each point's area to pi r_k^2 / k, r_k its k-th neighbour distance: on a surface sampled with
/// local density rho the disc of radius r_k holds about k points, so pi r_k^2 / k estimates 1 / rho (the
/// unbiased one for a Poisson sampling of a flat surface). Points at a surface's open border see half a disc
/// and get up to twice their share. Throws as kth_neighbour_distances.
void assign_knn_areas(PointCloud& cloud, std::size_t k = 10);

}  // namespace bvhlab
