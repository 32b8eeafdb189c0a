#pragma once
// A preconditioner for Newton–Krylov shooting on a long chain: the inverse of J0 = M0 − I, where M0
// is the monodromy of the structure with every gap spring open (the linear structure M, C, K).
//
// Why it is needed. A lightly damped chain's low modes barely decay over a period, so the
// multipliers of M lie on a ring near the unit circle, and the eigenvalues of J = M − I on a circle
// through 0 with many close to 0 (μ ≈ 1 + iω_k T for the slow modes): unpreconditioned GMRES then
// needs about as many products as there are such modes, and restarted GMRES stagnates. The slow,
// long-wave modes are what the open structure describes well (a local contact changes them
// little), so J0⁻¹ J has its eigenvalues clustered near 1 except for the few the contacts move.
//
// How. When the damping is classical (C diagonal in the modes of K φ = ω² M φ, as for Rayleigh
// damping C = aM + bK, which the paper's chain has), the open structure decouples into 2 x 2 modal
// blocks, J0 is block-diagonal in modal coordinates (q = Φ^T M x), and J0⁻¹ costs two products
// with the n x n modal matrix per application. The modes come from one dense eigen-decomposition
// (O(n³) once). With a diagonal mass matrix (every chain) it is the symmetric problem
// K̃ ψ = ω² ψ, K̃ = M^-½ K M^-½ and φ = M^-½ ψ, and when K̃ is tridiagonal (a chain of nearest
// neighbours) its QR iteration starts from K̃ itself, with no Householder reduction and no
// reduced basis to form (the whole set-up 1.52 s -> 0.79 s for the paper's 1000-mass chain).
// A uniform fixed-free chain (equal masses and springs, Rayleigh damping: the paper's chain) has
// its modes in closed form and goes to and from them by sine transforms (fixed_free_chain_modes.hpp):
// no decomposition and no n x n matrix, O(n log n) per application, which is what makes 10^4 masses
// and more affordable (the decomposition would take O(n³) and Φ 8 n² bytes).
// Classical damping is checked column by column: Φ^T C Φ is diagonal exactly when
// C φ_k = d_k M φ_k for every mode, and since M^½ Φ is orthogonal, column k of Φ^T C Φ − diag(d)
// has the 2-norm of M^-½ (C φ_k − d_k M φ_k): sparse products, O(n² · bandwidth), instead of two
// dense n x n products. Without classical damping the preconditioner is not available and
// shooting runs unpreconditioned. The eigenvalue algorithms: the symmetric QR iteration (Golub &
// Van Loan, Matrix Computations, 4th ed., §8.3), as Eigen's SelfAdjointEigenSolver implements it.
//
// Reference: right preconditioning of Newton–Krylov, D. A. Knoll and D. E. Keyes, J. Comput. Phys.
// 193 (2004) 357-397, §3; the modal decoupling under classical damping, T. K. Caughey and
// M. E. J. O'Kelly, J. Appl. Mech. 32 (1965) 583-588.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <complex>
#include <optional>
#include <vector>

#include "orbits/fixed_free_chain_modes.hpp"
#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/model/gap_structure.hpp"

