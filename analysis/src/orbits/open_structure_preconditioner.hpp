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
// with the n x n modal matrix per application. The modes come from one dense generalised
// eigen-decomposition (O(n³) once, about a second at n = 1000). Without classical damping the
// preconditioner is not available and shooting runs unpreconditioned.
//
// Reference: right preconditioning of Newton–Krylov, D. A. Knoll and D. E. Keyes, J. Comput. Phys.
// 193 (2004) 357-397, §3; the modal decoupling under classical damping, T. K. Caughey and
// M. E. J. O'Kelly, J. Appl. Mech. 32 (1965) 583-588.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <vector>

#include "pwl/model/gap_structure.hpp"

namespace pwl::orbits::detail {

class OpenStructurePreconditioner {
 public:
  // For the map over time `tau` (k forcing periods).
  OpenStructurePreconditioner(const GapStructure& structure, double tau) {
    const Matrix M = Matrix(structure.mass);
    const Matrix K = Matrix(structure.stiffness);
    const Matrix C = Matrix(structure.damping);
    Eigen::GeneralizedSelfAdjointEigenSolver<Matrix> modes(K, M);
    if (modes.info() != Eigen::Success) return;
    phi_ = modes.eigenvectors();  // Φ^T M Φ = I
    const Matrix D = phi_.transpose() * C * phi_;
    const double scale = std::max(1e-300, D.cwiseAbs().maxCoeff());
    const Matrix off = D - Matrix(D.diagonal().asDiagonal());
    if (off.cwiseAbs().maxCoeff() > 1e-8 * scale) return;  // not classical damping
    mass_phi_ = M * phi_;
    const Index n = K.rows();
    inverse_.resize(n);
    for (Index k = 0; k < n; ++k) {
      const double w2 = std::max(0.0, modes.eigenvalues()(k));
      const Eigen::Matrix2d E = exp2x2(w2, D(k, k), tau);
      const Eigen::Matrix2d J = E - Eigen::Matrix2d::Identity();
      const double det = J.determinant();
      inverse_[k] = std::abs(det) > 1e-12 ? Eigen::Matrix2d(J.inverse())
                                          : Eigen::Matrix2d(-Eigen::Matrix2d::Identity());
    }
    available_ = true;
  }

  bool available() const { return available_; }

  // J0⁻¹ r for a state vector r = [r_x; r_v].
  Vector apply(const Vector& r) const {
    const Index n = phi_.rows();
    const Vector qx = mass_phi_.transpose() * r.head(n);
    const Vector qv = mass_phi_.transpose() * r.tail(n);
    Vector zx(n), zv(n);
    for (Index k = 0; k < n; ++k) {
      const Eigen::Vector2d z = inverse_[k] * Eigen::Vector2d(qx(k), qv(k));
      zx(k) = z(0);
      zv(k) = z(1);
    }
    Vector out(2 * n);
    out.head(n) = phi_ * zx;
    out.tail(n) = phi_ * zv;
    return out;
  }

 private:
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

  bool available_ = false;
  Matrix phi_, mass_phi_;
  std::vector<Eigen::Matrix2d> inverse_;
};

}  // namespace pwl::orbits::detail
