// bvhlab.Tree: a tree of any registered bounding volume and density, built from a mesh (saved and loaded)
// or from a point cloud.
#include "engine/any_tree.hpp"
#include "python/bindings.hpp"

#include <atomic>
#include <chrono>
#include <functional>
#include <future>

namespace bvhlab::python {

namespace {

/// The checked arguments of a build: the density's parameters and the build options, `leaf` counting
/// triangles (a mesh) or points (a cloud).
struct BuildArguments {
  DensitySpec density;
  BuildOptions options;
};

BuildArguments build_arguments(const std::string& bv, const std::string& density, const std::string& split,
                               int leaf, const char* leaf_items, int threads, const py::kwargs& parameters) {
  if (leaf < 1 || leaf > 255)
    throw py::value_error(std::string("leaf: ") + leaf_items + " per leaf must lie in [1, 255]");
  if (threads < 0) throw py::value_error("threads must be >= 0 (0: all cores)");
  check_volume_name(bv);  // an unknown name fails before the density's checks
  BuildArguments out{density_spec(density, parameter_values(parameters)), {}};
  out.options.split = split_method_from_string(split);
  out.options.max_leaf_triangles = out.options.max_leaf_points = static_cast<std::uint32_t>(leaf);
  out.options.threads = static_cast<unsigned>(threads);
  return out;
}

/// Thrown from a build's progress callback once Python has a pending signal: it abandons the build.
struct BuildInterrupted {};

/// Runs `build(options)` on a worker thread without the GIL; every 50 ms takes the GIL back and lets Python
/// handle its signals. On Ctrl-C the build is told to stop at its next progress call, its tree is dropped
/// (nothing half-built returns) and KeyboardInterrupt is raised.
AnyTree build_interruptibly(BuildOptions options, const std::function<AnyTree(const BuildOptions&)>& build) {
  std::atomic<bool> stop = false;
  options.progress = [&stop](std::size_t, std::size_t) {
    if (stop.load(std::memory_order_relaxed)) throw BuildInterrupted{};
  };
  auto result = std::async(std::launch::async, [&] { return build(options); });
  bool interrupted = false;
  {
    py::gil_scoped_release release;
    while (result.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready) {
      py::gil_scoped_acquire acquire;
      if (PyErr_CheckSignals() != 0) {  // the KeyboardInterrupt stays set until it is raised below
        interrupted = true;
        break;
      }
    }
    stop = true;
    result.wait();
  }
  if (!interrupted) return result.get();
  try {
    (void)result.get();
  } catch (...) {  // BuildInterrupted, or whatever the build met first: Python's interrupt wins
  }
  throw py::error_already_set();
}

AnyTree build(const UnitMesh& mesh, const std::string& bv, const std::string& density,
              const std::string& split, int leaf, int threads, const py::kwargs& parameters) {
  const BuildArguments args = build_arguments(bv, density, split, leaf, "triangles", threads, parameters);
  return build_interruptibly(args.options, [&](const BuildOptions& options) {
    return AnyTree::build(mesh, bv, args.density, options);
  });
}

AnyTree build_from_points(const UnitCloud& cloud, const std::string& bv, const std::string& density,
                          const std::string& split, int leaf, int threads, const py::kwargs& parameters) {
  const BuildArguments args = build_arguments(bv, density, split, leaf, "points", threads, parameters);
  return build_interruptibly(args.options, [&](const BuildOptions& options) {
    return AnyTree::build_points(cloud, bv, args.density, options);
  });
}

AnyTree load_tree(const py::object& file, const UnitMesh* mesh) {
  const std::filesystem::path path = path_argument(file, "Tree.load");
  require_file(path, "Tree.load");
  py::gil_scoped_release release;
  return AnyTree::load(path, mesh);
}

void save(const AnyTree& tree, const py::object& file) {
  const std::filesystem::path path = path_argument(file, "Tree.save");
  const std::filesystem::path folder = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(folder)) {
    const std::string message = "Tree.save: no such folder: '" + folder.string() + "'";
    PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
    throw py::error_already_set();
  }
  py::gil_scoped_release release;
  tree.save(path);
}

std::string repr(const AnyTree& tree) {
  const TreeInfo& i = tree.info();
  if (i.points > 0)
    return "<bvhlab.Tree " + i.bv + ", " + i.annotation + ": " + std::to_string(i.points) + " points, " +
           std::to_string(i.nodes) + " nodes>";
  return "<bvhlab.Tree " + i.bv + ", " + i.annotation + ": " + std::to_string(i.triangles) + " triangles, " +
         std::to_string(i.nodes) + " nodes" + (i.polygons ? "" : ", without polygons") + ">";
}

}  // namespace

