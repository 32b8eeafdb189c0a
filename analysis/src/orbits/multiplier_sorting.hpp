#pragma once
// The order in which multipliers are reported (largest modulus first; a conjugate pair with its
// positive imaginary part first), with their Ritz vectors carried along. Shared by Arnoldi and
// Davidson (floquet_multipliers.cpp, davidson_multipliers.cpp).
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::orbits::detail {

// Largest modulus first; ties (a conjugate pair) with the positive imaginary part first.
inline void sort_multipliers(std::vector<std::complex<double>>& values) {
  std::stable_sort(values.begin(), values.end(),
                   [](const std::complex<double>& a, const std::complex<double>& b) {
                     const double ma = std::abs(a), mb = std::abs(b);
                     if (std::abs(ma - mb) > 1e-12 * std::max(ma, mb)) return ma > mb;
                     return a.imag() > b.imag();
                   });
}

// The values sorted as above and the columns of `vectors` (column i for values[i]) with them.
inline void sort_multipliers(std::vector<std::complex<double>>& values,
                             Eigen::MatrixXcd& vectors) {
  std::vector<std::complex<double>> sorted = values;
  sort_multipliers(sorted);
  Eigen::MatrixXcd arranged(vectors.rows(), static_cast<Index>(sorted.size()));
  std::vector<bool> used(sorted.size(), false);
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    for (std::size_t j = 0; j < sorted.size(); ++j) {
      if (!used[j] && values[j] == sorted[i]) {
        arranged.col(static_cast<Index>(i)) = vectors.col(static_cast<Index>(j));
        used[j] = true;
        break;
      }
    }
  }
  vectors = std::move(arranged);
  values = std::move(sorted);
}

// x minus its projection on the orthonormal columns of `basis`, the coefficients added to h, by
// classical Gram-Schmidt twice: as orthogonal to rounding as modified Gram-Schmidt twice ("twice
// is enough": L. Giraud, J. Langou, M. Rozloznik, Comput. Math. Appl. 50 (2005) 1069-1075), in
// two matrix-vector products with the basis a pass instead of a dot product and an update per
// column.
template <class Basis, class Column, class Coefficients>
void project_out_twice(const Basis& basis, Column&& x, Coefficients&& h) {
  for (int pass = 0; pass < 2; ++pass) {
    const Vector c = basis.transpose() * x;
    h += c;
    x.noalias() -= basis * c;
  }
}

}  // namespace pwl::orbits::detail
