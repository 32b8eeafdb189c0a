#include "pwl/orbits/floquet_multipliers.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <omp.h>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <random>

#include "orbits/multiplier_sorting.hpp"
#include "orbits/schur_vectors.hpp"
#include "pwl/errors.hpp"

namespace pwl::orbits {

using detail::project_out_twice;
using detail::sort_multipliers;

double FloquetMultipliers::largest_modulus() const {
  return values.empty() ? 0.0 : std::abs(values.front());
}

bool FloquetMultipliers::stable(double margin) const { return largest_modulus() < 1.0 - margin; }

double FloquetMultipliers::shifted_determinant(double target) const {
  std::complex<double> product{1.0, 0.0};
  for (const auto& m : values) product *= 1.0 - m / target;
  return product.real();
}

int FloquetMultipliers::unstable_count() const {
  return static_cast<int>(std::count_if(values.begin(), values.end(),
                                        [](const auto& mu) { return std::abs(mu) > 1.0; }));
}

FloquetMultipliers floquet_multipliers(const Matrix& monodromy) {
  if (monodromy.rows() != monodromy.cols() || monodromy.rows() == 0) {
    throw InputError(fmt::format("monodromy is {} x {}: it must be square and not empty",
                                 monodromy.rows(), monodromy.cols()));
  }
  if (!monodromy.allFinite()) throw InputError("monodromy has a non-finite entry");
  Eigen::EigenSolver<Matrix> solver(monodromy, /*computeEigenvectors=*/false);
  if (solver.info() != Eigen::Success) throw Error("monodromy: the eigenvalue iteration failed");
  FloquetMultipliers result;
  result.values.assign(solver.eigenvalues().begin(), solver.eigenvalues().end());
  sort_multipliers(result.values);
  result.complete = true;
  return result;
}

bool ArnoldiOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (count < 1) {
    *why = fmt::format("floquet count = {} must be >= 1", count);
    return false;
  }
  if (block < 1) {
    *why = fmt::format("arnoldi block = {} must be >= 1", block);
    return false;
  }
  if (krylov_dimension <= count) {
    *why = fmt::format("krylov dimension = {} must exceed the count of multipliers {}",
                       krylov_dimension, count);
    return false;
  }
  if (davidson_dimension <= count) {
    *why = fmt::format("davidson dimension = {} must exceed the count of multipliers {}",
                       davidson_dimension, count);
    return false;
  }
  if (max_restarts < 0) {
    *why = fmt::format("max restarts = {} must be >= 0", max_restarts);
    return false;
  }
  if (!(tolerance > 0) || !std::isfinite(tolerance)) {
    *why = fmt::format("arnoldi tolerance = {} must be positive and finite", tolerance);
    return false;
  }
  if (!(margin >= 0) || !(margin < 1)) {
    *why = fmt::format("multiplier margin = {} must be in [0, 1)", margin);
    return false;
  }
  return true;
}

