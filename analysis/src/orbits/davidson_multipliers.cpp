// The leading Floquet multipliers by a preconditioned Davidson iteration (the declaration in
// pwl/orbits/floquet_multipliers.hpp says what and why). References: E. R. Davidson, J. Comput.
// Phys. 17 (1975) 87-94 (the method); J. Olsen, P. Jørgensen and J. Simons, Chem. Phys. Lett.
// 169 (1990) 463-472 (the correction orthogonal to the Ritz vector, without which an exact
// preconditioner returns the Ritz vector itself and the iteration stalls); G. L. G. Sleijpen and
// H. A. van der Vorst, SIAM J. Matrix Anal. Appl. 17 (1996) 401-425 (Olsen's correction as one
// step of Jacobi-Davidson's correction equation, and thick restarts to the leading Ritz vectors);
// Y. Saad, Numerical Methods for Large Eigenvalue Problems, 2nd ed., SIAM 2011, §8.3.
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <random>

#include "orbits/multiplier_sorting.hpp"
#include "orbits/schur_vectors.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/floquet_multipliers.hpp"

namespace pwl::orbits {

namespace {

using Complex = std::complex<double>;

// Pairs corrected per step: the corrections of up to four pairs go to the map in one call, and
// the projected eigenproblem (dense, O(m³)) is solved once for them.
constexpr std::size_t kTargets = 4;

// The real basis V (orthonormal columns), W = M V and the projected matrix H = Vᵀ M V, grown
// column by column and kept consistent through restarts.
class DavidsonBasis {
 public:
  DavidsonBasis(const std::function<void(Matrix&)>& apply, Index size, int capacity)
      : apply_(apply), V_(size, capacity), W_(size, capacity), H_(capacity, capacity) {}

  int columns() const { return columns_; }
  Index size() const { return V_.rows(); }
  auto basis() const { return V_.leftCols(columns_); }
  auto image() const { return W_.leftCols(columns_); }
  Matrix projected() const { return H_.topLeftCorner(columns_, columns_); }

  // Adds what of each candidate column is new to the basis (a column whose new part is below
  // 1e-10 of it is left out), then their products, in one call of apply (the map spreads two
  // columns over two integrators). Returns how many were added. The candidates are orthogonalised
  // against the basis as one block, twice (classical Gram-Schmidt with reorthogonalisation: V is
  // read four times a step, not four times a column), then column by column against each other.
  int add(Matrix candidates) {
    const int before = columns_;
    const Vector original = candidates.colwise().norm().transpose();
    const auto usable = [&original](Index c) {
      return original(c) > 0 && std::isfinite(original(c));
    };
    for (Index c = 0; c < candidates.cols(); ++c) {
      if (!usable(c)) candidates.col(c).setZero();
    }
    if (before > 0) {
      for (int pass = 0; pass < 2; ++pass) {
        const Matrix coefficients = V_.leftCols(before).transpose() * candidates;
        candidates.noalias() -= V_.leftCols(before) * coefficients;
      }
    }
    for (Index c = 0; c < candidates.cols() && columns_ < V_.cols(); ++c) {
      if (!usable(c)) continue;
      Vector x = candidates.col(c);
      Vector unused = Vector::Zero(columns_ - before);
      detail::project_out_twice(V_.middleCols(before, columns_ - before), x, unused);
      const double left = x.norm();
      if (!(left > 1e-10 * original(c))) continue;
      V_.col(columns_++) = x / left;
    }
    const int added = columns_ - before;
    if (added == 0) return 0;
    Matrix products = V_.middleCols(before, added);
    apply_(products);
    W_.middleCols(before, added) = products;
    // H(i, j) = v_iᵀ w_j: the new columns against the whole basis, the new rows against the old
    // columns.
    H_.block(0, before, columns_, added).noalias() = V_.leftCols(columns_).transpose() * products;
    H_.block(before, 0, added, before).noalias() =
        V_.middleCols(before, added).transpose() * W_.leftCols(before);
    return added;
  }