namespace pwl::orbits::detail {

class OpenStructurePreconditioner {
 public:
  // For the map over time `tau` (k forcing periods), shifted by σ = `shift`: (M0 − σ I)⁻¹. σ = 1
  // is the orbit's Jacobian M − I; σ = −1 is M + I, the matrix of a period doubling's condition
  // (singular where a multiplier is −1), whose open-structure inverse is as cheap.
  OpenStructurePreconditioner(const GapStructure& structure, double tau, double shift = 1.0)
      : shift_(shift) {
    const Index n = structure.dofs();
    Vector omega2, modal_damping;
    if (auto chain = uniform_chain_modes(structure, modal_damping)) {
      chain_.emplace(std::move(*chain));
      omega2 = chain_->omega2();
    } else if (!banded_layout(structure).diagonal_mass) {
      // The generalised problem, dense, and Φ^T C Φ formed whole.
      const Matrix M = Matrix(structure.mass);
      Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> modes(Matrix(structure.stiffness), M);
      if (modes.info() != Eigen::Success) return;
      phi_ = modes.eigenvectors();  // Φ^T M Φ = I
      const Matrix D = phi_.transpose() * (structure.damping * phi_);
      const double scale = std::max(1e-300, D.cwiseAbs().maxCoeff());
      const Matrix off = D - Matrix(D.diagonal().asDiagonal());
      if (off.cwiseAbs().maxCoeff() > 1e-8 * scale) return;  // not classical damping
      omega2 = modes.eigenvalues();
      modal_damping = D.diagonal();
    } else {
      const Vector root_inverse_mass = structure.mass.diagonal().cwiseSqrt().cwiseInverse();
      const SparseMatrix scaled = root_inverse_mass.asDiagonal() * structure.stiffness *
                                  root_inverse_mass.asDiagonal();  // K̃
      Eigen::SelfAdjointEigenSolver<Matrix> modes;
      if (bandwidth(scaled) <= 1) {
        Vector main(n), sub = Vector::Zero(std::max<Index>(n - 1, 0));
        for (Index i = 0; i < n; ++i) {
          main(i) = scaled.coeff(i, i);
          if (i + 1 < n) sub(i) = scaled.coeff(i + 1, i);
        }
        modes.computeFromTridiagonal(main, sub, Eigen::ComputeEigenvectors);
      } else {
        modes.compute(Matrix(scaled));
      }
      if (modes.info() != Eigen::Success) return;
      phi_ = root_inverse_mass.asDiagonal() * modes.eigenvectors();  // Φ^T M Φ = I
      const Vector mass = structure.mass.diagonal();
      const Matrix damping_phi = structure.damping * phi_;  // C Φ, sparse times dense
      modal_damping = phi_.cwiseProduct(damping_phi).colwise().sum().transpose();
      const double scale = std::max(1e-300, modal_damping.cwiseAbs().maxCoeff());
      for (Index k = 0; k < n; ++k) {
        // |column k of Φ^T C Φ − diag(d)|_2 = |M^-½ (C φ_k − d_k M φ_k)|_2
        const double off =
            root_inverse_mass
                .cwiseProduct(damping_phi.col(k) - modal_damping(k) * mass.cwiseProduct(phi_.col(k)))
                .norm();
        if (off > 1e-8 * scale) return;  // not classical damping
      }
      omega2 = modes.eigenvalues();
    }
    if (!chain_) mass_ = structure.mass;
    omega2_ = std::move(omega2);
    modal_damping_ = std::move(modal_damping);
    available_ = true;
    retime(tau);
  }

  bool available() const { return available_; }
  // Whether the modes are the uniform chain's closed form (no decomposition, no n x n matrix).
  bool closed_form() const { return chain_.has_value(); }
  double time() const { return tau_; }
  double shift() const { return shift_; }

  // The inverse of M0² − 2κ M0 + I instead (kappa set) or of M0 − σI again (kappa empty): a
  // Neimark–Sacker curve's condition, singular where a pair of multipliers is e^{±iω} with
  // cos ω = κ, has the same 2 x 2 modal blocks (O(n) to change).
  void set_quadratic(std::optional<double> kappa) {
    if (kappa == kappa_) return;
    kappa_ = kappa;
    retime(tau_);
  }

  // The same structure's map over another time (a continuation in the forcing frequency, whose
  // period changes and whose structure does not): the 2 x 2 blocks again, the modes kept (O(n)).
  void retime(double tau) {
    tau_ = tau;
    if (!available_) return;
    const Index n = omega2_.size();
    inverse_.resize(n);
    exp_.resize(n);
    for (Index k = 0; k < n; ++k) {
      const double w2 = std::max(0.0, omega2_(k));
      const Eigen::Matrix2d E = exp2x2(w2, modal_damping_(k), tau);
      exp_[k] = E;
      const Eigen::Matrix2d J =
          kappa_ ? Eigen::Matrix2d(E * E - 2 * *kappa_ * E + Eigen::Matrix2d::Identity())
                 : Eigen::Matrix2d(E - shift_ * Eigen::Matrix2d::Identity());
      const double det = J.determinant();
      inverse_[k] = std::abs(det) > 1e-12 ? Eigen::Matrix2d(J.inverse())
                                          : Eigen::Matrix2d(-Eigen::Matrix2d::Identity());
    }
  }

