// The bvhlab Python module: one bind_* function per concern (meshes.cpp, points.cpp, trees.cpp,
// queries.cpp, scenes.cpp), and the checks of Python input they share (arrays.cpp). Bad input raises a Python
// exception naming the argument and the problem: TypeError for a wrong type or dtype, ValueError for a wrong
// shape or value, FileNotFoundError for a missing file.
#pragma once

#include "adb/parameters.hpp"
#include "engine/any_tree.hpp"
#include "volumes/geometry.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <filesystem>
#include <string>
#include <vector>

namespace bvhlab::python {

namespace py = pybind11;

void bind_meshes(py::module_& m);
void bind_points(py::module_& m);
void bind_trees(py::module_& m);
void bind_queries(py::module_& m);
void bind_scenes(py::module_& m);

/// A C-contiguous float64 array with `value`'s numbers. `shape` gives each dimension's size, -1 for any;
/// `shape_text` says the same for messages ("(N, 3)"). Refuses (TypeError) what is not an array or sequence
/// of real numbers (booleans, complex numbers, strings, objects), and (ValueError) another shape.
py::array_t<double, py::array::c_style> real_array(const py::handle& value, const std::string& what,
                                                   const std::vector<py::ssize_t>& shape,
                                                   const std::string& shape_text);

/// An (N, 3) array of real numbers as N vectors (real_array's checks, `what` naming it); values unchecked.
std::vector<Vec3> vec3_rows(const py::handle& value, const std::string& what);
/// N vectors as an (N, 3) float64 array (a copy).
py::array_t<double> vec3_array(const std::vector<Vec3>& vectors);

/// The rigid motion a 4 x 4 homogeneous matrix (row-major, as numpy stores it) describes. Throws ValueError
/// naming `what` for a NaN or infinite entry, a last row other than 0 0 0 1, or a matrix that is not a
/// rotation (not orthonormal, or a reflection).
RigidTransform rigid_from_matrix(const double* m, const std::string& what);
/// The same from a row-major 3 x 3 rotation and a translation.
RigidTransform rigid_from_parts(const double* rotation, const double* translation, const std::string& what);
/// The 4 x 4 matrix of `pose`, row-major, into `out`.
void matrix_from_rigid(const RigidTransform& pose, double* out);

/// Keyword arguments as policy parameters (p_min=0.9, grid=2): every value a real number (TypeError else);
/// the policy's table checks the names and ranges.
ParamValues parameter_values(const py::kwargs& kwargs);

/// Units as Python sees them: {"normalized", "scale", "centre", "scaled_by", "description"}.
py::dict units_dict(const MeshUnits& units);

/// A str or os.PathLike as a path; TypeError otherwise.
std::filesystem::path path_argument(const py::handle& value, const std::string& what);
/// Raises FileNotFoundError naming `what` and the file unless `file` is an existing regular file.
void require_file(const std::filesystem::path& file, const std::string& what);

}  // namespace bvhlab::python