void bind_trees(py::module_& m) {
  auto info = [](auto member) { return [member](const AnyTree& t) { return t.info().*member; }; };
  py::class_<AnyTree>(m, "Tree",
                      "A bounding-volume hierarchy of one mesh or point cloud, of any registered bounding "
                      "volume, with or without a density annotation.")
      .def(py::init(&build), py::arg("mesh"), py::arg("bv") = "aabb", py::arg("density") = "none",
           py::kw_only(), py::arg("split") = "sah", py::arg("leaf") = 1, py::arg("threads") = 0,
           "Builds the tree of `mesh` with bounding volume `bv` (bvhlab.volumes()) and annotates it with "
           "`density` (bvhlab.policies()), whose parameters are keyword arguments (grid=2, tau=0.25). split: "
           "'sah' or 'median'; leaf: triangles per leaf at most; threads: 0 for all cores.")
      .def(py::init(&build_from_points), py::arg("cloud"), py::arg("bv") = "aabb",
           py::arg("density") = "none", py::kw_only(), py::arg("split") = "sah", py::arg("leaf") = 16,
           py::arg("threads") = 0,
           "Builds the tree of a bvhlab.PointCloud, with the cloud's implicit surface and the nodes' sphere "
           "coverings that queries test: density 'none' or 'adb' (cell counts from the points' areas; "
           "grid=, tau=); leaf: points per leaf at most (8 to 32 keeps leaf tests cheap). Such a tree "
           "queries a cloud's tree or a mesh's of the same volume and density; it cannot be saved.")
      .def_static(
          "load", &load_tree, py::arg("path"), py::arg("mesh") = nullptr,
          "Reads a saved tree, in the units it records. Saved trees carry no polygons: give the mesh it was "
          "built from to run the strategies that test triangles (it is checked against the tree: its units "
          "and its triangles).")
      .def("save", &save, py::arg("path"),
           "Saves the tree without polygons, with its units (the format `bvhlab build` writes). A tree of a "
           "mesh loaded with scale= is refused: the format records only the file's units or the "
           "normalisation.")
      .def_property_readonly(
          "units", [](const AnyTree& t) { return units_dict(t.info().units); },
          "its mesh's units (Mesh.units), or those its file records; query refuses a normalised tree "
          "against one in its file's units")
      .def_property_readonly("bv", info(&TreeInfo::bv))
      .def_property_readonly("density", info(&TreeInfo::density))
      .def_property_readonly("annotation", info(&TreeInfo::annotation), "the density and its parameters")
      .def_property_readonly("triangles", info(&TreeInfo::triangles))
      .def_property_readonly("points", info(&TreeInfo::points), "a point cloud's tree: its points (else 0)")
      .def_property_readonly("nodes", info(&TreeInfo::nodes))
      .def_property_readonly("depth", info(&TreeInfo::depth))
      .def_property_readonly("model_bytes", info(&TreeInfo::model_bytes),
                             "bytes of nodes, volumes and density data (what a query reads, no polygons)")
      .def_property_readonly("build_seconds", info(&TreeInfo::build_seconds))
      .def_property_readonly("annotate_seconds", info(&TreeInfo::annotate_seconds))
      .def_property_readonly("has_polygons", info(&TreeInfo::polygons))
      .def("__repr__", &repr);
}

}  // namespace bvhlab::python
