// Checks of Python input shared by the bindings: arrays of real numbers, poses, parameters, paths.
#include "python/bindings.hpp"

#include <cmath>
#include <stdexcept>

namespace bvhlab::python {

namespace {

std::string shape_of(const py::array& array) {
  std::string out = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i)
    out += (i ? ", " : "") + std::to_string(array.shape(i)) + (array.ndim() == 1 ? "," : "");
  return out + ")";
}

bool shape_matches(const py::array& array, const std::vector<py::ssize_t>& shape) {
  if (array.ndim() != static_cast<py::ssize_t>(shape.size())) return false;
  for (std::size_t i = 0; i < shape.size(); ++i)
    if (shape[i] >= 0 && array.shape(static_cast<py::ssize_t>(i)) != shape[i]) return false;
  return true;
}

}  // namespace

py::array_t<double, py::array::c_style> real_array(const py::handle& value, const std::string& what,
                                                   const std::vector<py::ssize_t>& shape,
                                                   const std::string& shape_text) {
  const py::array array = py::array::ensure(value);
  if (!array)
    throw py::type_error(what + ": expected an array of real numbers, got " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  const char kind = array.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error(what + ": expected real numbers (float64), got dtype " +
                         std::string(py::str(array.dtype())));
  if (!shape_matches(array, shape))
    throw py::value_error(what + ": expected shape " + shape_text + ", got " + shape_of(array));
  return py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(array);
}

std::vector<Vec3> vec3_rows(const py::handle& value, const std::string& what) {
  const auto array = real_array(value, what, {-1, 3}, "(N, 3)");
  const double* xyz = array.data();
  std::vector<Vec3> out(static_cast<std::size_t>(array.shape(0)));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  return out;
}

py::array_t<double> vec3_array(const std::vector<Vec3>& vectors) {
  py::array_t<double> out({static_cast<py::ssize_t>(vectors.size()), py::ssize_t{3}});
  double* data = out.mutable_data();
  for (std::size_t i = 0; i < vectors.size(); ++i)
    for (int k = 0; k < 3; ++k) data[3 * i + k] = vectors[i](k);
  return out;
}

RigidTransform rigid_from_parts(const double* rotation, const double* translation, const std::string& what) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = rotation[3 * i + j];
  try {
    return RigidTransform::checked(r, Vec3(translation[0], translation[1], translation[2]));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(what + ": " + e.what());
  }
}

RigidTransform rigid_from_matrix(const double* m, const std::string& what) {
  for (int k = 0; k < 16; ++k)
    if (!std::isfinite(m[k])) throw py::value_error(what + ": the matrix has a NaN or infinite entry");
  if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
    throw py::value_error(what + ": not a rigid motion: the last row must be 0 0 0 1");
  const double rotation[9] = {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
  const double translation[3] = {m[3], m[7], m[11]};
  return rigid_from_parts(rotation, translation, what);
}

void matrix_from_rigid(const RigidTransform& pose, double* out) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) out[4 * i + j] = pose.rotation(i, j);
    out[4 * i + 3] = pose.translation(i);
  }
  out[12] = out[13] = out[14] = 0;
  out[15] = 1;
}

ParamValues parameter_values(const py::kwargs& kwargs) {
  ParamValues out;
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    if (py::isinstance<py::bool_>(value))
      throw py::type_error("parameter " + name + ": expected a number, got a bool");
    try {
      out[name] = value.cast<double>();
    } catch (const py::cast_error&) {
      throw py::type_error("parameter " + name + ": expected a number, got " +
                           std::string(py::str(py::type::of(value).attr("__name__"))));
    }
  }
  return out;
}

std::filesystem::path path_argument(const py::handle& value, const std::string& what) {
  const py::object fspath = py::module_::import("os").attr("fspath");
  try {
    const py::object path = fspath(value);
    if (!py::isinstance<py::str>(path)) throw py::type_error(what + ": expected a str path, got bytes");
    return std::filesystem::path(path.cast<std::string>());
  } catch (const py::error_already_set& e) {
    if (!e.matches(PyExc_TypeError)) throw;
    throw py::type_error(what + ": expected a path (str or os.PathLike)");
  }
}

void require_file(const std::filesystem::path& file, const std::string& what) {
  if (std::filesystem::is_regular_file(file)) return;
  const std::string message = what + ": no such file: '" + file.string() + "'";
  PyErr_SetString(PyExc_FileNotFoundError, message.c_str());
  throw py::error_already_set();
}

}  // namespace bvhlab::python
