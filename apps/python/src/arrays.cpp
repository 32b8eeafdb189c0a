#include "arrays.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pwl/errors.hpp"

namespace pwl::python {

py::array_t<double> vector_array(const Vector& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

py::array_t<double> vector_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<int> int_array(const std::vector<int>& v) {
  py::array_t<int> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::array_t<double> rows_array(const std::vector<double>& values, py::ssize_t rows,
                               py::ssize_t columns) {
  if (static_cast<py::ssize_t>(values.size()) != rows * columns) {
    throw Error(fmt::format("internal: {} values for {} x {}", values.size(), rows, columns));
  }
  py::array_t<double> a({rows, columns});
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

py::array_t<double> matrix_array(const Matrix& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto out = a.mutable_unchecked<2>();
  for (Index i = 0; i < m.rows(); ++i) {
    for (Index j = 0; j < m.cols(); ++j) out(i, j) = m(i, j);
  }
  return a;
}

py::array_t<std::complex<double>> complex_array(const std::vector<std::complex<double>>& v) {
  py::array_t<std::complex<double>> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

Matrix square_matrix(const py::handle& value, const std::string& name) {
  // A null array when NumPy cannot read `value` as numbers.
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a) {
    throw InputError(fmt::format("{}: expected a square matrix of numbers, got {}", name,
                                 py::repr(value).cast<std::string>()));
  }
  if (a.ndim() != 2 || a.shape(0) != a.shape(1) || a.shape(0) == 0) {
    std::string shape;
    for (py::ssize_t d = 0; d < a.ndim(); ++d) {
      shape += fmt::format("{}{}", d > 0 ? " x " : "", a.shape(d));
    }
    throw InputError(fmt::format("{}: expected a square matrix (n x n, n >= 1), got shape ({})",
                                 name, shape));
  }
  const auto r = a.unchecked<2>();
  Matrix m(a.shape(0), a.shape(1));
  for (Index i = 0; i < m.rows(); ++i) {
    for (Index j = 0; j < m.cols(); ++j) {
      if (!std::isfinite(r(i, j))) {
        throw InputError(
            fmt::format("{}[{},{}] = {}: expected a finite number", name, i, j, r(i, j)));
      }
      m(i, j) = r(i, j);
    }
  }
  return m;
}

}  // namespace pwl::python
