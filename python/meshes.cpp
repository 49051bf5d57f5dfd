// bvhlab.Mesh: from numpy arrays (checked here) or from a file (the library's loader and its checks).
#include "bvh/mesh_io.hpp"
#include "engine/mesh_catalog.hpp"
#include "python/bindings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace bvhlab::python {

namespace {

std::vector<Vec3> vertices_from(const py::handle& value) {
  const auto array = real_array(value, "vertices", {-1, 3}, "(N, 3)");
  const double* xyz = array.data();
  if (array.shape(0) > py::ssize_t{std::numeric_limits<std::uint32_t>::max()})
    throw py::value_error("vertices: more than 2^32-1 vertices");
  std::vector<Vec3> out(static_cast<std::size_t>(array.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    if (!out[i].allFinite())
      throw py::value_error("vertices[" + std::to_string(i) + "] has a NaN or infinite coordinate");
    if (out[i].cwiseAbs().maxCoeff() > MeshPrecisionLimits::max_abs_coordinate)
      throw py::value_error("vertices[" + std::to_string(i) +
                            "]: a coordinate beyond 1e15 (the queries' precision "
                            "ends there)");
  }
  return out;
}

/// Indices of any integer dtype, each checked against the vertex count.
template <class Int>
std::vector<TriangleIndices> indices_from(const py::array& array, std::size_t vertices) {
  const auto ints = py::array_t<Int, py::array::c_style | py::array::forcecast>::ensure(array);
  const Int* data = ints.data();
  std::vector<TriangleIndices> out(static_cast<std::size_t>(ints.shape(0)));
  for (std::size_t t = 0; t < out.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const Int index = data[3 * t + k];
      bool negative = false;
      if constexpr (std::is_signed_v<Int>) negative = index < 0;
      if (negative || static_cast<std::uint64_t>(index) >= vertices)
        throw py::value_error("triangles[" + std::to_string(t) + ", " + std::to_string(k) +
                              "] = " + std::to_string(index) + " is out of range (the mesh has " +
                              std::to_string(vertices) + " vertices)");
      out[t][k] = static_cast<std::uint32_t>(index);
    }
  return out;
}

std::vector<TriangleIndices> triangles_from(const py::handle& value, std::size_t vertices) {
  const py::array array = py::array::ensure(value);
  if (!array) throw py::type_error("triangles: expected an integer array");
  const char kind = array.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("triangles: expected integer vertex indices, got dtype " +
                         std::string(py::str(array.dtype())));
  if (array.ndim() != 2 || array.shape(1) != 3)
    throw py::value_error("triangles: expected shape (M, 3), got " +
                          std::string(py::str(py::tuple(array.attr("shape")))));
  if (array.shape(0) == 0) throw py::value_error("triangles: the mesh has no triangles");
  return kind == 'i' ? indices_from<std::int64_t>(array, vertices)
                     : indices_from<std::uint64_t>(array, vertices);
}

UnitMesh mesh_from_arrays(const py::object& vertices, const py::object& triangles, const std::string& name) {
  UnitMesh mesh;  // in its own units
  mesh.name = name;
  mesh.vertices = vertices_from(vertices);
  mesh.triangles = triangles_from(triangles, mesh.vertices.size());
  Box used;  // the loader's zero-size rule, over the vertices the triangles use
  for (const TriangleIndices& t : mesh.triangles)
    for (std::uint32_t v : t) used.extend(mesh.vertices[v]);
  if (!(used.extent().norm() >= MeshPrecisionLimits::min_diagonal))
    throw py::value_error("the model has zero size: all triangle vertices coincide");
  return mesh;
}

/// A file, or else a mesh of the catalog (bundled meshes/, the fetched-mesh cache), as the CLI resolves it.
std::filesystem::path resolve_mesh(const py::handle& argument) {
  const std::filesystem::path path = path_argument(argument, "load_mesh");
  if (std::filesystem::is_regular_file(path)) return std::filesystem::absolute(path);
  if (auto found = find_mesh(path.filename().string())) return *found;
  require_file(path,
               "load_mesh (neither a file nor a mesh of the catalog: bundled meshes/ or the mesh cache)");
  return path;
}

UnitMesh load_unit_mesh(const py::object& argument, bool normalize, double scale) {
  if (!std::isfinite(scale) || scale <= 0) throw py::value_error("scale must be finite and positive");
  const std::filesystem::path path = resolve_mesh(argument);
  LoadedMesh loaded = [&] {
    py::gil_scoped_release release;
    return load_mesh(path);
  }();
  for (const std::string& warning : loaded.report.warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, (path.string() + ": " + warning).c_str(), 1) != 0)
      throw py::error_already_set();
  UnitMesh mesh;
  static_cast<Mesh&>(mesh) = std::move(loaded.mesh);
  if (normalize) mesh.units.file = normalize_mesh(mesh);
  if (scale != 1)
    for (Vec3& v : mesh.vertices) v *= scale;
  mesh.units.scaled_by = scale;
  return mesh;
}

/// Normalising twice changes nothing; a scaled mesh is refused, as its units would be neither the file's nor
/// the normalisation.
UnitMesh normalized(UnitMesh mesh) {
  if (mesh.units.scaled_by != 1)
    throw py::value_error("Mesh.normalized: the mesh is in " + mesh.units.describe() +
                          "; normalise before scaling: load_mesh(path, normalize=True, scale=...)");
  if (!mesh.units.file.normalized) mesh.units.file = normalize_mesh(mesh);
  return mesh;
}

py::array_t<std::int64_t> triangle_array(const UnitMesh& mesh) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
  std::int64_t* data = out.mutable_data();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) data[3 * t + k] = mesh.triangles[t][k];
  return out;
}

}  // namespace

