#pragma once
// Lyapunov exponents of a map.
//
// The exponents λ_1 >= λ_2 >= ... measure the average exponential rates at which the map
// stretches or shrinks infinitesimal perturbations: λ_1 > 0 means sensitive dependence on
// initial conditions (chaos), λ_1 = 0 a neutral direction (quasi-periodic motion, or the flow
// direction of an autonomous flow), λ_1 < 0 an attracting equilibrium or periodic orbit.
//
// Two estimators:
//
// * The QR method (Shimada & Nagashima, Prog. Theor. Phys. 61 (1979) 1605; Benettin, Galgani,
//   Giorgilli & Strelcyn, Meccanica 15 (1980) 9 and 21). An orthonormal frame Q of p tangent
//   vectors is pushed through the Jacobian of every iteration and re-orthonormalised by a QR
//   factorisation, J_n Q_n = Q_{n+1} R_n; then λ_i = lim (1/N) Σ_n ln |R_n(i,i)|. Re-orthonormal-
//   ising every iteration keeps the columns from all collapsing onto the most expanding
//   direction and keeps the numbers in range. It needs the tangent map (the Jacobian of one
//   iteration), which the precise-integration stepper provides and any smooth map has.
//
// * Two nearby trajectories (Benettin, Galgani & Strelcyn, Phys. Rev. A 14 (1976) 2338): a
//   companion trajectory started a small distance d0 away is advanced alongside the reference
//   one, and after every iteration the separation d is measured and reset to d0 along the same
//   direction; λ_1 = lim (1/N) Σ ln(d/d0). It needs no Jacobian, so it cross-checks the QR method
//   and works for any map or flow (advance a flow by a fixed time Δ per iteration and give
//   Δ as time_per_iteration). It gives λ_1 only and carries an O(d0) bias from the nonlinearity.
//
// Convergence. The running average converges like 1/sqrt(N) for chaotic motion (the local
// stretching rates fluctuate) and like 1/N for regular motion (the sum of the logs telescopes to
// a bounded quantity). Three estimates of the error are reported:
//  - standard_error: of the mean over `blocks` consecutive blocks of the averaging window (batch
//    means; blocks much longer than the correlation time are nearly independent). Right for
//    chaotic motion, but for regular motion the block boundaries can sample the bounded
//    oscillation at nearly the same phase and report far too small an error;
//  - half_difference: |estimate over the second half of the window - estimate over the whole|;
//  - range_error: the range of the bridge S(n) - n λ over the window, divided by N, where S(n) is
//    the sum of the first n logs (sampled at about 4096 evenly spaced n). For chaotic motion it
//    is about 1.25 standard errors (the mean range of a Brownian bridge); for regular motion it
//    is the size of the bounded oscillation over N, which is what the error is.
// `error` is the largest of the three.
//
// Rates are reported per iteration and per unit time (divided by time_per_iteration).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "pwl/types.hpp"

namespace pwl::analysis {

// One iteration of a map: returns the image of x. When `jacobian` is not null, also stores there
// the derivative of the map at x (dim x dim); callers that pass null need only the state.
using TangentMap = std::function<Vector(const Vector& x, Matrix* jacobian)>;

// One iteration of a map (or a flow advanced over a fixed time) without a derivative.
using StateMap = std::function<Vector(const Vector& x)>;

struct LyapunovOptions {
  long iterations = 10000;       // iterations averaged over, after the transient (>= blocks)
  long transient = 1000;         // iterations done first to settle the state and the frame (>= 0)
  int exponents = 0;             // p: how many of the largest exponents; 0 means all (dim)
  double time_per_iteration = 1.0;  // for the rates per unit time (> 0)
  int blocks = 10;               // batches for the standard error (>= 2)
  std::uint64_t seed = 1;        // for the random initial orthonormal frame
  // The state must stay finite with every |x_i| <= divergence_bound, else DivergenceError.
  double divergence_bound = 1e12;

  bool is_valid(std::string* why) const;
};

struct LyapunovResult {
  // Largest first. Per iteration and per unit time (per_iteration / time_per_iteration).
  Vector per_iteration;
  Vector per_unit_time;
  // Convergence estimates, per iteration (divide by time_per_iteration for per unit time).
  Vector standard_error;   // batch-means standard error of the mean
  Vector half_difference;  // |estimate over the second half - estimate over the whole|
  Vector range_error;      // range of the bridge S(n) - n λ, over N
  Vector error;            // max of the three
  long iterations = 0;     // averaged over
  double time_per_iteration = 1.0;
  Vector final_state;      // the state after transient + iterations (empty for Jacobian input)

  double largest() const { return per_iteration[0]; }
  double largest_per_unit_time() const { return per_unit_time[0]; }
};

// The p largest exponents of the map by the QR method, from x0.
//
// The initial frame is a random orthonormal one (seeded) rather than the identity's columns: a
// coordinate vector may lie exactly in a contracting invariant subspace (a decoupled degree of
// freedom), where it would stay forever and report the wrong exponent.
//
// An iteration whose Jacobian maps a frame vector to zero (a superstable point, e.g. the logistic
// map at x = 1/2) makes the corresponding exponent -infinity, which is the exact answer.
//
// Throws InputError for invalid options, an empty or non-finite x0, p > dim, or a Jacobian of the
// wrong size or not finite; DivergenceError when the state leaves the bound.
LyapunovResult lyapunov_spectrum(const TangentMap& map, const Vector& x0,
                                 const LyapunovOptions& options = {});

// The same from a precomputed sequence of Jacobians J_0, J_1, ... of one trajectory (for example
// recorded by an integrator). The first options.transient of them settle the frame; the next
// options.iterations are averaged, so the sequence must hold at least transient + iterations.
LyapunovResult lyapunov_spectrum(const std::vector<Matrix>& jacobians,
                                 const LyapunovOptions& options = {});

struct TwoTrajectoryOptions {
  long iterations = 10000;       // averaged over, after the transient (>= blocks)
  long transient = 1000;         // iterations that settle the state and the separation direction
  double separation = 1e-8;      // d0, in state units (> 0); keep it well above rounding of x
  double time_per_iteration = 1.0;
  int blocks = 10;
  std::uint64_t seed = 1;        // for the initial separation direction
  double divergence_bound = 1e12;

  bool is_valid(std::string* why) const;
};

// λ_1 by renormalised separation of two nearby trajectories. The result has one exponent.
// Throws as lyapunov_spectrum does; also DivergenceError when the companion trajectory lands on
// the reference one (zero separation, where no direction remains to renormalise along).
LyapunovResult largest_lyapunov_two_trajectories(const StateMap& map, const Vector& x0,
                                                 const TwoTrajectoryOptions& options = {});

}  // namespace pwl::analysis
