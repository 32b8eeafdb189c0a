#include "pwl/orbits/floquet_multipliers.hpp"

#include <Eigen/Eigenvalues>
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
                                               Index size, const ArnoldiOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (size < 1) throw InputError(fmt::format("operator size = {} must be >= 1", size));
  const int wanted = static_cast<int>(std::min<Index>(options.count, size));
  const int m = static_cast<int>(std::min<Index>(options.krylov_dimension, size));

  std::mt19937 rng(options.seed);
  std::normal_distribution<double> normal;
  Vector start(size);
  for (Index i = 0; i < size; ++i) start(i) = normal(rng);

  FloquetMultipliers result;
  result.complete = wanted == size;
  for (int restart = 0; restart <= options.max_restarts; ++restart) {
    Matrix V = Matrix::Zero(size, m + 1);
    Matrix H = Matrix::Zero(m + 1, m);
    V.col(0) = start / start.norm();
    int built = m;
    for (int j = 0; j < m; ++j) {
      Matrix w = V.col(j);
      apply(w);
      // Modified Gram-Schmidt, twice (re-orthogonalisation keeps the basis orthonormal to
      // rounding when the multipliers are clustered).
      for (int pass = 0; pass < 2; ++pass) {
        for (int i = 0; i <= j; ++i) {
          const double h = V.col(i).dot(w.col(0));
          H(i, j) += h;
          w.col(0) -= h * V.col(i);
        }
      }
      const double beta = w.col(0).norm();
      H(j + 1, j) = beta;
      if (beta <= 1e-14 * H.col(j).head(j + 1).norm() || j + 1 == size) {
        built = j + 1;  // an invariant subspace: its Ritz values are exact
        break;
      }
      V.col(j + 1) = w.col(0) / beta;
    }
    const Matrix Hm = H.topLeftCorner(built, built);
    Eigen::EigenSolver<Matrix> eig(Hm);
    if (eig.info() != Eigen::Success) throw Error("arnoldi: the Hessenberg eigenproblem failed");
    std::vector<int> order(built);
    for (int i = 0; i < built; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      return std::abs(eig.eigenvalues()(a)) > std::abs(eig.eigenvalues()(b));
    });
    const double beta = built < H.rows() ? H(built, built - 1) : 0.0;
    const double scale = std::max(1.0, std::abs(eig.eigenvalues()(order[0])));
    double worst = 0;
    const int reported = std::min(wanted, built);
    for (int r = 0; r < reported; ++r) {
      const Eigen::VectorXcd s = eig.eigenvectors().col(order[r]);
      worst = std::max(worst, std::abs(beta) * std::abs(s(built - 1)) / s.norm() / scale);
    }
    result.values.clear();
    for (int r = 0; r < reported; ++r) result.values.push_back(eig.eigenvalues()(order[r]));
    result.residual = worst;
    if (worst <= options.tolerance || built < m) break;
    // Explicit restart from the sum of the wanted Ritz vectors (real and imaginary parts).
    start.setZero();
    for (int r = 0; r < reported; ++r) {
      const Eigen::VectorXcd s = eig.eigenvectors().col(order[r]);
      const Eigen::VectorXcd z = V.leftCols(built).cast<std::complex<double>>() * s;
      start += z.real() / std::max(z.real().norm(), 1e-300);
      if (z.imag().norm() > 0) start += z.imag() / z.imag().norm();
    }
    if (!start.allFinite() || start.norm() == 0) break;
  }
  result.converged = result.residual <= options.tolerance;
  sort_multipliers(result.values);
  return result;
}

}  // namespace pwl::orbits
