#pragma once
// The test functions of a singular matrix by bordering (W. Govaerts, Numerical Methods for
// Bifurcations of Dynamical Equilibria, SIAM 2000, ch. 3; Y. A. Kuznetsov, Elements of Applied
// Bifurcation Theory, 3rd ed., Springer 2004, §10.2): for A (N × N) with a null space of dimension
// at most k near the points of interest, and borders B, C (N × k) that make
//
//     [A   B] [W]   [0 ]
//     [C^T 0] [G] = [I_k]
//
// regular, G (k × k) vanishes exactly where A has a k-dimensional null space, and is as smooth as
// A (never a determinant, which under- or overflows for large N). W spans the null space there,
// and the adjoint [A^T C; B^T 0] [V; H] = [0; I_k] gives the left one. A change of A by dA changes
// G by dG_ij = −V_i^T dA W_j: the derivatives of the test functions come from products with dA,
// which the defining systems form from directional derivatives of the map. The borders are
// refreshed at each accepted point of a curve from the last W and V (orthonormalised), so that the
// bordered matrix stays well conditioned along it.
#include <Eigen/LU>
#include <Eigen/QR>

#include "pwl/types.hpp"

namespace pwl::orbits {

struct BorderedSolution {
  Matrix W;  // N × k: the right null vectors' approximations
  Matrix V;  // N × k: the left ones
  Matrix G;  // k × k: the test functions
};

// Solves the bordered system and its adjoint. Returns false when the bordered matrix is singular
// or the solution not finite.
inline bool solve_bordered(const Matrix& A, const Matrix& B, const Matrix& C,
                           BorderedSolution& out) {
  const Index N = A.rows(), k = B.cols();
  Matrix K = Matrix::Zero(N + k, N + k);
  K.topLeftCorner(N, N) = A;
  K.topRightCorner(N, k) = B;
  K.bottomLeftCorner(k, N) = C.transpose();
  Matrix rhs = Matrix::Zero(N + k, k);
  rhs.bottomRows(k) = Matrix::Identity(k, k);
  const Eigen::PartialPivLU<Matrix> lu(K);
  const Matrix x = lu.solve(rhs);
  // The adjoint: K^T [V; H] = [0; I] with K^T = [A^T C; B^T 0].
  const Matrix y = lu.transpose().solve(rhs);
  if (!x.allFinite() || !y.allFinite()) return false;
  out.W = x.topRows(N);
  out.G = x.bottomRows(k);
  out.V = y.topRows(N);
  return true;
}

// An orthonormal basis of the columns of X (N × k, k <= N).
inline Matrix orthonormal_columns(const Matrix& X) {
  const Eigen::HouseholderQR<Matrix> qr(X);
  return qr.householderQ() * Matrix::Identity(X.rows(), X.cols());
}

}  // namespace pwl::orbits