  // The basis becomes V Q (Q orthonormal, columns × k), and W and H with it.
  void restrict_to(const Matrix& Q) {
    const int k = static_cast<int>(Q.cols());
    const Matrix v = V_.leftCols(columns_) * Q;
    const Matrix w = W_.leftCols(columns_) * Q;
    const Matrix h = Q.transpose() * H_.topLeftCorner(columns_, columns_) * Q;
    V_.leftCols(k) = v;
    W_.leftCols(k) = w;
    H_.topLeftCorner(k, k) = h;
    columns_ = k;
  }

 private:
  const std::function<void(Matrix&)>& apply_;
  Matrix V_, W_, H_;
  int columns_ = 0;
};

// A Ritz pair of the basis: θ, its coefficients y (complex) and the residual |M u − θ u| / |u|.
struct RitzPair {
  Complex value;
  Eigen::VectorXcd coefficients;
  double residual = -1.0;  // not yet computed
};

// The reported pairs' Ritz vectors u = V y and their images M u = W y, all in two products of
// the basis with one real matrix (the pairs' coefficients' real and imaginary parts side by
// side): V and W are read once a step, not once a pair, which at 10^4 masses and a basis of
// hundreds of columns is what a step costs besides its products.
struct RitzVectors {
  Matrix u, w;  // columns 2j and 2j + 1: the real and imaginary parts of pair j's V y and W y

  RitzVectors(const DavidsonBasis& basis, const std::vector<RitzPair>& pairs) {
    const Index k = basis.columns();
    Matrix Y(k, 2 * static_cast<Index>(pairs.size()));
    for (std::size_t j = 0; j < pairs.size(); ++j) {
      Y.col(2 * static_cast<Index>(j)) = pairs[j].coefficients.real();
      Y.col(2 * static_cast<Index>(j) + 1) = pairs[j].coefficients.imag();
    }
    u.noalias() = basis.basis() * Y;
    w.noalias() = basis.image() * Y;
  }

  // Pair j's unit Ritz vector and its residual M u − θ u (|y| = |V y|, V orthonormal).
  Eigen::VectorXcd vector(std::size_t j, const RitzPair& pair) const {
    return part(u, j) / pair.coefficients.norm();
  }
  Eigen::VectorXcd residual(std::size_t j, const RitzPair& pair) const {
    return (part(w, j) - pair.value * part(u, j)) / pair.coefficients.norm();
  }

 private:
  static Eigen::VectorXcd part(const Matrix& x, std::size_t j) {
    const Index c = 2 * static_cast<Index>(j);
    Eigen::VectorXcd z(x.rows());
    z.real() = x.col(c);
    z.imag() = x.col(c + 1);
    return z;
  }
};

}  // namespace

FloquetMultipliers preconditioned_floquet_multipliers(const std::function<void(Matrix&)>& apply,
                                                      const ShiftedInverse& inverse, Index size,
                                                      const ArnoldiOptions& options,
                                                      const Eigen::MatrixXcd* warm,
                                                      Eigen::MatrixXcd* vectors) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  if (size < 1) throw InputError(fmt::format("operator size = {} must be >= 1", size));
  if (!inverse) throw InputError("preconditioned multipliers: no shifted inverse given");
  int wanted = static_cast<int>(std::min<Index>(options.count, size));
  // The basis: davidson_dimension columns, fewer where V and W would take more than 1 GiB (but
  // never fewer than Arnoldi's), at most the space.
  const Index affordable = (Index(1) << 30) / (16 * size);
  const int m = static_cast<int>(std::min<Index>(
      {std::max<Index>(std::min<Index>(options.davidson_dimension, affordable),
                       std::min(options.krylov_dimension, options.davidson_dimension)),
       size}));
  const double edge = 1.0 - options.margin;

