#pragma once
// The bordered linear system of matrix-free continuation, solved by GMRES on products of the
// monodromy. Private to the orbits room.
//
//     [ M − I   b ] [ x ]   [ r ]
//     [  cᵀ     d ] [ s ] = [ ρ ]
//
// with M the monodromy (known only by its products M v, each a tangent integration of the map,
// replayed from one recorded integration where the integrator records its tangent), b = ∂F/∂p,
// and the border row (cᵀ, d) the continuation's: the tangent of the branch for the corrector's
// arclength condition, or the previous tangent for the new one. The border makes the matrix
// regular at a fold, where M − I alone is singular (H. B. Keller, in Applications of Bifurcation
// Theory, Academic Press 1977, 359-384; the matrix-free form for periodic orbits: K. Lust,
// D. Roose, A. Spence and A. R. Champneys, SIAM J. Sci. Comput. 19 (1998) 1188-1209).
//
// Preconditioning. GMRES is right-preconditioned by the inverse of the same bordered matrix with
// M replaced by the open structure's monodromy M0 (open_structure_preconditioner.hpp: modal 2 x 2
// blocks), applied by block elimination: with A0 = M0 − I, z_b = A0⁻¹ b, 
//
//     s = (ρ − cᵀ A0⁻¹ r) / (d − cᵀ z_b),   x = A0⁻¹ r − s z_b,
//
// one A0⁻¹ product per application (z_b once per system). Where M = M0 (the springs never act
// during the orbit) this is the exact inverse and GMRES converges in one product; otherwise the
// preconditioned operator is the identity plus what the contacts change, which is what the slow
// long-wave modes of a chain (many multipliers near 1) no longer dominate. Where the eliminated
// pivot d − cᵀ z_b vanishes (the border orthogonal to A0⁻¹'s image of b) the border is left
// unpreconditioned: diag(A0⁻¹, 1). Without the open structure's inverse (non-classical damping)
// GMRES runs unpreconditioned.
#include <cmath>
#include <functional>
#include <utility>

#include "orbits/gmres.hpp"
#include "orbits/open_structure_preconditioner.hpp"
#include "pwl/types.hpp"

namespace pwl::orbits::detail {

class BorderedKrylov {
 public:
  // `product(v)` returns M v. `open` may be null or unavailable (no preconditioning).
  BorderedKrylov(std::function<Vector(const Vector&)> product,
                 const OpenStructurePreconditioner* open, Vector b, Vector c, double d)
      : product_(std::move(product)), b_(std::move(b)), c_(std::move(c)), d_(d) {
    if (open != nullptr && open->available()) {
      open_ = open;
      z_b_ = open_->apply(b_);
      pivot_ = d_ - c_.dot(z_b_);
      const double size = std::abs(d_) + c_.norm() * z_b_.norm();
      eliminate_ = std::isfinite(pivot_) && std::abs(pivot_) > 1e-10 * size;
    }
  }

  // Solves to |residual| <= tolerance |[r; ρ]| (2-norms) from zero, at most `restarts` + 1
  // cycles of `dimension` products. Returns what GMRES reached.
  GmresResult solve(const Vector& r, double rho, Vector& x, double& s, double tolerance,
                    int dimension, int restarts) const {
    const Index n = r.size();
    Vector rhs(n + 1);
    rhs << r, rho;
    const auto apply = [&](const Vector& v) -> Vector {
      const Vector w = precondition(v);
      Vector out(n + 1);
      out.head(n) = product_(w.head(n)) - w.head(n) + b_ * w(n);
      out(n) = c_.dot(w.head(n)) + d_ * w(n);
      return out;
    };
    Vector u;
    const GmresResult g = gmres(apply, rhs, u, tolerance, dimension, restarts);
    const Vector z = precondition(u);
    x = z.head(n);
    s = z(n);
    return g;
  }

 private:
  Vector precondition(const Vector& v) const {
    if (open_ == nullptr) return v;
    const Index n = v.size() - 1;
    Vector out(n + 1);
    const Vector a = open_->apply(v.head(n));
    if (eliminate_) {
      out(n) = (v(n) - c_.dot(a)) / pivot_;
      out.head(n) = a - out(n) * z_b_;
    } else {
      out.head(n) = a;
      out(n) = v(n);
    }
    return out;
  }

  std::function<Vector(const Vector&)> product_;
  const OpenStructurePreconditioner* open_ = nullptr;
  Vector b_, c_, z_b_;
  double d_ = 0.0, pivot_ = 0.0;
  bool eliminate_ = false;
};

}  // namespace pwl::orbits::detail
