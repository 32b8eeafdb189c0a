#pragma once
// Periodic orbits by shooting: Newton's method on the fixed-point equation of the stroboscopic map,
//
//     F(y) = φ_{kT}(y) − y = 0,
//
// for a period-k orbit, y = [x; x'] at t = 0 mod T. Newton needs J = M − I with the monodromy
// M = ∂φ_{kT}/∂y, which the StroboscopicMap gives exactly for the methods with a tangent map (no
// saltation term: the vector field is continuous).
//
// Linear algebra by size. A small structure forms M (2n tangent columns, one integration) and
// solves J δ = −F by LU; its Floquet multipliers are then all the eigenvalues of the M of the last
// iteration. A long chain never forms M: J δ = −F is solved by GMRES on products M v (one
// integration of k periods with one tangent vector each; Y. Saad and M. H. Schultz, SIAM J. Sci.
// Stat. Comput. 7 (1986) 856-869), to a relative residual that tightens as F shrinks and loosens
// while Newton converges slowly (inexact Newton, S. C. Eisenstat and H. F. Walker, SIAM J. Sci.
// Comput. 17 (1996) 16-32), and the leading
// multipliers come from Arnoldi (floquet_multipliers.hpp). A lightly damped chain's slow modes put
// many eigenvalues of M − I near 0, where GMRES alone needs about one product per mode; GMRES is
// therefore right-preconditioned by the inverse of M0 − I of the structure with its springs open
// (modal 2 x 2 blocks when the damping is classical: analysis/src/orbits/
// open_structure_preconditioner.hpp), which clusters the spectrum near 1. The products of one
// Newton step (and Arnoldi's, at the answer) all start from one state: with an integrator that
// records its tangent map (the banded switching PIM) only the first integrates, the others replay
// it (stroboscopic_map.hpp). A product then costs the tangent's arithmetic, which grows with the
// pieces the springs' switches cut the steps into: on the 1000-mass chain of `pwl bench orbits`
// Newton's early iterates move whole stretches of the chain across the gaps (about 1000 switches
// a period, 60-100 ms a replayed product) while the orbit itself switches 14 times a period
// (about 6 ms).
//
// Multiple shooting. An orbit that is strongly unstable (|μ| ≫ 1) makes the single-shooting
// Jacobian badly conditioned and its Newton basin tiny. With `shots` = m > 1 the k periods are cut
// into m arcs of k/m periods each (m must divide k) or, for m = s·k, each period into s arcs of
// T/s (the step grid must divide them), and the unknowns are the m arc starts y_i with
// F_i = φ_{arc}(y_i) − y_{i+1 mod m} = 0 (block-cyclic Jacobian; U. M. Ascher, R. M. M. Mattheij
// and R. D. Russell, Numerical Solution of Boundary Value Problems for ODEs, SIAM 1995, ch. 4).
// Only the dense form supports it.
//
// Globalisation: a step that does not decrease |F|_2 enough is halved (backtracking) down to
// 1/1024; Newton stops with a ShootingError that says the residual reached when it cannot go on.
#include <functional>
#include <string>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/orbits/floquet_multipliers.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"

