#pragma once
// NumPy arrays for the module's results, and matrices from NumPy for its inputs.
//
// Every array handed to Python owns a copy of its data (float64 or complex128, C-contiguous): no
// view into a C++ object that dies with the call.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <complex>
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::python {

namespace py = pybind11;

py::array_t<double> vector_array(const Vector& v);
py::array_t<double> vector_array(const std::vector<double>& v);
py::array_t<int> int_array(const std::vector<int>& v);
// rows x columns from `values` stored row by row (values.size() == rows * columns).
py::array_t<double> rows_array(const std::vector<double>& values, py::ssize_t rows,
                               py::ssize_t columns);
py::array_t<double> matrix_array(const Matrix& m);
py::array_t<std::complex<double>> complex_array(const std::vector<std::complex<double>>& v);

// A square matrix from anything NumPy reads as a 2-D array of numbers. Throws InputError naming
// `name` for another shape or a non-finite entry ("mass[1,0] = nan", 0-based as in NumPy and in
// GapStructure's own messages).
Matrix square_matrix(const py::handle& value, const std::string& name);

}  // namespace pwl::python