py::dict units_dict(const MeshUnits& units) {
  const Vec3& c = units.file.centre;
  return py::dict(py::arg("normalized") = units.file.normalized, py::arg("scale") = units.file.scale,
                  py::arg("centre") = py::make_tuple(c.x(), c.y(), c.z()),
                  py::arg("scaled_by") = units.scaled_by, py::arg("description") = units.describe());
}

void bind_meshes(py::module_& m) {
  const char* units_help =
      "The units of the coordinates, a dict: normalized (the protocol normalisation x' = (x - centre) * "
      "scale "
      "of the file's coordinates x), scale and centre (1 and 0 unless normalised), scaled_by (load_mesh's "
      "scale, applied after; a saved tree cannot record it) and description.";
  py::class_<UnitMesh>(m, "Mesh",
                       "A triangle mesh: vertices (N x 3, float64) and triangles (M x 3 vertex indices).")
      .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("triangles"), py::arg("name") = "",
           "Checks the arrays: an (N, 3) array of finite real numbers and an (M, 3) integer array of indices "
           "below N, M >= 1, the triangles not all in one point.")
      .def_property_readonly(
          "vertices", [](const UnitMesh& mesh) { return vec3_array(mesh.vertices); },
          "(N, 3) float64 array (a copy)")
      .def_property_readonly("triangles", &triangle_array, "(M, 3) int64 array (a copy)")
      .def_readwrite("name", &Mesh::name)
      .def_property_readonly("vertex_count", [](const UnitMesh& mesh) { return mesh.vertices.size(); })
      .def_property_readonly("triangle_count", &Mesh::triangle_count)
      .def_property_readonly(
          "bounds",
          [](const UnitMesh& mesh) {
            const Box b = mesh.bounds();
            py::array_t<double> out({2, 3});
            for (int k = 0; k < 3; ++k) {
              out.mutable_at(0, k) = b.min(k);
              out.mutable_at(1, k) = b.max(k);
            }
            return out;
          },
          "(2, 3) array: the bounding box's min and max corners")
      .def_property_readonly(
          "units", [](const UnitMesh& mesh) { return units_dict(mesh.units); }, units_help)
      .def("normalized", &normalized,
           "A copy with the protocol normalisation (bounding-box centre at the origin, longest side 2), its "
           "units "
           "recorded; a mesh already normalised is returned as it is, a scaled one refused.")
      .def("__repr__", [](const UnitMesh& mesh) {
        return "<bvhlab.Mesh '" + mesh.name + "': " + std::to_string(mesh.vertices.size()) + " vertices, " +
               std::to_string(mesh.triangles.size()) + " triangles>";
      });

  m.def(
      "load_mesh", &load_unit_mesh, py::arg("path"), py::arg("normalize") = false, py::arg("scale") = 1.0,
      "Loads a mesh file (OBJ, PLY, STL, OFF, MS3D, glTF 2, GLB) with the library's checks; a name that is "
      "no "
      "file is looked up in the mesh catalog (bundled meshes/, the fetched-mesh cache). The file's own "
      "coordinates are kept unless normalize=True (the protocol normalisation: centre at the origin, longest "
      "side 2); then the vertices are multiplied by scale. Both are recorded in the mesh's units. Raises "
      "bvhlab.MeshError for a file the loader "
      "refuses.");
}

}  // namespace bvhlab::python
