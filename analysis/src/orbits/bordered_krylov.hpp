#pragma once
// The bordered linear systems of matrix-free continuation, solved by GMRES on products of the
// monodromy. Private to the orbits room.
//
//     [ M − σI   B ] [ x ]   [ r ]
//     [  Cᵀ      D ] [ s ] = [ ρ ]
//
// (σ = 1 for the orbit's equations; σ = −1 for the condition of a period doubling, M + I singular)
// with M the monodromy (known only by its products M v, each a tangent integration of the map,
// replayed from one recorded integration where the integrator records its tangent) and k borders:
// B (n × k), C (n × k), D (k × k). In one parameter k = 1: b = ∂F/∂p and the border row (cᵀ, d)
// the continuation's, the tangent of the branch for the corrector's arclength condition or the
// previous tangent for the new one. On a bifurcation curve in two parameters k = 2: B = [∂F/∂p,
// ∂F/∂q] and the rows are the curve's condition and the arclength condition. The border makes the
// matrix regular at a fold of the curve, where M − I alone is singular (H. B. Keller, in
// Applications of Bifurcation Theory, Academic Press 1977, 359-384; the matrix-free form for
// periodic orbits: K. Lust, D. Roose, A. Spence and A. R. Champneys, SIAM J. Sci. Comput. 19
// (1998) 1188-1209).
//
// Rows known only by their products. A border row may be known only by its products cᵀ v with
// tangent vectors, not as a vector: the gradient of a gap function's extreme along the orbit is
// the gap's row of the state transition matrix at the extreme's time, which a forward tangent
// integration gives as products and only n of them as a vector. The first `implicit_rows` rows
// are such: `product(v)` returns M v followed by their products, and C's first columns hold what
// the preconditioner takes for them (zeros where nothing better is known). The operator GMRES sees
// is exact; only the preconditioner differs from it, by one rank per such row, which costs GMRES
// about one product more each.
//
// Preconditioning. GMRES is right-preconditioned by the inverse of the same bordered matrix with
// M replaced by the open structure's monodromy M0 (open_structure_preconditioner.hpp: modal 2 x 2
// blocks), applied by block elimination: with A0 = M0 − σI, Z_B = A0⁻¹ B and the k × k Schur
// complement S = D − Cᵀ Z_B,
//
//     s = S⁻¹ (ρ − Cᵀ A0⁻¹ r),   x = A0⁻¹ r − Z_B s,
//
// one A0⁻¹ product per application (Z_B once per system). Where M = M0 (the springs never act
// during the orbit) and every row is known this is the exact inverse and GMRES converges in one
// product; otherwise the preconditioned operator is the identity plus what the contacts change,
// which is what the slow long-wave modes of a chain (many multipliers near 1) no longer dominate.
// Where S is nearly singular (its smallest singular value below 1e-10 of the borders' size) the
// borders are left unpreconditioned: diag(A0⁻¹, I). Without the open structure's inverse
// (non-classical damping) GMRES runs unpreconditioned.
#include <Eigen/SVD>
#include <cmath>
#include <functional>
#include <utility>

#include "orbits/gmres.hpp"
#include "orbits/open_structure_preconditioner.hpp"
#include "pwl/types.hpp"