  // The start: the warm point's real Schur vectors (schur_vectors.hpp: an orthonormal basis of
  // the invariant subspace of its leading multipliers, at most half the basis less three), a fixed
  // random vector, and the preconditioner's (M0 − I)⁻¹ of it, which lifts the modes near 1 (a
  // long chain's long waves).
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> normal;
  Vector random(size);
  for (Index i = 0; i < size; ++i) random(i) = normal(rng);
  random /= random.norm();
  std::vector<Vector> start;
  if (warm != nullptr && warm->rows() == size) {
    const Matrix schur = detail::real_schur_vectors(*warm, std::max(0, m / 2 - 3));
    for (Index c = 0; c < schur.cols(); ++c) start.emplace_back(schur.col(c));
  }
  start.push_back(random);
  const Eigen::VectorXcd lifted = inverse(random.cast<Complex>(), Complex(1.0, 0.0));
  if (lifted.allFinite()) start.emplace_back(lifted.real());
  Matrix first(size, static_cast<Index>(start.size()));
  for (std::size_t c = 0; c < start.size(); ++c) first.col(static_cast<Index>(c)) = start[c];

  // Room for the basis and one more step's corrections beyond m.
  const int room = 2 * static_cast<int>(kTargets);
  DavidsonBasis basis(apply, size, m + room);
  basis.add(std::move(first));

