#pragma once
// The real Schur vectors of the leading multipliers of a point of a branch: the warm start of the
// next point's multipliers (Arnoldi's starting vector is their sum, Davidson's first basis they
// themselves). Private to the orbits room.
//
// M U = U Λ on the invariant subspace of the leading multipliers (U their eigenvectors, in the
// order they are reported: largest modulus first, a complex pair adjacent). Gram–Schmidt on the
// real and imaginary parts of U's columns, in that order, gives Q with orthonormal columns whose
// first j span the invariant subspace of the first j multipliers (a complex pair's two at once):
// Qᵀ M Q is then quasi-upper-triangular, M Q = Q T, the real Schur form of M on that subspace
// (G. H. Golub and C. F. Van Loan, Matrix Computations, 4th ed., 2013, §7.4.1 and §7.6.1). Unlike
// the eigenvectors, Q stays well conditioned where two multipliers nearly coincide (a crowd of
// long waves on a long chain, a pair about to collide on the real axis). It is the basis that
// Krylov–Schur restarts keep (G. W. Stewart, SIAM J. Matrix Anal. Appl. 23 (2001) 601-614), and
// the one a subspace method starts the next point from (K. Lust, D. Roose, A. Spence and A. R.
// Champneys, SIAM J. Sci. Comput. 19 (1998) 1188-1209, start each point's subspace iteration
// from the last point's basis).
#include <Eigen/Dense>
#include <algorithm>

#include "orbits/multiplier_sorting.hpp"
#include "pwl/types.hpp"

namespace pwl::orbits::detail {

// At most `limit` columns. A part below 1e-10 of its eigenvector's norm (the imaginary part of a
// real one's), or that the columns before it already span to 1e-10 of its own norm (the
// conjugate of a pair, a repeated vector), is left out. Non-finite input gives no columns.
inline Matrix real_schur_vectors(const Eigen::MatrixXcd& eigenvectors, Index limit) {
  Matrix q(eigenvectors.rows(), std::clamp<Index>(limit, 0, 2 * eigenvectors.cols()));
  if (!eigenvectors.allFinite()) return q.leftCols(0);
  Index kept = 0;
  const auto add = [&](Vector part, double whole) {
    const double norm = part.norm();
    if (kept >= q.cols() || !(norm > 1e-10 * whole)) return;
    Vector unused = Vector::Zero(kept);
    project_out_twice(q.leftCols(kept), part, unused);
    if (part.norm() <= 1e-10 * norm) return;
    q.col(kept++) = part / part.norm();
  };
  for (Index c = 0; c < eigenvectors.cols() && kept < q.cols(); ++c) {
    const double whole = eigenvectors.col(c).norm();
    add(eigenvectors.col(c).real(), whole);
    add(eigenvectors.col(c).imag(), whole);
  }
  return q.leftCols(kept);
}

}  // namespace pwl::orbits::detail