namespace pwl::orbits::detail {

class BorderedKrylov {
 public:
  // `product(v)` returns M v, followed by the products of the first `implicit_rows` border rows
  // with v. `open` may be null or unavailable (no preconditioning); it inverts the open
  // structure's counterpart of M − σI (OpenStructurePreconditioner's shift σ; σ = 0 where
  // `product` gives another operator, such as M² − 2κM + I, and `open` its counterpart).
  BorderedKrylov(std::function<Vector(const Vector&)> product,
                 const OpenStructurePreconditioner* open, Matrix B, Matrix C, Matrix D,
                 Index implicit_rows = 0, double shift = 1.0)
      : product_(std::move(product)),
        B_(std::move(B)),
        C_(std::move(C)),
        D_(std::move(D)),
        implicit_(implicit_rows),
        shift_(shift) {
    // The operator's rows: the products stand in for C's first columns.
    C_known_ = C_;
    C_known_.leftCols(implicit_).setZero();
    if (open != nullptr && open->available()) {
      open_ = open;
      Z_B_.resize(B_.rows(), B_.cols());
      for (Index j = 0; j < B_.cols(); ++j) Z_B_.col(j) = open_->apply(B_.col(j));
      const Matrix S = D_ - C_.transpose() * Z_B_;
      const double size = D_.norm() + C_.norm() * Z_B_.norm();
      if (S.allFinite()) {
        const Eigen::JacobiSVD<Matrix> svd(S);
        if (svd.singularValues().minCoeff() > 1e-10 * size) {
          S_inverse_ = S.inverse();
          eliminate_ = S_inverse_.allFinite();
        }
      }
    }
  }
  // One border: [M − I, b; cᵀ, d] (the same algorithm as with k borders; the pivot's division is a
  // product with its inverse, equal to rounding).
  BorderedKrylov(std::function<Vector(const Vector&)> product,
                 const OpenStructurePreconditioner* open, const Vector& b, const Vector& c,
                 double d, double shift = 1.0)
      : BorderedKrylov(std::move(product), open, Matrix(b), Matrix(c), Matrix::Constant(1, 1, d),
                       0, shift) {}

  // Solves to |residual| <= tolerance |[r; ρ]| (2-norms) from zero, at most `restarts` + 1
  // cycles of `dimension` products, recycling through `recycled` where it is given (gmres.hpp:
  // the space lives in GMRES's preconditioned variable, and the caller says when the operator
  // changed). Returns what GMRES reached.
  GmresResult solve(const Vector& r, const Vector& rho, Vector& x, Vector& s, double tolerance,
                    int dimension, int restarts, RecycledSubspace* recycled = nullptr) const {
    const Index n = r.size(), k = borders();
    Vector rhs(n + k);
    rhs << r, rho;
    const auto apply = [&](const Vector& v) -> Vector {
      const Vector w = precondition(v);
      const Vector m = product_(w.head(n));
      Vector out(n + k);
      out.head(n) = m.head(n) - shift_ * w.head(n) + B_ * w.tail(k);
      out.tail(k) = C_known_.transpose() * w.head(n) + D_ * w.tail(k);
      if (implicit_ > 0) out.segment(n, implicit_) += m.segment(n, implicit_);
      return out;
    };
    Vector u;
    const GmresResult g = gmres(apply, rhs, u, tolerance, dimension, restarts, recycled);
    const Vector z = precondition(u);
    x = z.head(n);
    s = z.tail(k);
    return g;
  }
  // One border.
  GmresResult solve(const Vector& r, double rho, Vector& x, double& s, double tolerance,
                    int dimension, int restarts, RecycledSubspace* recycled = nullptr) const {
    Vector sv;
    const GmresResult g =
        solve(r, Vector::Constant(1, rho), x, sv, tolerance, dimension, restarts, recycled);
    s = sv(0);
    return g;
  }

  Index borders() const { return B_.cols(); }

 private:
  Vector precondition(const Vector& v) const {
    if (open_ == nullptr) return v;
    const Index k = borders(), n = v.size() - k;
    Vector out(n + k);
    const Vector a = open_->apply(v.head(n));
    if (eliminate_) {
      out.tail(k) = S_inverse_ * (v.tail(k) - C_.transpose() * a);
      out.head(n) = a - Z_B_ * out.tail(k);
    } else {
      out.head(n) = a;
      out.tail(k) = v.tail(k);
    }
    return out;
  }

  std::function<Vector(const Vector&)> product_;
  const OpenStructurePreconditioner* open_ = nullptr;
  Matrix B_, C_, C_known_, D_, Z_B_, S_inverse_;
  Index implicit_ = 0;
  double shift_ = 1.0;
  bool eliminate_ = false;
};

}  // namespace pwl::orbits::detail