  FloquetMultipliers result;
  result.method = FloquetMultipliers::Method::davidson;
  result.complete = wanted == size;
  int restarts = 0;
  std::vector<RitzPair> pairs;  // the reported ones, a complex pair once (θ with Im θ > 0)
  bool invariant = false;
  while (true) {
    const int k = basis.columns();
    invariant = k == size;
    Eigen::EigenSolver<Matrix> eig(basis.projected());
    if (eig.info() != Eigen::Success) throw Error("davidson: the Ritz eigenproblem failed");
    const Eigen::VectorXcd theta = eig.eigenvalues();
    const Eigen::MatrixXcd Y = eig.eigenvectors();
    std::vector<int> order(k);
    for (int i = 0; i < k; ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
      const double mx = std::abs(theta(x)), my = std::abs(theta(y));
      if (std::abs(mx - my) > 1e-14 * std::max(mx, my)) return mx > my;
      return theta(x).imag() > theta(y).imag();
    });
    // The reported set: the leading `wanted` values, a complex pair whole (its second half joins
    // where the count would cut it); with the whole space spanned (every Ritz value exact), on
    // until the first value below the band, as Arnoldi reports it.
    pairs.clear();
    int reported = 0;
    for (int i : order) {
      if (theta(i).imag() < 0.0) continue;  // its conjugate stands for it
      const bool band_goes_on =
          invariant && !pairs.empty() && std::abs(pairs.back().value) > edge;
      if (reported >= wanted && !band_goes_on) break;
      pairs.push_back({theta(i), Y.col(i)});
      reported += theta(i).imag() > 0.0 ? 2 : 1;
    }
    // Residuals in order; the first kTargets pairs that have not converged get their corrections.
    const double scale = std::max(1.0, pairs.empty() ? 1.0 : std::abs(pairs.front().value));
    std::vector<std::size_t> targets;
    double worst = 0.0;
    const RitzVectors ritz(basis, invariant ? std::vector<RitzPair>{} : pairs);
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      pairs[i].residual = invariant ? 0.0 : ritz.residual(i, pairs[i]).norm() / scale;
      worst = std::max(worst, pairs[i].residual);
      if (pairs[i].residual > options.tolerance && targets.size() < kTargets) targets.push_back(i);
    }
    result.residual = worst;
    const bool converged = targets.empty();
    const double smallest = pairs.empty() ? 0.0 : std::abs(pairs.back().value);
    if (converged) {
      // Converged with the smallest still in the band: twice as many (up to half the basis), or,
      // where the basis can hold the whole space (a small structure), all of them: the space is
      // then spanned and the band reported whole, as Arnoldi reports it.
      if (smallest > edge && !invariant && wanted < size && (4 * wanted <= m || m == size)) {
        wanted = static_cast<int>(4 * wanted <= m ? std::min<Index>(2 * wanted, size) : size);
        result.complete = wanted == size;
        continue;
      }
      break;
    }
    if (invariant) break;

    // The corrections of the target pairs (θ, u), r = M u − θ u, u of unit norm.
    Matrix candidates(size, 2 * static_cast<Index>(targets.size()));
    Index filled = 0;
    for (const std::size_t target : targets) {
      const RitzPair& pair = pairs[target];
      const Eigen::VectorXcd u = ritz.vector(target, pair);
      const Eigen::VectorXcd r = ritz.residual(target, pair);
      const Eigen::VectorXcd Kr = inverse(r, pair.value);
      const Eigen::VectorXcd Ku = inverse(u, pair.value);
      Eigen::VectorXcd t;
      const Complex denominator = u.dot(Ku);
      if (Kr.allFinite() && Ku.allFinite() && std::abs(denominator) > 1e-300) {
        t = -Kr + (u.dot(Kr) / denominator) * Ku;
      } else {
        t = r;  // no usable preconditioner here: the residual itself (as Arnoldi would grow)
      }
      candidates.col(filled++) = t.real();
      if (pair.value.imag() != 0.0) candidates.col(filled++) = t.imag();
    }
    candidates.conservativeResize(Eigen::NoChange, filled);

    bool restarted = false;  // then `pairs` belong to the basis before the restart
    if (basis.columns() < m && basis.columns() + candidates.cols() > m) {
      // What fits before the basis is full (all of the space, where m is its size).
      candidates.conservativeResize(Eigen::NoChange, m - basis.columns());
    } else if (basis.columns() + candidates.cols() > m) {
      if (restarts == options.max_restarts) break;
      ++restarts;
      // Thick restart to the span of the leading Ritz vectors (real and imaginary parts), more of
      // them than wanted, a pair whole or not at all.
      const int keep = std::max(2, std::min(m - 2, std::max(wanted + (m - wanted) / 2, wanted)));
      Matrix Z(k, keep);
      int kept = 0;
      for (int i : order) {
        if (theta(i).imag() < 0.0) continue;
        if (theta(i).imag() == 0.0) {
          if (kept + 1 > keep) break;
          Z.col(kept++) = Y.col(i).real();
        } else {
          if (kept + 2 > keep) break;
          Z.col(kept++) = Y.col(i).real();
          Z.col(kept++) = Y.col(i).imag();
        }
      }
      if (kept == 0) break;
      const Eigen::HouseholderQR<Matrix> qr(Z.leftCols(kept));
      basis.restrict_to(qr.householderQ() * Matrix::Identity(k, kept));
      restarted = true;
    }
    if (basis.add(candidates) == 0) {
      // The correction lies in the basis already: a fresh random direction keeps it growing.
      Matrix fresh(size, 1);
      for (Index i = 0; i < size; ++i) fresh(i, 0) = normal(rng);
      // Nothing new at all: stop, unless a restart just changed the basis, whose Ritz pairs the
      // next pass forms (each such pass spends a restart, so this ends).
      if (basis.add(fresh) == 0 && !restarted) break;
    }
  }

  result.values.clear();
  for (const RitzPair& pair : pairs) {
    result.values.push_back(pair.value);
    if (pair.value.imag() != 0.0) result.values.push_back(std::conj(pair.value));
  }
  result.complete = result.complete || static_cast<Index>(result.values.size()) == size;
  result.converged = result.residual <= options.tolerance;
  std::vector<std::complex<double>> by_modulus = result.values;
  detail::sort_multipliers(by_modulus);
  result.band_covered =
      result.complete || (result.converged && !by_modulus.empty() && std::abs(by_modulus.back()) <= edge);
  if (vectors == nullptr) {
    result.values = std::move(by_modulus);
    return result;
  }
  vectors->resize(size, static_cast<Index>(result.values.size()));
  Index c = 0;
  const RitzVectors ritz(basis, pairs);
  for (std::size_t j = 0; j < pairs.size(); ++j) {
    const RitzPair& pair = pairs[j];
    Eigen::VectorXcd x = ritz.vector(j, pair);
    x /= x.norm();
    vectors->col(c++) = x;
    if (pair.value.imag() != 0.0) vectors->col(c++) = x.conjugate();
  }
  detail::sort_multipliers(result.values, *vectors);
  return result;
}

}  // namespace pwl::orbits
