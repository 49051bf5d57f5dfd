// bvhlab.PointCloud: points with optional normals and areas, from numpy arrays, a PLY or XYZ file, or sampled
// from a mesh (bvh/point_cloud.hpp); the library validates them (PointCloudError, a ValueError).
#include "python/bindings.hpp"

#include <cmath>

namespace bvhlab::python {

namespace {

/// The arrays as a cloud, checked by the library (validate: finite, counts, areas >= 0, not one position).
UnitCloud cloud_from_arrays(const py::object& points, const py::object& normals, const py::object& areas,
                            const std::string& name) {
  UnitCloud cloud;  // in its own units
  cloud.name = name.empty() ? "points" : name;
  cloud.positions = vec3_rows(points, "points");
  if (!normals.is_none()) cloud.normals = vec3_rows(normals, "normals");
  if (!areas.is_none()) {
    const auto a = real_array(areas, "areas", {-1}, "(N,)");
    cloud.areas.assign(a.data(), a.data() + a.shape(0));
  }
  validate(cloud);
  return cloud;
}

UnitCloud load_unit_cloud(const py::object& file) {
  const std::filesystem::path path = path_argument(file, "PointCloud.load");
  require_file(path, "PointCloud.load");
  UnitCloud cloud;  // in the file's units
  py::gil_scoped_release release;
  static_cast<PointCloud&>(cloud) = load_point_cloud(path);
  return cloud;
}

/// sample_uniform (areas: the mesh's area / count), or with `ratio` sample_varying and k-NN areas.
UnitCloud sample(const UnitMesh& mesh, long long count, long long seed, const py::object& ratio,
                 long long k) {
  if (count < 1) throw py::value_error("count must be >= 1");
  if (seed < 0) throw py::value_error("seed must be >= 0");
  if (k < 1) throw py::value_error("k must be >= 1");
  const bool varying = !ratio.is_none();
  const double varying_ratio = varying ? py::cast<double>(ratio) : 0.0;
  UnitCloud cloud;
  cloud.units = mesh.units;  // the sampled points are in the mesh's units
  py::gil_scoped_release release;
  if (varying) {
    static_cast<PointCloud&>(cloud) = sample_varying(mesh, static_cast<std::size_t>(count),
                                                     static_cast<std::uint64_t>(seed), varying_ratio);
    assign_knn_areas(cloud, static_cast<std::size_t>(k));
  } else {
    static_cast<PointCloud&>(cloud) =
        sample_uniform(mesh, static_cast<std::size_t>(count), static_cast<std::uint64_t>(seed));
  }
  return cloud;
}

void save(const UnitCloud& cloud, const py::object& file) {
  const std::filesystem::path path = path_argument(file, "PointCloud.save");
  py::gil_scoped_release release;
  save_point_cloud_ply(cloud, path);
}

}  // namespace

void bind_points(py::module_& m) {
  py::class_<UnitCloud>(
      m, "PointCloud",
      "Points (N x 3) with optional unit normals (N x 3) and areas (N: the surface area each "
      "point stands for, which the ADB density counts). A bvhlab.Tree is built over it like "
      "over a mesh; queries then test the clouds' implicit surfaces at the leaves.")
      .def(py::init(&cloud_from_arrays), py::arg("points"), py::arg("normals") = py::none(),
           py::arg("areas") = py::none(), py::arg("name") = "",
           "Checks the arrays: finite (N, 3) points, normals of the same shape, areas (N,) >= 0, not all "
           "points at one position.")
      .def_static("load", &load_unit_cloud, py::arg("path"),
                  "Reads a PLY (the vertex element: x, y, z and optionally nx, ny, nz) or XYZ file (3 or 6 "
                  "numbers a line); raises PointCloudError naming the file and the problem.")
      .def_static("sample", &sample, py::arg("mesh"), py::arg("count"), py::kw_only(), py::arg("seed") = 1,
                  py::arg("ratio") = py::none(), py::arg("k") = 10,
                  "count points on `mesh`'s surface, the same for a seed on every platform, normals from "
                  "the triangles: uniform by area (each point's area the mesh's area / count), or with ratio "
                  "(>= 1) denser along the longest axis, from 1 to ratio, areas from each point's k-th "
                  "nearest neighbour. The cloud is in the mesh's units.")
      .def_property_readonly(
          "points", [](const UnitCloud& c) { return vec3_array(c.positions); },
          "(N, 3) float64 array (a copy)")
      .def_property_readonly(
          "normals",
          [](const UnitCloud& c) -> py::object {
            if (!c.has_normals()) return py::none();
            return vec3_array(c.normals);
          },
          "(N, 3) float64 array (a copy), or None")
      .def_property_readonly(
          "areas",
          [](const UnitCloud& c) -> py::object {
            if (!c.has_areas()) return py::none();
            return py::array_t<double>(static_cast<py::ssize_t>(c.areas.size()), c.areas.data());
          },
          "(N,) float64 array (a copy), or None")
      .def_readwrite("name", &PointCloud::name)
      .def_property_readonly(
          "units", [](const UnitCloud& c) { return units_dict(c.units); },
          "its mesh's units when sampled from one; else the coordinates as given")
      .def(
          "assign_knn_areas",
          [](UnitCloud& c, long long k) {
            if (k < 1) throw py::value_error("k must be >= 1");
            assign_knn_areas(c, static_cast<std::size_t>(k));
          },
          py::arg("k") = 10,
          "Sets each point's area from the distance to its k-th nearest neighbour (pi r^2 / k), for clouds "
          "without areas (scans, varying densities).")
      .def("save", &save, py::arg("path"),
           "Writes an ascii PLY of the points and their normals, if any (not the areas).")
      .def("__len__", [](const UnitCloud& c) { return c.size(); })
      .def("__repr__", [](const UnitCloud& c) {
        return "<bvhlab.PointCloud '" + c.name + "': " + std::to_string(c.size()) + " points" +
               (c.has_normals() ? ", normals" : "") + (c.has_areas() ? ", areas" : "") + ">";
      });
}

}  // namespace bvhlab::python
