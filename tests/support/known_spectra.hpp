#pragma once
// Operators whose eigenvalues are known by construction, for the tests of the eigen-solvers of
// the leading multipliers (Arnoldi's in krylov_shooting_test.cpp, Davidson's in
// davidson_multipliers_test.cpp): block-diagonal D of 2 x 2 rotation-scaling blocks, one per
// conjugate pair, seen in a random well-conditioned basis S (A = S D S⁻¹).
#include <Eigen/QR>
#include <cmath>
#include <random>

#include "pwl/types.hpp"

namespace pwl::test {

// The 2x2 rotation-scaling block of the pair r e^{±iφ}, at (i, i) of D.
inline void put_pair(Matrix& D, Index i, double r, double phi) {
  D(i, i) = D(i + 1, i + 1) = r * std::cos(phi);
  D(i, i + 1) = r * std::sin(phi);
  D(i + 1, i) = -r * std::sin(phi);
}

// A random well-conditioned n x n basis: an orthogonal Q bent by 5%, both from uniform draws in
// [-1, 1] of `rng`.
inline Matrix random_basis(Index n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix random(n, n);
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j) random(i, j) = u(rng);
  const Matrix Q = Eigen::HouseholderQR<Matrix>(random).householderQ();
  return Q * (Matrix::Identity(n, n) + 0.05 * random / std::sqrt(double(n)));
}

}  // namespace pwl::test
