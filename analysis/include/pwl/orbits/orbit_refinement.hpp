#pragma once
// Orbit refinement: settle a motion's regime by finding the periodic orbit it is on or approaching,
// instead of integrating the approach out.
//
// Why. A lightly damped structure can approach a stable periodic orbit along a slow spiral: its
// leading Floquet multiplier lies just inside the unit circle (|μ| = 0.998 per period takes about
// 9000 periods to shrink a distance by 1e-8), so that a record of a few hundred stroboscopic
// points after a transient of a few hundred periods still drifts. The period search finds no
// period, the largest Lyapunov exponent is slightly negative, and the classifier can only say
// "uncertain" (or mistake the spiral for a torus). Newton on the stroboscopic map converges to the
// orbit in a handful of iterations from such a point, and the orbit's multipliers say at what
// rate the motion approaches it.
//
// How.
//  1. Candidate periods from near-returns of the recorded points p_0 .. p_{N−1}: for each
//     k <= max_period, the mean distance |p_i − p_{i−k}|_∞ over the last min(N − k, 50) points,
//     relative to the spread of the record (the largest range of a coordinate). A motion near a
//     period-k orbit returns close to itself after k periods, and the closer the longer it has
//     approached. The `candidates` smallest local minima of that score are tried, shortest period
//     first. A period-p record also returns at every multiple of p, and a multiple can score
//     lower (a slow drift back in phase), so each minimum k stands for its shortest divisor j
//     whose score is within 10 times k's (plus 1e-3 of the spread), and a multiple of a period
//     chosen already (with a closer return) is left out: Newton for it finds the same orbits,
//     reduced to their least period (step 2). A divisor is kept (its Newton is cheaper).
//  2. Newton on φ_{kT}(y) = y (periodic_orbit.hpp) from the motion's last state, which must be at
//     phase 0 of the forcing (a whole number of periods after the start). When it converges, the
//     orbit's least period is checked: if φ_{jT}(y) = y for a divisor j of k (at_minimal_period
//     in periodic_orbit.hpp says to what tolerance) the orbit is period-j, solved again at j.
//  3. Where the motion is with respect to the orbit: the distance from its last state to the
//     nearest of the orbit's k points at phase 0, against `on_orbit_tolerance` (relative to
//     max(1, |y|_∞)). The orbit is attracting when every multiplier lies inside the unit circle
//     (FloquetMultipliers::stable); the distance then shrinks asymptotically by the factor
//     ρ^{1/k} per period (ρ the largest |μ| of the k-period monodromy), and
//         periods to settle ≈ k · ln(tolerance / distance) / ln ρ.
//     An orbit that is not attracting and that the motion is not on does not describe the motion
//     (an unstable orbit inside chaos, say); it is reported as found but not as the motion's.
//     The candidates are tried in turn until an orbit describes the motion (steps 3 and 4);
//     when none does, the first orbit found is reported.
//  4. That the motion does approach it. An attracting orbit Newton reaches from the last state
//     need not be the motion's: beside a torus or a chaotic attractor a stable orbit can coexist,
//     and Newton may converge to it from a state in the other basin. So the motion is carried on
//     for P + W periods, P = k ln(1/2) / ln ρ the periods in which the multiplier halves its
//     distance and W = P/4 (at most max_check_periods in all), and the largest distance over the
//     last W periods is compared with the largest over the first W, which the multiplier
//     predicts to be half of it: the approach is confirmed when it shrank by at least the square
//     root of that (0.71). Faster is allowed: modes that decay faster than the slowest one may
//     still carry part of the distance. Window maxima rather than two single distances, because
//     a motion on a torus or on another attractor around the orbit keeps its distance only on
//     the whole, rising and falling along the way (measured: a check on one distance 255
//     periods on passed a cell of the (θ, α) map, α = 6.5, θ = 1.91, whose motion stays 0.04 from
//     a stable period-1 orbit for 40000 periods). An attracting orbit whose approach is not
//     confirmed does not describe the motion, and neither does one whose halving takes longer
//     than max_check_periods allow (the check then predicts a shrinking by less than half, which
//     a motion on a torus around the orbit can mimic: measured on figure 5's chain at α = 5,
//     θ = 1.8, a torus whose rotation lies within 1e-8 of 295/963 and a period-963 orbit that
//     would be reached after about 390000 periods).
//
// The estimate of the periods to settle is asymptotic: it holds once the slowest mode dominates
// the distance, and it is of the order of the truth, not an exact count (tests/orbits/
// orbit_refinement_test.cpp measures it against a run that settles).
//
// References: shooting for periodic orbits of forced oscillators, T. S. Parker and L. O. Chua,
// Practical Numerical Algorithms for Chaotic Systems, Springer 1989, ch. 5; periods from near
// returns of a Poincaré record, the method of close returns of D. P. Lathrop and E. J. Kostelich,
// Phys. Rev. A 40 (1989) 4028-4031.
#include <string>
#include <vector>