namespace pwl::orbits {

enum class ShootingSolver {
  automatic,  // dense up to dense_state_limit state components, Krylov beyond
  dense,      // form M, LU
  krylov,     // GMRES on M v products, Arnoldi for the leading multipliers
};

struct ShootingOptions {
  int period = 1;  // k: forcing periods per orbit
  int shots = 1;   // arcs of multiple shooting (1: single shooting)
  // Convergence: |F|_∞ <= tolerance · max(1, |y|_∞).
  double tolerance = 1e-10;
  int max_iterations = 40;
  ShootingSolver solver = ShootingSolver::automatic;
  Index dense_state_limit = 400;
  // Krylov: basis size of GMRES per Newton step and restarts.
  int gmres_dimension = 60;
  int gmres_restarts = 4;
  // Krylov: vectors GMRES carries from one solve to the next while the operator stays (GCRO-DR
  // recycling: the harmonic Ritz vectors of its smallest eigenvalues), and from one restart of a
  // solve to the next; 0 for none, fewer than gmres_dimension. It pays where one operator takes
  // several right-hand sides: the matrix-free bifurcation curves' inner solves (on the 1000-mass
  // chain's Neimark-Sacker curves 26% fewer GMRES products with 10).
  int gmres_recycled = 10;
  // Krylov: whether those vectors are also carried to a new operator (the next Newton iterate,
  // the next point of a branch or a curve) by forming their image under it again, `gmres_recycled`
  // products, as GCRO-DR does for a sequence of systems (gmres.hpp). Off by default: a new
  // operator starts afresh, since on these short, preconditioned solves the image costs more
  // products than the deflation saves (analysis/README.md, "Recycled Krylov subspaces").
  bool gmres_reform = false;
  // Krylov: the largest relative residual GMRES is asked for in a Newton step (η_max of
  // Eisenstat and Walker's forcing terms, their 0.9). The forcing starts at 1e-2 and tightens as
  // Newton converges; far from the orbit it may loosen up to this. On the 1000-mass chain of
  // `pwl bench orbits` a ceiling of 1e-2 instead cost 27.7 s against 19.5 s at 0.9 (more
  // Newton iterations, 42% fewer GMRES products).
  double max_forcing = 0.9;
  // Krylov: precondition by the inverse of the open structure's M0 − I when its damping is
  // classical (see the Krylov paragraph above); otherwise unpreconditioned.
  bool precondition = true;
  // Floquet multipliers: all for the dense form; the leading `floquet_count` for Krylov.
  bool multipliers = true;
  ArnoldiOptions arnoldi;
  // Progress (optional): called at the start of every Newton iteration with its number, the
  // residual |φ(y) − y|_∞ so far and the GMRES products spent (0 for the dense form). A long chain's
  // cold orbit takes minutes (6 min at 10^4 masses); a program shows this to say it is alive.
  std::function<void(int iteration, double residual, long products)> on_iteration;
  bool is_valid(std::string* why) const;
};

// "automatic", "dense", "krylov" and back (InputError naming the value otherwise).
std::string shooting_solver_name(ShootingSolver solver);
ShootingSolver parse_shooting_solver(const std::string& name);

struct PeriodicOrbit {
  Vector state;                  // y at t = 0 mod T, [x; x']
  int period = 1;                // k
  double forcing_period = 0.0;   // T
  double residual = 0.0;         // |φ_{kT}(y) − y|_∞ at the answer
  int iterations = 0;            // Newton iterations
  long evaluations = 0;          // integrations of the map (k periods each, tangent included)
  long tangent_replays = 0;      // tangent products replayed, not integrated (StroboscopicMap)
  bool exact_tangent = true;     // multipliers from the exact tangent (else forward differences)
  ShootingSolver solver = ShootingSolver::dense;  // the one used
  long krylov_products = 0;      // Krylov: products with M − I in GMRES, over all iterations
  bool preconditioned = false;   // Krylov: by the open structure (classical damping)
  FloquetMultipliers multipliers;
  Matrix monodromy;              // M at the answer (dense form only; empty otherwise)

  bool stable() const { return multipliers.stable(); }
};

// Newton did not converge: the message says why, with the residual reached.
class ShootingError : public Error {
 public:
  ShootingError(const std::string& message, double residual, int iterations)
      : Error(message), residual_(residual), iterations_(iterations) {}
  double residual() const { return residual_; }
  int iterations() const { return iterations_; }

 private:
  double residual_;
  int iterations_;
};

// The period-k orbit near `guess` ([x; x'] at t = 0 mod T). Throws ShootingError when Newton does
// not converge, InputError for invalid options or a guess of the wrong size, DivergenceError when
// the motion from an iterate blows up.
PeriodicOrbit find_periodic_orbit(StroboscopicMap& map, const Vector& guess,
                                  const ShootingOptions& options = {});

// The orbit at its minimal period. A period-k request can converge on an orbit of a shorter period
// m dividing k (the period-1 orbit taken k times, with multipliers μ^k): near a stable period-1
// orbit whose complex pair turns about p/k of a circle a period, a record's period search can
// return k, and Newton at k then finds the period-1 orbit. The minimal period is the smallest
// divisor m of k with |φ_{mT}(y) − y|_∞ <= 1000 · tolerance · max(1, |y|_∞): a genuine period-k
// orbit's points are apart by far more, unless it is born a hair from the bifurcation that made
// it; the factor covers the error of a y that met Newton's test at k, where the error in y can be
// larger than the residual by the conditioning of M^k − I. When m < k the orbit is solved again
// at m from y (one or two Newton iterations), so that its state, residual and multipliers are
// those of the period-m orbit; shots are kept when they divide m, else single shooting. One
// integration of each divisor tried. Returns `orbit` unchanged when its period is minimal.
PeriodicOrbit at_minimal_period(StroboscopicMap& map, const PeriodicOrbit& orbit,
                                const ShootingOptions& options);

// The multipliers of the period-k orbit through `state` (no Newton): the dense monodromy or
// Arnoldi, as `options` says.
FloquetMultipliers orbit_multipliers(StroboscopicMap& map, const Vector& state,
                                     const ShootingOptions& options, Matrix* monodromy = nullptr);

// Whether the solver is dense for a map of this size.
bool uses_dense_solver(const StroboscopicMap& map, const ShootingOptions& options);

}  // namespace pwl::orbits
