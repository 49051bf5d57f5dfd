// The bvhlab Python module: meshes, trees, queries and scenes through the same registries and runner as the
// bvhlab command line. Errors of the library become Python exceptions: MeshError, SavedTreeError,
// SceneError and PointCloudError (all ValueError), std::invalid_argument as ValueError.
#include "adb/saved_tree.hpp"
#include "bench/run_scene.hpp"
#include "bvh/mesh_io.hpp"
#include "bvh/point_cloud.hpp"
#include "python/bindings.hpp"

PYBIND11_MODULE(bvhlab, m) {
  namespace py = pybind11;
  m.doc() =
      "bvhlab: collision detection between rigid triangle meshes and point clouds with bounding-volume "
      "hierarchies and ADB-trees.";
  m.attr("__version__") = BVHLAB_VERSION;
  py::register_exception<bvhlab::MeshError>(m, "MeshError", PyExc_ValueError);
  py::register_exception<bvhlab::SavedTreeError>(m, "SavedTreeError", PyExc_ValueError);
  py::register_exception<bvhlab::SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<bvhlab::PointCloudError>(m, "PointCloudError", PyExc_ValueError);
  bvhlab::python::bind_meshes(m);
  bvhlab::python::bind_points(m);
  bvhlab::python::bind_trees(m);
  bvhlab::python::bind_queries(m);
  bvhlab::python::bind_scenes(m);
}
