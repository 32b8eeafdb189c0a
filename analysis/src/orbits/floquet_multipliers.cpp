#include "pwl/orbits/floquet_multipliers.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <random>

#include "pwl/errors.hpp"

namespace pwl::orbits {

namespace {

// Largest modulus first; ties (a conjugate pair) with the positive imaginary part first.
void sort_multipliers(std::vector<std::complex<double>>& values) {
  std::stable_sort(values.begin(), values.end(),
                   [](const std::complex<double>& a, const std::complex<double>& b) {
                     const double ma = std::abs(a), mb = std::abs(b);
                     if (std::abs(ma - mb) > 1e-12 * std::max(ma, mb)) return ma > mb;
                     return a.imag() > b.imag();
                   });
}

}  // namespace

double FloquetMultipliers::largest_modulus() const {
  return values.empty() ? 0.0 : std::abs(values.front());
}

bool FloquetMultipliers::stable(double margin) const { return largest_modulus() < 1.0 - margin; }

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
  if (krylov_dimension <= count) {
    *why = fmt::format("krylov dimension = {} must exceed the count of multipliers {}",
                       krylov_dimension, count);
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
  return true;
}

FloquetMultipliers leading_floquet_multipliers(const std::function<void(Matrix&)>& apply,
                                               Index size, const ArnoldiOptions& options,
                                               const Eigen::MatrixXcd* warm,
                                               Eigen::MatrixXcd* vectors) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (size < 1) throw InputError(fmt::format("operator size = {} must be >= 1", size));
  const int wanted = static_cast<int>(std::min<Index>(options.count, size));
  const int m = static_cast<int>(std::min<Index>(options.krylov_dimension, size));

  std::mt19937 rng(options.seed);
  std::normal_distribution<double> normal;
  Vector start(size);
  for (Index i = 0; i < size; ++i) start(i) = normal(rng);
  if (warm != nullptr && warm->rows() == size && warm->cols() > 0 && warm->allFinite()) {
    Vector sum = Vector::Zero(size);
    for (Index c = 0; c < warm->cols(); ++c) {
      const double norm = warm->col(c).norm();
      if (norm > 0) sum += (warm->col(c).real() + warm->col(c).imag()) / norm;
    }
    if (sum.norm() > 0) start = sum / sum.norm() + 0.1 * start / start.norm();
  }

  FloquetMultipliers result;
  result.complete = wanted == size;
  // The Krylov-Schur relation A V_j = V_j G_j + g v_{j+1} e_j^T, G upper Hessenberg except, after
  // a restart, the row under the kept block.
  Matrix V = Matrix::Zero(size, m + 1);
  Matrix G = Matrix::Zero(m + 1, m);
  V.col(0) = start / start.norm();
  int kept = 0;  // columns carried over from the last cycle
  Matrix w(size, 1);
  Vector h(m + 1);
  for (int restart = 0; restart <= options.max_restarts; ++restart) {
    int built = m;
    for (int j = kept; j < m; ++j) {
      w = V.col(j);
      apply(w);
      // Classical Gram-Schmidt, twice: as orthogonal to rounding as modified Gram-Schmidt
      // twice ("twice is enough": L. Giraud, J. Langou, M. Rozloznik, Comput. Math. Appl. 50
      // (2005) 1069-1075), in two matrix-vector products with the basis instead of 2(j + 1)
      // dot products and updates one column at a time.
      const auto basis = V.leftCols(j + 1);
      for (int pass = 0; pass < 2; ++pass) {
        h.head(j + 1).noalias() = basis.transpose() * w.col(0);
        G.col(j).head(j + 1) += h.head(j + 1);
        w.col(0).noalias() -= basis * h.head(j + 1);
      }
      const double beta = w.col(0).norm();
      G(j + 1, j) = beta;
      if (beta <= 1e-14 * G.col(j).head(j + 1).norm() || j + 1 == size) {
        built = j + 1;  // an invariant subspace: its Ritz values are exact
        break;
      }
      V.col(j + 1) = w.col(0) / beta;
    }
    const Matrix Gm = G.topLeftCorner(built, built);
    Eigen::EigenSolver<Matrix> eig(Gm);
    if (eig.info() != Eigen::Success) throw Error("arnoldi: the Ritz eigenproblem failed");
    // Formed once: EigenSolver::eigenvectors() builds the whole complex matrix at each call.
    const Eigen::MatrixXcd ritz_vectors = eig.eigenvectors();
    std::vector<int> order(built);
    for (int i = 0; i < built; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return std::abs(eig.eigenvalues()(a)) > std::abs(eig.eigenvalues()(b));
    });
    // Residual of the Ritz pair (θ, V s): |g| |s_last| / |s|, g the last Arnoldi step's.
    const double beta = built < G.rows() ? G(built, built - 1) : 0.0;
    const double scale = std::max(1.0, std::abs(eig.eigenvalues()(order[0])));
    const auto residual_of = [&](int i) {
      const Eigen::VectorXcd s = ritz_vectors.col(i);
      return std::abs(beta) * std::abs(s(built - 1)) / s.norm() / scale;
    };
    double worst = 0;
    int reported = std::min(wanted, built);
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
    if (worst <= options.tolerance || built < m || restart == options.max_restarts) break;

    // Thick restart (G. W. Stewart, SIAM J. Matrix Anal. Appl. 23 (2001) 601-614, Krylov-Schur;
    // R. B. Morgan, Math. Comp. 65 (1996) 1213-1230): keep the span of the leading Ritz vectors,
    // more of them than wanted, so that what the cycle learnt about the next ones is not thrown
    // away. A real basis Z of that span (a complex pair gives its real and imaginary parts), Q
    // its orthonormal basis: V Q spans an invariant subspace of the projected operator, with
    // A (V Q) = (V Q) (Qᵀ G Q) + g v_{m+1} (e_mᵀ Q).
    int keep = std::min(m - 1, std::max(wanted + (m - wanted) / 2, wanted));
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
    const Vector next = V.col(built);
    const Eigen::RowVectorXd coupling = beta * Q.row(built - 1);
    V.setZero();
    G.setZero();
    V.leftCols(columns) = kept_basis;
    V.col(columns) = next;
    G.topLeftCorner(columns, columns) = projected;
    G.row(columns).head(columns) = coupling;
    kept = columns;
    if (!V.allFinite()) break;
  }
  result.converged = result.residual <= options.tolerance;
  if (vectors == nullptr) {
    sort_multipliers(result.values);
    return result;
  }
  // Sorted with their vectors.
  std::vector<std::complex<double>> sorted = result.values;
  sort_multipliers(sorted);
  Eigen::MatrixXcd arranged(size, static_cast<Index>(sorted.size()));
  std::vector<bool> used(sorted.size(), false);
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    for (std::size_t j = 0; j < sorted.size(); ++j) {
      if (!used[j] && result.values[j] == sorted[i]) {
        arranged.col(static_cast<Index>(i)) = vectors->col(static_cast<Index>(j));
        used[j] = true;
        break;
      }
    }
  }
  *vectors = std::move(arranged);
  result.values = std::move(sorted);
  return result;
}

}  // namespace pwl::orbits