#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"

namespace pwl::orbits {

struct RefinementOptions {
  int max_period = 300;   // longest candidate period (forcing periods), >= 1
  int candidates = 3;     // periods tried at most, >= 1
  // The periods to try, in order, instead of step 1's candidates (each in 1..max_period): a
  // period the record's search already found (period_detection.hpp), to be checked by Newton.
  // Empty: the candidates of step 1.
  std::vector<int> periods;
  // The motion is on the orbit when its last state is within this of the orbit, relative to
  // max(1, |y|_∞); also the distance the periods to settle are counted to.
  double on_orbit_tolerance = 1e-8;
  // Step 4: the motion is carried on for at most this many forcing periods (>= 1).
  int max_check_periods = 20000;
  // Newton's settings; `period` is set per candidate. Multipliers are always computed.
  ShootingOptions shooting;
  bool is_valid(std::string* why) const;
};

struct OrbitRefinement {
  bool found = false;          // Newton converged for some candidate period
  PeriodicOrbit orbit;         // the orbit found (least period), when found
  std::vector<int> tried;      // the candidate periods tried, in order
  std::string failure;         // when not found: why (no candidate, or Newton's last message)
  double distance = 0.0;       // from the motion's last state to the nearest orbit point
  double tolerance = 0.0;      // on_orbit_tolerance · max(1, |y|_∞)
  bool on_orbit = false;       // distance <= tolerance
  bool attracting = false;     // every multiplier inside the unit circle
  // ρ^{1/k}: the factor the distance to an attracting orbit shrinks by per forcing period.
  double contraction_per_period = 0.0;
  // Attracting and not on it: about how many more forcing periods until distance <= tolerance.
  double periods_to_settle = 0.0;
  // Step 4 (attracting, not on it): the periods the motion was carried on, the factor its
  // largest distance over a window shrank by (last window against first) and the factor the
  // multiplier predicts, and whether they agree.
  int check_periods = 0;
  double measured_factor = 0.0;
  double predicted_factor = 0.0;
  bool approach_confirmed = false;

  // Whether the orbit describes the motion: the motion is on it, or approaches it as confirmed.
  bool explains_motion() const {
    return found && (on_orbit || (attracting && approach_confirmed));
  }
  // One line: "period-1, attracting (|μ| = 0.998 per period): reached after about 9000 more
  // periods" and the like.
  std::string describe() const;
};

// The candidate periods of step 1 (at most `count`, shortest first) from points at phase 0, each
// the same length. Fewer than 3 points, or a record that does not vary: period 1 only.
std::vector<int> candidate_periods(const std::vector<Vector>& points, int max_period, int count);

// Steps 1-3 from the recorded points (any coordinates; for the candidates) and the motion's last
// state [x; v] at phase 0 (for Newton and the distance). Throws InputError for invalid options
// or a last state of the wrong size or not finite; Newton's failures are reported in `failure`.
OrbitRefinement refine_orbit(StroboscopicMap& map, const std::vector<Vector>& points,
                             const Vector& last_state, const RefinementOptions& options = {});

}  // namespace pwl::orbits