FloquetMultipliers leading_floquet_multipliers(const std::function<void(Matrix&)>& apply,
                                               Index size, const ArnoldiOptions& options,
                                               const Eigen::MatrixXcd* warm,
                                               Eigen::MatrixXcd* vectors) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (size < 1) throw InputError(fmt::format("operator size = {} must be >= 1", size));
  int wanted = static_cast<int>(std::min<Index>(options.count, size));
  const int m = static_cast<int>(std::min<Index>(options.krylov_dimension, size));
  const double edge = 1.0 - options.margin;  // the band |μ| > edge must be covered

  // The start: a fixed random vector or, warm (schur_vectors.hpp), the sum of the nearby
  // operator's real Schur vectors of its leading multipliers plus a tenth of that random vector,
  // so that a multiplier that was not among them (one that grows past them) still has a
  // component to grow from. One vector, not the Schur vectors as a block: on the 1000-mass chain
  // (`pwl continue --n 1000 --alpha 2 --zeta 0.2 --theta 1.5 --parameter theta --range 1.5:1.6
  // --max-points 25 --multiplier-method arnoldi`, 2026-12-02) the sum took 16324 products, the
  // sum of the Ritz vectors 17852, and the Schur vectors themselves as the first block (six or
  // more, with the random one) 27869, with 19 of the 25 points short of the tolerance: a block of
  // b columns grows a polynomial of 1/b the degree for the same products, and the crowd of long
  // waves needs the degree.
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> normal;
  Vector start(size);
  for (Index i = 0; i < size; ++i) start(i) = normal(rng);
  if (warm != nullptr && warm->rows() == size && warm->cols() > 0) {
    const Vector sum = detail::real_schur_vectors(*warm, 2 * warm->cols()).rowwise().sum();
    if (sum.norm() > 0) start = sum / sum.norm() + 0.1 * start / start.norm();
  }

  FloquetMultipliers result;
  result.method = FloquetMultipliers::Method::arnoldi;
  result.complete = wanted == size;
  // Block Krylov-Schur: apply() takes `block` columns at a time (a caller can spread them over
  // threads). The relation A V_j = V_j G_j + V_next E, E nonzero in its last block of columns
  // only (the triangular factor of the last block's QR) except, after a restart, under the kept
  // columns. One column (the default) is the usual Arnoldi relation A V_j = V_j G_j + g v e_j^T.
  // At most m − wanted, so that a restart keeps the wanted columns and still grows by a block;
  // and one column where the basis and a block would not fit in the space side by side (the last
  // block would run out of directions: plain Arnoldi ends there on an invariant subspace).
  const int b = size >= static_cast<Index>(m) + options.block
                    ? std::max(1, std::min(options.block, m - wanted))
                    : 1;
  Matrix V = Matrix::Zero(size, m + b);
  Matrix G = Matrix::Zero(m + b, m);
  V.col(0) = start / start.norm();
  // The other starting columns: fixed random vectors, orthonormal to the first.
  for (int c = 1; c < b; ++c) {
    Vector extra(size);
    for (Index i = 0; i < size; ++i) extra(i) = normal(rng);
    Vector unused = Vector::Zero(c);
    project_out_twice(V.leftCols(c), extra, unused);
    V.col(c) = extra / extra.norm();
  }
  int kept = 0;  // columns carried over from the last cycle
  Matrix W(size, b);
  int restarts = 0;
  while (true) {
    int built = kept;  // columns whose products are in G
    bool invariant = false;
    for (int j = kept; j + b <= m; j += b) {
      W = V.middleCols(j, b);
      apply(W);
      // Against the basis column by column (matrix-vector products stream the basis once
      // each, where a matrix product would first copy it into packed panels). The columns of a
      // block are independent here: on threads of their own when the basis is large (the same
      // arithmetic per column on any number of threads).
      const auto basis = V.leftCols(j + b);
      const int threads = std::min(b, omp_get_max_threads());
      const bool spread = threads > 1 && !omp_in_parallel() && size * (j + b) >= 100000;
#pragma omp parallel for num_threads(threads) if (spread)
      for (int c = 0; c < b; ++c) project_out_twice(basis, W.col(c), G.col(j + c).head(j + b));
      // The new block's QR, column by column: R under the block.
      for (int c = 0; c < b; ++c) {
        project_out_twice(V.middleCols(j + b, c), W.col(c), G.col(j + c).segment(j + b, c));
        const double beta = W.col(c).norm();
        G(j + b + c, j + c) = beta;
        if (beta <= 1e-14 * G.col(j + c).head(j + b + c).norm()) invariant = true;
        if (!invariant) V.col(j + b + c) = W.col(c) / beta;
      }
      built = j + b;
      if (invariant || j + b >= size) {
        invariant = true;  // an invariant subspace: its Ritz values are exact
        break;
      }
    }
    const Matrix Gm = G.topLeftCorner(built, built);
    Eigen::EigenSolver<Matrix> eig(Gm);
    if (eig.info() != Eigen::Success) throw Error("arnoldi: the Ritz eigenproblem failed");
    // Formed once: EigenSolver::eigenvectors() builds the whole complex matrix at each call.
    const Eigen::MatrixXcd ritz_vectors = eig.eigenvectors();
    std::vector<int> order(built);
    for (int i = 0; i < built; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int x, int y) {
      return std::abs(eig.eigenvalues()(x)) > std::abs(eig.eigenvalues()(y));
    });
    // Residual of the Ritz pair (θ, V s): |E s| / |s|, E the rows under G (the last block's R).
    const Matrix E = G.block(built, built - b, b, b);
    const double scale = std::max(1.0, std::abs(eig.eigenvalues()(order[0])));
    const auto residual_of = [&](int i) {
      const Eigen::VectorXcd s = ritz_vectors.col(i);
      return (E * s.tail(b)).norm() / s.norm() / scale;
    };
    double worst = 0;
    int reported = std::min(wanted, built);
    // A basis that spans the whole space: every Ritz value is an eigenvalue, and the band is
    // reported whole (the doubling below is for a basis still growing; a breakdown on a smaller
    // invariant subspace may have missed some).
    if (invariant && built == size) {
      while (reported < built && std::abs(eig.eigenvalues()(order[reported - 1])) > edge) {
        ++reported;
      }
      if (reported == built) result.complete = true;
    }
    // A complex pair whole: its second half joins where the count would cut it.
    if (reported < built) {
      const std::complex<double> last = eig.eigenvalues()(order[reported - 1]);
      const auto conjugate_of_last = [&](int r) {
        return std::abs(eig.eigenvalues()(order[r]) - std::conj(last)) <= 1e-12 * std::abs(last);
      };
      const bool paired = reported >= 2 && conjugate_of_last(reported - 2);
      if (last.imag() != 0.0 && !paired && conjugate_of_last(reported)) ++reported;
    }
    for (int r = 0; r < reported; ++r) worst = std::max(worst, residual_of(order[r]));
    result.values.clear();
    for (int r = 0; r < reported; ++r) result.values.push_back(eig.eigenvalues()(order[r]));
    result.residual = worst;
    if (vectors != nullptr) {
      vectors->resize(size, reported);
      for (int r = 0; r < reported; ++r) {
        const Eigen::VectorXcd s = ritz_vectors.col(order[r]);
        vectors->col(r) = V.leftCols(built).cast<std::complex<double>>() * s;
        vectors->col(r) /= vectors->col(r).norm();
      }
    }
    // Converged, with the smallest value reported still in the band: twice as many wanted (up to
    // half the basis, so that they can still converge), the decomposition going on from its
    // thick restart as it stands (which keeps the span of more Ritz vectors than wanted); not
    // counted as a restart. Short of convergence, values in the band may be Ritz values with
    // nothing there (a 10^4-mass chain's crowded long waves: 1.00007 at a residual of 3e-2).
    const bool converged = worst <= options.tolerance;
    const bool in_band = std::abs(result.values.back()) > edge;
    if (converged && in_band && !invariant && 4 * wanted <= m && wanted < size) {
      wanted = static_cast<int>(std::min<Index>(2 * wanted, size));
      result.complete = wanted == size;
    } else {
      if (converged || invariant || restarts == options.max_restarts) break;
      ++restarts;
    }

    // Thick restart (G. W. Stewart, SIAM J. Matrix Anal. Appl. 23 (2001) 601-614, Krylov-Schur;
    // R. B. Morgan, Math. Comp. 65 (1996) 1213-1230): keep the span of the leading Ritz vectors,
    // more of them than wanted, so that what the cycle learnt about the next ones is not thrown
    // away. A real basis Z of that span (a complex pair gives its real and imaginary parts), Q
    // its orthonormal basis: V Q spans an invariant subspace of the projected operator, with
    // A (V Q) = (V Q) (Qᵀ G Q) + V_next (E_full Q), E_full the rows under G.
    int keep = std::min(m - b, std::max(wanted + (m - wanted) / 2, wanted));
    Matrix Z(built, keep);
    int columns = 0;
    for (int r = 0; r < built && columns < keep; ++r) {
      const std::complex<double> theta = eig.eigenvalues()(order[r]);
      const Eigen::VectorXcd s = ritz_vectors.col(order[r]);
      if (theta.imag() == 0.0) {
        Z.col(columns++) = s.real();
      } else if (theta.imag() > 0.0) {
        if (columns + 2 > keep) break;  // a pair is kept whole or not at all
        Z.col(columns++) = s.real();
        Z.col(columns++) = s.imag();
      }
    }
    if (columns == 0) break;
    const Eigen::HouseholderQR<Matrix> qr(Z.leftCols(columns));
    const Matrix Q = qr.householderQ() * Matrix::Identity(built, columns);
    const Matrix kept_basis = V.leftCols(built) * Q;
    const Matrix projected = Q.transpose() * Gm * Q;
    const Matrix next = V.middleCols(built, b);
    const Matrix coupling = G.block(built, 0, b, built) * Q;
    V.setZero();
    G.setZero();
    V.leftCols(columns) = kept_basis;
    V.middleCols(columns, b) = next;
    G.topLeftCorner(columns, columns) = projected;
    G.block(columns, 0, b, columns) = coupling;
    kept = columns;
    if (!V.allFinite()) break;
  }
  result.converged = result.residual <= options.tolerance;
  // The values are in decreasing modulus: the last is the smallest.
  result.band_covered =
      result.complete || (result.converged && std::abs(result.values.back()) <= edge);
  if (vectors == nullptr) {
    sort_multipliers(result.values);
    return result;
  }
  sort_multipliers(result.values, *vectors);
  return result;
}

}  // namespace pwl::orbits
