#pragma once
// What the curves' runner asks of a bifurcation curve followed without the monodromy, and what
// every such defining system does the same way. Private to the orbits room.
//
// A matrix-free curve corrects a point by Newton–Krylov on its bordered system (newton_krylov.hpp),
// gives the curve's unit tangent from the same system, and the orbit's leading multipliers by
// Arnoldi; how it poses and solves its bordered system is its own (matrix_free_grazing.hpp: a
// gap's extreme, whose row is known by its products; matrix_free_bordered.hpp: a fold's, a period
// doubling's or a Neimark–Sacker point's condition, whose rows are known by directional
// derivatives): it gives its residual and its bordered solve, and the corrector and the tangent
// here are built on them. What they share besides is here too: the multipliers and GMRES's
// preconditioner.
#include <functional>
#include <optional>

#include "orbits/curve_systems.hpp"
#include "orbits/newton_krylov.hpp"
#include "orbits/open_structure_preconditioner.hpp"
#include "pwl/orbits/floquet_multipliers.hpp"

namespace pwl::orbits::curves_detail {

class MatrixFreeCurve {
 public:
  // `tolerance`: the orbits' (ShootingOptions::tolerance), relative to the state's size.
  explicit MatrixFreeCurve(double tolerance) : tolerance_(tolerance) {}
  virtual ~MatrixFreeCurve() = default;

  using Corrected = detail::NewtonKrylovPoint;  // its residual max(|F|∞, |condition|)
  // G(u) = 0 with τ · (u − prediction) = 0 from `guess` by Newton–Krylov: at most `iterations`
  // steps, to the shooting tolerance (relative to the state's size), polished on to `polish` while
  // each step shrinks the residual fourfold (CorrectorSettings::polish). Empty where it does not
  // converge, the motion cannot be integrated or u leaves the domain (newton_krylov.hpp, on the
  // curve's residual_norm and bordered_solve).
  std::optional<Corrected> correct(const Vector& guess, const Vector& prediction,
                                   const Vector& tau, int iterations, double polish);
  // The unit tangent of the curve at u, oriented like `previous`: [∂G/∂u; previousᵀ] z = e_last.
  // Not finite where GMRES fails.
  Vector tangent(const Vector& u, const Vector& previous);
  // The leading multipliers of the orbit at u by Arnoldi (ShootingOptions::arnoldi), warm-started
  // from `warm` (Ritz vectors of a point nearby); its Ritz vectors into `ritz`.
  virtual FloquetMultipliers multipliers(const Vector& u, const Eigen::MatrixXcd* warm,
                                         Eigen::MatrixXcd* ritz) = 0;

 protected:
  // The curve as a defining system: its domain and its state's scale.
  virtual const CurveSystem& curve() const = 0;
  // max(|F|∞, |the conditions|) at u; empty where it cannot be evaluated.
  virtual std::optional<double> residual_norm(const Vector& u) = 0;
  // [∂G/∂u; τᵀ] δ = [r; ρ] at u by GMRES to the relative residual `tolerance`: a Newton step
  // (r = −G(u), ρ = −arc) or, without `arc`, the tangent's system (r = 0, ρ = e_last). Empty where
  // it fails.
  virtual std::optional<Vector> bordered_solve(const Vector& u, const Vector& tau,
                                               std::optional<double> arc, double tolerance) = 0;

 private:
  double tolerance_;
};

// M v by the map of (p, q) over `period` forcing periods from y (replayed where the map recorded
// y), counted as a GMRES product (CurvesResult::krylov_products).
std::function<Vector(const Vector&)> monodromy_products(PlaneMaps& maps, const Vector& y, double p,
                                                        double q, int period);

// The leading multipliers of the orbit through y at (p, q) on its map's products (counted as
// CurvesResult::arnoldi_products), every one with |μ| > 1 − `margin` among them (at least
// ArnoldiOptions::margin): a curve whose condition puts a multiplier on the circle asks for a
// margin, so that its multiplier is reported even where many others lie outside the circle. By
// Davidson preconditioned by `open` where that is given and available, by Arnoldi otherwise, as
// on a one-parameter branch (orbits/leading_multipliers.hpp).
FloquetMultipliers leading_multipliers(PlaneMaps& maps, const Vector& y, double p, double q,
                                       int period, const detail::OpenStructurePreconditioner* open,
                                       const Eigen::MatrixXcd* warm, Eigen::MatrixXcd* ritz,
                                       double margin = 0.0);

// The open structure's (M0 − σI)⁻¹, GMRES's preconditioner on a curve: built from the structure
// at the curve's start (where ShootingOptions::precondition asks for it) and retimed to each
// point's forcing period. Where the second parameter changes the linear structure (its damping,
// masses or stiffnesses) it stays that of the start, which only slows GMRES.
class CurvePreconditioner {
 public:
  CurvePreconditioner(PlaneMaps& maps, int period, double p0, double q0, double shift);
  // Null where it is not available (non-classical damping, or not asked for). With `kappa`, the
  // inverse of M0² − 2κM0 + I instead (OpenStructurePreconditioner::set_quadratic).
  const detail::OpenStructurePreconditioner* at(double p, double q,
                                                std::optional<double> kappa = {});

 private:
  PlaneMaps& maps_;
  int period_;
  std::optional<detail::OpenStructurePreconditioner> open_;
};

}  // namespace pwl::orbits::curves_detail
