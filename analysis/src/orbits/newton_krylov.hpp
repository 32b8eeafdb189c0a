#pragma once
// Inexact Newton on a bordered system whose Jacobian is known only by its products: the corrector
// of every matrix-free continuation (the one-parameter branch, continuation.cpp; the bifurcation
// curves, matrix_free_curve.hpp). Private to the orbits room.
//
// From `guess`, each step solves [∂G/∂u; τᵀ] δ = −[G(u); τ · (u − prediction)] by GMRES to a
// relative residual η that tightens as the residual falls, η = ½ tolerance / |G|∞ within
// [1e-10, 1e-2] (the forcing of S. C. Eisenstat and H. F. Walker, SIAM J. Sci. Comput. 17 (1996)
// 16-32): a loose solve far from the solution, a tight one near it. It converges when |G|∞ and the
// arclength condition are within the tolerance (relative to the state's size), and past it
// polishes as the dense corrector does (CorrectorSettings::polish): on to `polish` while each step
// shrinks the residual fourfold, the best iterate within the tolerance kept. It gives up where the
// residual grows fourfold in a step, where u leaves the domain, or where G or a step cannot be
// evaluated.
#include <functional>
#include <optional>

#include "pwl/types.hpp"

namespace pwl::orbits::detail {

// The pieces of one correction, as a problem gives them.
struct NewtonKrylovSystem {
  // |G(u)|∞ (for a curve: max(|F|∞, |condition|)); empty where it cannot be evaluated.
  std::function<std::optional<double>(const Vector& u)> residual;
  // The step δ from u, the last point `residual` evaluated: [∂G/∂u; τᵀ] δ = −[G(u); arc] to
  // GMRES's relative residual `eta`; empty where it fails.
  std::function<std::optional<Vector>(const Vector& u, double arc, double eta)> step;
  std::function<bool(const Vector& u)> admissible;
  std::function<double(const Vector& u)> scale;  // max(1, |state|∞)
};

struct NewtonKrylovPoint {
  Vector u;
  double residual = 0.0;  // the residual function's value at u
  int iterations = 0;
};

// At most `iterations` steps; `tolerance` relative to the scale. Empty where it does not converge.
std::optional<NewtonKrylovPoint> newton_krylov(const NewtonKrylovSystem& system,
                                               const Vector& guess, const Vector& prediction,
                                               const Vector& tau, int iterations, double polish,
                                               double tolerance);

}  // namespace pwl::orbits::detail