  // J0⁻¹ r for a state vector r = [r_x; r_v]: the modal coordinates q = Φ^T M r of each half,
  // the 2 x 2 blocks, and back (Φ z). Matrix-vector products: a two-column product would pack Φ
  // for the matrix-matrix kernel on every call, which costs more than a second pass over it.
  // A uniform fixed-free chain goes to its modes and back by sine transforms instead (O(n log n)).
  // Not for concurrent calls on one object (the transforms share their work space).
  Vector apply(const Vector& r) const {
    const Index n = omega2_.size();
    Vector qx, qv;
    to_modal(r, qx, qv);
    Vector zx(n), zv(n);
    for (Index k = 0; k < n; ++k) {
      const Eigen::Vector2d z = inverse_[k] * Eigen::Vector2d(qx(k), qv(k));
      zx(k) = z(0);
      zv(k) = z(1);
    }
    return from_modal(zx, zv);
  }

  // (M0 − σI)⁻¹ r for a complex shift σ and a complex r: the preconditioner of the Davidson
  // iteration for the leading multipliers (preconditioned_floquet_multipliers), σ its current
  // Ritz value. The same modal coordinates (the real and imaginary parts each), each block
  // E_k − σI inverted in complex arithmetic (2 x 2: O(n) besides the transforms); a block
  // singular to rounding (σ on an eigenvalue of M0 to 1e-14) is taken as the identity.
  Eigen::VectorXcd shifted_inverse(const Eigen::VectorXcd& r, std::complex<double> sigma) const {
    const Index n = omega2_.size();
    Vector qxr, qvr, qxi, qvi;
    to_modal(r.real(), qxr, qvr);
    to_modal(r.imag(), qxi, qvi);
    Vector zxr(n), zvr(n), zxi(n), zvi(n);
    for (Index k = 0; k < n; ++k) {
      Eigen::Matrix2cd J = exp_[k].cast<std::complex<double>>();
      J(0, 0) -= sigma;
      J(1, 1) -= sigma;
      const std::complex<double> det = J(0, 0) * J(1, 1) - J(0, 1) * J(1, 0);
      const Eigen::Vector2cd q(std::complex<double>(qxr(k), qxi(k)),
                               std::complex<double>(qvr(k), qvi(k)));
      Eigen::Vector2cd z = q;
      if (std::abs(det) > 1e-14 * std::max(1.0, J.cwiseAbs().maxCoeff())) {
        z(0) = (J(1, 1) * q(0) - J(0, 1) * q(1)) / det;
        z(1) = (J(0, 0) * q(1) - J(1, 0) * q(0)) / det;
      }
      zxr(k) = z(0).real();
      zxi(k) = z(0).imag();
      zvr(k) = z(1).real();
      zvi(k) = z(1).imag();
    }
    Eigen::VectorXcd out(2 * n);
    out.real() = from_modal(zxr, zvr);
    out.imag() = from_modal(zxi, zvi);
    return out;
  }

 private:
  // The modal coordinates q = Φ^T M r of the two halves of a state vector, and back (Φ z).
  void to_modal(const Vector& r, Vector& qx, Vector& qv) const {
    const Index n = omega2_.size();
    if (chain_) {
      chain_->to_modal(r.head(n), r.tail(n), qx, qv);
    } else {
      qx = phi_.transpose() * (mass_ * r.head(n));
      qv = phi_.transpose() * (mass_ * r.tail(n));
    }
  }
  Vector from_modal(const Vector& zx, const Vector& zv) const {
    const Index n = omega2_.size();
    Vector out(2 * n);
    if (chain_) {
      chain_->from_modal(zx, zv, out.head(n), out.tail(n));
    } else {
      out.head(n).noalias() = phi_ * zx;
      out.tail(n).noalias() = phi_ * zv;
    }
    return out;
  }

