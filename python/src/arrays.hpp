// numpy <-> Eigen helpers of the kelp extension module: arguments checked with kelp's exceptions
// (a wrong shape or a non-numeric array is a kelp.InvalidArgument naming the argument), and
// zero-copy views of C++ memory kept alive by the Python object that owns it.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <initializer_list>
#include <string>
#include <vector>

#include "kelp/core/error.hpp"

namespace kelp_python {

namespace py = pybind11;

/// A C-contiguous float64 array, numpy's conversion of `obj` (a copy only when needed).
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// "(3,)", "(n, 3)": a shape for messages.
inline std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// `obj` as float64 numbers. \throws kelp::invalid_argument naming `name` when numpy cannot
/// make numbers of it.
inline DoubleArray as_doubles(py::handle obj, const char* name) {
  DoubleArray a = DoubleArray::ensure(obj);
  if (!a) {
    PyErr_Clear();
    kelp::detail::throw_invalid_argument(
        std::string(name) + ": expected an array of numbers, got " +
        std::string(py::str(py::type::handle_of(obj).attr("__name__"))));
  }
  return a;
}

/// `obj` as a vector of N numbers (shape (N,)). \throws kelp::invalid_argument naming `name`.
template <int N>
Eigen::Matrix<double, N, 1> vector_arg(py::handle obj, const char* name) {
  const DoubleArray a = as_doubles(obj, name);
  if (a.ndim() != 1 || a.shape(0) != N)
    kelp::detail::throw_invalid_argument(std::string(name) + ": expected shape (" +
                                         std::to_string(N) + ",), got " + shape_text(a));
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(a.data());
}

/// `obj` as a dynamic vector of `n` numbers. \throws kelp::invalid_argument naming `name`.
inline Eigen::VectorXd vector_arg(py::handle obj, Eigen::Index n, const char* name) {
  const DoubleArray a = as_doubles(obj, name);
  if (a.ndim() != 1 || a.shape(0) != n)
    kelp::detail::throw_invalid_argument(std::string(name) + ": expected shape (" +
                                         std::to_string(n) + ",), got " + shape_text(a));
  return Eigen::Map<const Eigen::VectorXd>(a.data(), n);
}

/// Points: an array of shape (n, C) or (C,) (one point), C = `columns`; `single` tells which.
/// \throws kelp::invalid_argument naming `name` for any other shape.
inline DoubleArray points_arg(py::handle obj, py::ssize_t columns, const char* name, bool& single) {
  DoubleArray a = as_doubles(obj, name);
  single = a.ndim() == 1;
  if (!((a.ndim() == 2 && a.shape(1) == columns) || (single && a.shape(0) == columns)))
    kelp::detail::throw_invalid_argument(std::string(name) + ": expected shape (n, " +
                                         std::to_string(columns) + ") or (" +
                                         std::to_string(columns) + ",), got " + shape_text(a));
  return a;
}

/// Sets the 3×n matrix `x` (a tether's nodes) from an array of exactly (n, 3), n = x.cols().
/// \throws kelp::invalid_argument naming `name` for any other shape (x is then unchanged).
inline void set_points(Eigen::Matrix3Xd& x, py::handle obj, const char* name) {
  bool single = false;
  const DoubleArray a = points_arg(obj, 3, name, single);
  if (single || a.shape(0) != x.cols())
    kelp::detail::throw_invalid_argument(std::string(name) + ": expected shape (" +
                                         std::to_string(x.cols()) + ", 3), got " + shape_text(a));
  x = Eigen::Map<const Eigen::Matrix3Xd>(a.data(), 3, x.cols());
}

/// A zero-copy float64 view of `data` (shape, strides in elements) whose base is `owner`: numpy
/// keeps `owner` alive as long as the view, so the view never dangles while the memory it shows
/// belongs to `owner` (and is not reallocated by it).
inline py::array view(const double* data, std::vector<py::ssize_t> shape,
                      std::vector<py::ssize_t> strides, py::handle owner, bool writable = true) {
  for (auto& s : strides) s *= static_cast<py::ssize_t>(sizeof(double));
  py::array a(py::dtype::of<double>(), std::move(shape), std::move(strides), data, owner);
  if (!writable)
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// A view of a contiguous vector of `n` doubles owned by `owner`.
inline py::array vector_view(const double* data, py::ssize_t n, py::handle owner,
                             bool writable = true) {
  return view(data, {n}, {1}, owner, writable);
}

/// A view of a column-major 3×n Eigen matrix (e.g. a tether's node positions) as n points,
/// shape (n, 3), owned by `owner`.
inline py::array points_view(const double* data, py::ssize_t n, py::handle owner,
                             bool writable = true) {
  return view(data, {n, 3}, {3, 1}, owner, writable);
}

/// A new (rows, cols) float64 array (a copy) of an Eigen matrix.
template <typename Derived>
py::array copy_matrix(const Eigen::MatrixBase<Derived>& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto r = a.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) r(i, j) = m(i, j);
  return a;
}

/// A new 1-D float64 array (a copy) of an Eigen vector.
template <typename Derived>
py::array copy_vector(const Eigen::MatrixBase<Derived>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  auto r = a.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < v.size(); ++i) r(i) = v(i);
  return a;
}

}  // namespace kelp_python
