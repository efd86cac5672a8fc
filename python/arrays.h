#pragma once
// numpy arrays at the edge of the bindings: shape checks with one-line messages, and Eigen views
// of the arrays' memory. An N x 2 C-contiguous float64 array has the memory layout of Eigen's
// 2 x N column-major matrix (x0, y0, x1, y1, ...), so points cross without a copy; pybind11's
// forcecast copies (once, on the way in) an array of another dtype or layout.

#include <pybind11/numpy.h>

#include <Eigen/Core>
#include <string>

#include "common/errors.h"

namespace airtwin::python {

/// The arrays the bindings accept: C-contiguous float64, converted (copied) when not.
using DoubleArray =
    pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

/// The shape of `a` as "(n, m)".
inline std::string shape_text(const pybind11::array& a) {
  std::string s = "(";
  for (pybind11::ssize_t i = 0; i < a.ndim(); ++i) {
    s += (i ? ", " : "") + std::to_string(a.shape(i));
  }
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// An N x `columns` array's rows; InputError naming `what` otherwise.
inline pybind11::ssize_t rows_of(const DoubleArray& a, pybind11::ssize_t columns,
                                 const std::string& what) {
  if (a.ndim() != 2 || a.shape(1) != columns) {
    throw InputError(what + ": expected an N x " + std::to_string(columns) + " array, got shape " +
                     shape_text(a));
  }
  return a.shape(0);
}

/// A length-N vector; InputError naming `what` otherwise.
inline void require_vector(const DoubleArray& a, pybind11::ssize_t n, const std::string& what) {
  if (a.ndim() != 1 || a.shape(0) != n) {
    throw InputError(what + ": expected a vector of " + std::to_string(n) + " values, got shape " +
                     shape_text(a));
  }
}

/// The N x 2 array `a` as Eigen's 2 x N matrix, no copy.
inline Eigen::Map<const Eigen::Matrix2Xd> as_columns(const DoubleArray& a) {
  return {a.data(), 2, static_cast<Eigen::Index>(a.shape(0))};
}

}  // namespace airtwin::python
