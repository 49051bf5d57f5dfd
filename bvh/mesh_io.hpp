// Mesh loading (anything assimp reads), validation, and the benchmark normalisation.
#pragma once

#include "mesh.hpp"

#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Thrown for any input the library refuses; what() is "<file or name>: <problem>".
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Precision limits the loader enforces (see load_mesh).
struct MeshPrecisionLimits {
  /// Coordinates beyond this are refused: there a double's spacing exceeds 0.1, so even unit-sized features
  /// are no longer representable.
  static constexpr double max_abs_coordinate = 1e15;
  /// A bounding-box diagonal below this (or zero) is refused: the model has no usable size.
  static constexpr double min_diagonal = 1e-300;
  /// Warn when max|coordinate| / diagonal exceeds this. assimp (as Debian builds it) reads coordinates into
  /// 32-bit floats before they become doubles, rounding each by up to 2^-24 of its magnitude: beyond a
  /// ratio of 100 that loses more than ~6e-6 of the model's size. With a double-precision assimp the bound
  /// is 1e6 (loss ~1e-10 of the size, close to what the exact queries resolve).
  static constexpr double warn_offset_ratio_float_reader = 100;
  static constexpr double warn_offset_ratio_double_reader = 1e6;
};

/// What the loader saw, for reports and the `info` command.
struct LoadReport {
  std::string source;              ///< file path or caller-given name
  std::size_t submeshes = 0;       ///< sub-mesh instances (after node instancing) merged into one Mesh
  std::size_t input_vertices = 0;  ///< vertices used by triangles, before identical ones were joined
  std::size_t degenerate_triangles =
      0;                           ///< repeated vertex or exactly collinear: kept (they can still touch)
  std::size_t ignored_points = 0;  ///< point primitives: not part of a triangle mesh, dropped
  std::size_t ignored_lines = 0;   ///< line primitives: dropped likewise
  Box bounds;
  std::vector<std::string> warnings;  ///< e.g. coordinates too large for the query precision, assimp warnings
};

struct LoadedMesh {
  Mesh mesh;
  LoadReport report;
};

/// Loads and validates a mesh file in one of the formats the loader checks before assimp reads it: OBJ, PLY,
/// STL, OFF, MS3D, glTF 2 and GLB. The file extension names the format when it is one of these, else the
/// content does; assimp reads the input with that format's importer only (its others are not used).
/// All sub-meshes are merged with their scene-graph transforms applied, polygons triangulated, vertices with
/// exactly equal positions joined (across sub-meshes too), point and line primitives dropped and counted.
/// Mesh::name is the file stem. Coordinates pass through assimp's float (ai_real) before becoming double.
/// glTF 2.0 (text or GLB) is checked and reduced before assimp reads it (bvh/gltf_reduce.hpp): only the
/// default scene's node trees and their meshes' float positions and unsigned indices are read; skins,
/// animations, morph targets and materials are not; line loops and strips are left out like other lines;
/// files needing what that leaves out (sparse or compressed data, glTF 1, unknown required extensions) are
/// refused.
/// Throws MeshError for: a missing, unreadable or empty file; an unknown format; any assimp failure; no
/// triangles; a NaN or infinite coordinate; an out-of-range index (also when assimp only logs it and
/// substitutes another vertex); coordinates beyond MeshPrecisionLimits; a zero-size model.
LoadedMesh load_mesh(const std::filesystem::path& path);
/// Same from a memory buffer; `format_hint` is a file extension such as "obj" or "ply" (leading dot allowed).
/// Mesh::name is the stem of `name`. Formats that refer to side files (OBJ's .mtl, glTF's .bin) cannot
/// resolve them from memory: a glTF buffer in a side file is refused.
LoadedMesh load_mesh_from_memory(std::span<const std::byte> buffer, std::string_view format_hint,
                                 std::string_view name = "<memory>");

/// The protocol normalisation (adb/README.md, section 4): bounding-box centre to the origin, uniform scale
/// so the longest bounding-box side is 2. Returns the applied scale. Throws MeshError on an empty mesh, a
/// non-finite coordinate or a zero-size bounding box.
double normalize_to_unit_cube(Mesh& mesh);

}  // namespace bvhlab
