#pragma once
// The grazing curve of one spring without the monodromy: the defining system of GrazingSystem
// (the orbit's equations F(y; p, q) = φ_kT(y) − y = 0 and γ(y; p, q) = 0, γ the largest or
// smallest value of the spring's gap function along the orbit) corrected by Newton–Krylov, for
// the structures whose monodromy is too large to form (a chain of a thousand masses and more).
//
// Each Newton step solves the doubly bordered system
//
//     [ M − I   ∂F/∂p̂   ∂F/∂q̂ ] [ δy ]     [ F   ]
//     [ ∇γᵀ     ∂γ/∂p̂   ∂γ/∂q̂ ] [ δp̂ ] = − [ γ   ]
//     [ τ_yᵀ    τ_p̂     τ_q̂   ] [ δq̂ ]     [ arc ]
//
// by GMRES (bordered_krylov.hpp, two borders). M is known by its products; so is the row ∇γᵀ: by
// the envelope theorem (ġ = 0 at the extreme's time t*) ∇γᵀ v = e_sᵀ Φ(t*) v, the gap direction
// of spring s times the state transition matrix at t*, a forward tangent integration to t*. A
// product is one tangent integration over the period split at t*, Φ(kT) v = Φ(kT, t*) Φ(t*) v,
// which gives both at the cost of one: the two arcs are carried by two maps of the same (p, q), so
// that each records its arc once per Newton step and replays it for the products that follow
// (StroboscopicMap, where the integrator records). The preconditioner takes ∇γ as unknown (zero):
// it differs from the operator by that one row, which costs GMRES about one product (at t* = 0
// the row is the gap direction itself, and the preconditioner has it). The parameter columns, ∂γ/∂p̂ and ∂γ/∂q̂ come from
// central differences (4 integrations over the period, 4 to t*), as in the dense system; the
// maps of the point's (p, q) are pinned in their cache meanwhile, so that what they recorded
// survives. A fixed-grid method stops at the grid time nearest t*: the row is then an
// approximation, which slows Newton to a linear rate without moving the solution (γ itself is the
// extreme as the orbit's profile locates it: on the exact motion for the exact solver, by
// interpolation between the steps of a fixed-grid method, as for the dense system). Only an
// integrator that records its tangent map (the banded switching PIM) replays; for the others each
// product integrates both arcs. GMRES is preconditioned by the open structure's inverse
// (matrix_free_curve.hpp, CurvePreconditioner).
//
// The bordered form of periodic-orbit continuation without the monodromy: K. Lust, D. Roose,
// A. Spence and A. R. Champneys, SIAM J. Sci. Comput. 19 (1998) 1188-1209. The grazing condition
// as a defining system: F. Colombo and F. Dercole, SIAM J. Appl. Dyn. Syst. 9(1), 2010. The
// Newton loop and its forcing: newton_krylov.hpp.
#include <optional>

#include "orbits/curve_systems.hpp"
#include "orbits/gmres.hpp"
#include "orbits/matrix_free_curve.hpp"

namespace pwl::orbits::curves_detail {

class MatrixFreeGrazing : public GrazingSystem, public MatrixFreeCurve {
 public:
  MatrixFreeGrazing(PlaneMaps& maps, int period, Index n, double p_scale, double q_scale,
                    int spring, bool at_largest, double p0, double q0);

  FloquetMultipliers multipliers(const Vector& u, const Eigen::MatrixXcd* warm,
                                 Eigen::MatrixXcd* ritz) override;

 protected:
  const CurveSystem& curve() const override { return *this; }
  std::optional<double> residual_norm(const Vector& u) override;
  std::optional<Vector> bordered_solve(const Vector& u, const Vector& tau,
                                       std::optional<double> arc, double tolerance) override;

 private:
  // What a Newton step or a tangent needs at u: the residuals, the extreme's (grid) time and the
  // state there, the parameter columns and ∂γ.
  struct Linearised {
    Vector F;
    double gamma = 0.0;
    double t = 0.0;
    Vector at_t;     // the state at t
    Matrix B;        // n × 2: ∂F/∂p̂, ∂F/∂q̂
    double gamma_p = 0.0, gamma_q = 0.0;
  };
  bool residuals(const Vector& u, Linearised& l);
  bool linearise(const Vector& u, Linearised& l);
  // Solves [J; τᵀ] [δ] = [r; ρ] (J: the system's Jacobian at u, as linearised).
  bool solve(const Vector& u, const Linearised& l, const Vector& tau, const Vector& r,
             const Vector& rho, Vector& delta, double tolerance);
  CurvePreconditioner open_;
  // GMRES's recycled subspace (gmres.hpp), kept across a solve's restarts and, with
  // ShootingOptions::gmres_reform, carried from one step's operator to the next.
  detail::RecycledSubspace space_;
  // The residuals of the last u evaluated (the tangent at a corrected point reuses them).
  Linearised last_;
  Vector last_at_;
};

}  // namespace pwl::orbits::curves_detail