  // exp(τ [[0, 1], [−ω², −c]]) in closed form (by the eigenvalues of the 2 x 2 block, which may be
  // real, complex or double).
  static Eigen::Matrix2d exp2x2(double w2, double c, double tau) {
    Eigen::Matrix2d A;
    A << 0.0, 1.0, -w2, -c;
    A *= tau;
    const double half_trace = 0.5 * A.trace();
    const double d = A.determinant();
    const std::complex<double> s = std::sqrt(std::complex<double>(half_trace * half_trace - d));
    const Eigen::Matrix2d B = A - half_trace * Eigen::Matrix2d::Identity();
    // exp(A) = e^{tr/2} (cosh s · I + sinh s / s · B)
    const double ch = std::cosh(s).real();
    const double sh_over_s = std::abs(s) < 1e-8 ? 1.0 + (s * s).real() / 6.0
                                                : (std::sinh(s) / s).real();
    return std::exp(half_trace) * (ch * Eigen::Matrix2d::Identity() + sh_over_s * B);
  }

  // The closed-form modes when the structure is a uniform fixed-free chain (M = m I, K = k L) with
  // Rayleigh damping C = a M + b K, and its modal damping a + b ω_k² in `modal_damping`; nothing
  // otherwise (the eigen-decomposition then decides). Entries are compared to 1e-13 of the largest.
  static std::optional<FixedFreeChainModes> uniform_chain_modes(const GapStructure& s,
                                                                Vector& modal_damping) {
    const Index n = s.dofs();
    if (n < 2 || !banded_layout(s).diagonal_mass) return std::nullopt;
    const double m = s.mass.coeff(0, 0);
    const Vector masses = s.mass.diagonal();
    if (!(m > 0) || (masses.array() - m).abs().maxCoeff() > 1e-13 * m) return std::nullopt;
    const double k = -s.stiffness.coeff(1, 0);
    const double b_off = -s.damping.coeff(1, 0);  // −C[1][0] = b k
    const double a_m = s.damping.coeff(0, 0) - 2.0 * b_off;  // C[0][0] = a m + 2 b k
    if (!(k > 0) || !std::isfinite(k)) return std::nullopt;
    // K = k L and C = a m I + (b k) L entry by entry, nothing stored off the three diagonals.
    const auto matches = [&](const SparseMatrix& A, double diagonal_shift, double factor) {
      const double tol = 1e-13 * std::max({std::abs(factor), std::abs(diagonal_shift), 1e-300});
      Index diagonal_count = 0, neighbour_count = 0;
      for (Index c = 0; c < A.outerSize(); ++c) {
        for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
          const Index i = it.row(), j = it.col();
          double expected = 0.0;
          if (i == j) {
            expected = diagonal_shift + factor * (i + 1 < n ? 2.0 : 1.0);
            ++diagonal_count;
          } else if (std::abs(i - j) == 1) {
            expected = -factor;
            ++neighbour_count;
          }
          if (std::abs(it.value() - expected) > tol) return false;
        }
      }
      // A missing entry is a zero where one may be expected.
      if (std::abs(diagonal_shift) + std::abs(factor) == 0.0) return true;
      return diagonal_count == n && (factor == 0.0 || neighbour_count == 2 * (n - 1));
    };
    if (!matches(s.stiffness, 0.0, k) || !matches(s.damping, a_m, b_off)) return std::nullopt;
    FixedFreeChainModes modes(n, m, k);
    modal_damping = Vector::Constant(n, a_m / m) + (b_off / m) * modes.laplacian_eigenvalues();
    return modes;
  }

  // The largest |i − j| of a stored non-zero.
  static Index bandwidth(const SparseMatrix& A) {
    Index w = 0;
    for (Index c = 0; c < A.outerSize(); ++c) {
      for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
        if (it.value() != 0.0) w = std::max<Index>(w, std::abs(it.row() - it.col()));
      }
    }
    return w;
  }

  bool available_ = false;
  double tau_ = 0.0;
  double shift_ = 1.0;
  std::optional<double> kappa_;
  Vector omega2_, modal_damping_;
  Matrix phi_;  // the general paths' modal matrix (Φ^T M Φ = I)
  SparseMatrix mass_;
  std::optional<FixedFreeChainModes> chain_;  // instead of Φ for a uniform fixed-free chain
  std::vector<Eigen::Matrix2d> inverse_;
  std::vector<Eigen::Matrix2d> exp_;  // E_k = exp(τ A_k), the modal blocks of M0
};

}  // namespace pwl::orbits::detail
