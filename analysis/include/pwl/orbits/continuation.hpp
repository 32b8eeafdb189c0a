#pragma once
// Continuation of a periodic orbit in a parameter, with its bifurcations located on the way.
//
// Pseudo-arclength continuation (H. B. Keller, in Applications of Bifurcation Theory, Academic
// Press 1977, 359-384; E. L. Allgower and K. Georg, Introduction to Numerical Continuation Methods,
// SIAM 2003, ch. 2) of the fixed points of the stroboscopic map,
//
//     F(y, p) = φ_{kT(p)}(y; p) − y = 0,
//
// in the unknowns (y, p): the branch is followed by its arclength, so it goes round a fold (where
// the parameter turns back) as easily as elsewhere. A step predicts along the unit tangent τ of
// the branch, (y, p) + h τ, and corrects by Newton on F = 0 with τ · ((y, p) − prediction) = 0,
// whose bordered Jacobian [M − I, ∂F/∂p; τ^T] is regular at a fold. The monodromy M comes from the
// map's exact tangent, ∂F/∂p from central differences of the map in p. On large structures the
// corrector is the chord method: it keeps the monodromy of the point it predicted from while the
// residual falls at least fourfold a step, and forms M again only where it does not, so an
// accepted point costs about one monodromy (at the orbit, for its multipliers) and a few plain
// integrations of the map (a bifurcation's trial points one more each, a grazing's none). The
// step grows after easy corrections (Newton: two iterations or fewer; chord: the corrected point
// within 2e-4 of the prediction, relative to the state) and shrinks after hard ones or a turn of
// the tangent by more than 30°.
//
// Bifurcations, between two accepted points, from the Floquet multipliers and the orbit's profile.
// The multipliers outside the unit circle are counted by kind at both ends of every step (real
// beyond +1, real below −1, complex pairs), each end on its own orbit, and every change of those
// counts must be explained by the events located inside the step:
//  - fold: a real multiplier crosses +1 (the count beyond +1 changes by one);
//  - period doubling: a real multiplier crosses −1 (the count below −1 changes by one);
//  - Neimark–Sacker: a complex pair crosses the unit circle (the complex pairs outside change by
//    one);
//  - a complex pair that meets the real axis inside the circle changes nothing, and one that meets
//    it outside turns into two real multipliers beyond ±1: no bifurcation.
// A change that is none of these alone (several events in one step, say a complex pair turning
// real past a grazing and one of the two then crossing −1), or an event whose location does not
// account for the whole change, cuts the step in two at half its arclength, and each half is
// explained in turn, until each event sits alone in its interval and is located. Beside those:
//  - grazing: the largest (or smallest) value along the orbit of a gap function g_j passes through
//    zero, so a contact appears or disappears. In a structure with continuous piecewise-linear
//    forces the map stays C¹ there, but its multipliers may change at an unbounded rate
//    (M. di Bernardo, C. J. Budd, A. R. Champneys and P. Kowalczyk, Piecewise-smooth Dynamical
//    Systems, Springer 2008, ch. 6 and 8). A grazing explains no change of the multipliers' counts:
//    they move continuously through it.
// Each is located by the Illinois variant of regula falsi on the arclength between the two points
// (every trial point corrected onto the branch) on a test function that vanishes there: the real
// multiplier nearest ±1 minus ±1, the modulus of the complex pair nearest the circle minus 1, the
// extreme gap. The parameter is located to `locate_tolerance`, on trial points closed past the
// shooting tolerance, to 1e-12 (or the shooting tolerance if tighter) where the corrector gets
// there while each step shrinks the residual fourfold: an orbit closed to a residual r places the
// test function to about r over its slope, and a gap's extreme can move slowly with the
// parameter.
//
// Branch switching: at a period doubling of a period-k branch, the period-2k branch passes through
// the same point with the tangent (v, 0), v the eigenvector of the multiplier −1 (Y. A. Kuznetsov,
// Elements of Applied Bifurcation Theory, 3rd ed., Springer 2004, §10.3). It is started at
// y* + ε v with the projection on v held fixed, checked to be a genuine period-2k orbit, and
// followed like the first.
//
// Matrix-free continuation. Up to ShootingOptions::dense_state_limit state components (or with
// solver = dense) continuation forms the monodromy as above. Beyond it (or with solver = krylov) it
// never does: the corrector is Newton–Krylov on the bordered system [M − I, ∂F/∂p; τᵀ], solved by
// GMRES on products M v (tangent integrations of the map from the iterate, replayed from its
// recorded integration where the integrator records its tangent: the banded switching PIM) and
// right-preconditioned by the bordered matrix of the open structure (analysis/src/orbits/
// bordered_krylov.hpp); the tangent is the same bordered solve with the previous tangent as its
// border; the multipliers are the leading ones by Davidson's method preconditioned by the open
// structure where its damping is classical, by thick-restarted Arnoldi elsewhere, warm-started from
// the real Schur vectors of the point before (of the bracket's end, at a bifurcation's trial
// points), and as many as it takes to have one below 1 − margin (1e-5 by default,
// continuation_shooting_options below), so that every multiplier outside the unit circle, and every
// one within the margin of it, is among them (K. Lust, D. Roose, A. Spence and A. R. Champneys,
// SIAM J. Sci. Comput. 19 (1998) 1188-1209, the Newton–Picard setting of the same idea). Detection
// and location are the same code: the signature counts the multipliers outside the circle, which
// the leading set holds, and the test functions det(I ∓ M) are taken over the leading set, whose
// left-out factors (of multipliers inside the circle) are all positive, so their sign changes
// exactly where the whole determinant's does. Branch switching takes the Ritz vector of the
// multiplier −1. The chord corrector is dense only.
//
// A band round the circle (ContinuationOptions::band, 0.05 unless set; dense or matrix-free): a
// step is halved while a multiplier within half the band of the circle at one end has no partner
// of its own (one to one) at the other, within half the band of it in the plane or in modulus
// (having turned by at most 0.02 rad), so that a multiplier does not leave the circle and come
// back (a window of stability or instability shorter than a step, the same signature at both
// ends) between two points unseen. Matrix-free, the band is narrowed to the moduli the leading
// multipliers cover at both ends, which ShootingOptions::arnoldi.margin asks to be at least 1e-5
// by default (continuation_shooting_options, below); BranchWalk::too_long in continuation.cpp
// says what this rests on and what it does not catch.
#include <complex>
#include <limits>
#include <string>
#include <vector>

#include "pwl/orbits/arclength_continuation.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::orbits {

enum class BifurcationType { fold, period_doubling, neimark_sacker, grazing };
// "fold", "period-doubling", "neimark-sacker", "grazing".
std::string bifurcation_name(BifurcationType type);

struct BranchPoint {
  int branch = 0;         // 0: the branch started from; 1, 2, ...: switched onto, in order
  double parameter = 0.0;
  double arclength = 0.0; // along its branch, from the branch's first point
  PeriodicOrbit orbit;    // state, period, multipliers (no monodromy kept)
  OrbitProfile profile;   // amplitudes and gap extremes
};

struct Bifurcation {
  BifurcationType type = BifurcationType::fold;
  int branch = 0;
  int period = 1;             // of the branch it was found on
  double parameter = 0.0;
  Vector state;               // the orbit there
  // fold, period doubling, Neimark–Sacker: the multiplier on the unit circle (as located).
  std::complex<double> multiplier{0.0, 0.0};
  // grazing: the spring (0-based), and whether it is the largest value of its gap function that
  // passes through zero (a contact appears or disappears at the orbit's closest approach) or the
  // smallest (a spring that never let go starts to).
  int spring = -1;
  bool at_largest_gap = true;
  double test_value = 0.0;    // the test function where located (≈ 0)
  int to_branch = -1;         // period doubling with branch switching: the branch it started
  int joined_by = -1;         // period doubling: a switched branch that ended here (it rejoined
                              // this branch at this point)
  // Whether it was located (the test function brought to zero on the branch); false: only
  // detected between two points of the branch, and `parameter` is the nearer of the two.
  bool located = true;
};

// The shooting options a continuation starts from: ShootingOptions' own, except that matrix-free
// the leading multipliers are asked at every point for each one of modulus above 1 − 1e-5
// (ArnoldiOptions::margin = kContinuationMargin), so that the band watched between two points
// (ContinuationOptions::band) is never narrowed below 1e-5 where they converged within half their
// basis (FloquetMultipliers::band_covered), instead of to whatever the leading count happens to
// reach: 2e-8 in the 1000-mass chain's cascade of Neimark–Sacker points with no margin. Measured
// 2026-12-02 (2 cores, nothing else running): the 1000-mass chain from θ = 0.605 to 0.575 (`pwl
// continue --n 1000 --alpha 2 --zeta 0.2 --theta 0.605 --parameter theta --range 0.605:0.575
// --multiplier-margin M`) with margins 0, 1e-5, 1e-4 and 1e-3: 11227, 10981, 13812 and 18074
// multiplier products, 56.1, 56.3, 71.1 and 96.9 s, the band narrowed to 1.0e-7, 1.0e-5, 4.9e-4
// and 3.8e-3, 4, 0, 0 and 0 steps halved, the same 8 Neimark–Sacker points. At 10^4 masses
// (`pwl continue --n 10000 --alpha 2 --zeta 0.2 --theta 1.5 --parameter theta --range 1.5:1.6
// --max-points 4`), whose long waves crowd ten times nearer the circle (|μ_k| ≈ 1 − 4e-8 k²):
// 1e-5 took 31.5 to 38.4 s a warm point (band 2.4e-5, 694 MB); 1e-4, about 100 multipliers in
// its band, 157 s for the first warm point. Wider bands are the caller's choice at that price.
inline constexpr double kContinuationMargin = 1e-5;
inline ShootingOptions continuation_shooting_options() {
  ShootingOptions s;
  s.arnoldi.margin = kContinuationMargin;
  return s;
}

struct ContinuationOptions {
  analysis::SweepParameter parameter;  // what varies (any parameter of the model)
  double start = 0.0;                  // the branch starts here ...
  double end = 1.0;                    // ... and is followed toward here
  double initial_step = 0.0;  // arclength of the first step; 0: |end − start| / 100
  double min_step = 0.0;      // 0: 1e-7 |end − start|
  // The largest step, as a change of the parameter: the arclength step is at most this divided by
  // the parameter's share of the tangent (up to 100 times this), so that a branch whose state
  // moves fast (near a resonance) is not crawled along. 0: |end − start| / 25.
  double max_step = 0.0;
  int max_points = 2000;      // per branch
  // The corrector: chord steps on the monodromy of the point predicted from, or Newton, which
  // forms the monodromy at every iterate (the same orbits to the tolerance). Automatic: Newton up
  // to 20 state components, where a monodromy costs about what an integration does (the exact
  // solver on the 5-DOF chain), chord above, where it costs its 2n tangent columns. Matrix-free
  // (see above) it is Newton–Krylov, and chord is refused.
  Corrector corrector = Corrector::automatic;
  int max_corrections = 7;    // monodromies one corrector may form before it converges
  double locate_tolerance = 1e-10;  // of the bifurcation parameters
  bool grazing = true;              // detect grazing
  bool switch_branches = false;     // follow the period-2k branch at each period doubling
  int max_branches = 4;             // branches switched onto, in all
  int profile_samples = 256;        // per period, methods off a fixed grid
  // The band round the unit circle watched between two points, so that a multiplier that goes
  // out and comes back within one step (a stable or unstable window shorter than the step: the
  // same counts outside at both ends) is not missed. A step is halved while a multiplier within
  // half the band of the circle at one end has no partner at the other: within half the band of
  // it in the plane, or in modulus having turned by at most 0.02 rad (see the head of this file).
  // Where only the leading multipliers are known (matrix-free), the band is narrowed to what they
  // cover at both ends: 1 − the smallest modulus reported (ShootingOptions::arnoldi: its count,
  // and its margin, 1e-5 here by default, which asks for every multiplier above 1 − margin). 0:
  // no band; steps are then explained by the counts at their ends alone.
  double band = 0.05;
  // The method that integrates the map, and its steps per forcing period (fixed grid).
  MethodSettings method{Method::exact};
  int steps_per_period = 200;
  // Period k, tolerance, Newton at the first point; `solver` picks dense or matrix-free (automatic:
  // by dense_state_limit), and its GMRES and Arnoldi settings are the matrix-free ones. Its
  // defaults are ShootingOptions' except the multipliers' margin (continuation_shooting_options).
  ShootingOptions shooting = continuation_shooting_options();
  bool is_valid(std::string* why) const;
};

// Hooks for progress and for writing as the branch grows (every hook optional).
class ContinuationObserver {
 public:
  virtual ~ContinuationObserver() = default;
  virtual void point(const BranchPoint& /*point*/) {}
  virtual void bifurcation(const Bifurcation& /*bifurcation*/) {}
  // Why a branch stopped, or a branch switch that failed, for people.
  virtual void note(const std::string& /*message*/) {}
};

struct ContinuationResult {
  std::vector<BranchPoint> points;        // every branch, in the order computed
  std::vector<Bifurcation> bifurcations;  // in the order found
  std::vector<std::string> notes;         // why each branch stopped
  // Integrations of the map over the orbit's period: with the monodromy (all its tangent
  // columns), and without (chord steps, ∂F/∂p, checks). Not counted: the profiles, and the
  // shooting at the branches' first points.
  long monodromies = 0;
  long integrations = 0;
  long chord_stalls = 0;  // chord steps that stalled, after which the monodromy was formed again
  // Matrix-free: whether the continuation was (no monodromy formed), its GMRES products (with
  // M − I, bordered: correctors, tangents, and the first orbit's Newton–Krylov), its Arnoldi
  // products, and the points whose Arnoldi did not reach its tolerance (their stability rests on
  // Ritz values short of it).
  bool matrix_free = false;
  long krylov_products = 0;
  long arnoldi_products = 0;
  long unconverged_multipliers = 0;
  // Matrix-free: the points (a location's trial points included) whose leading multipliers came
  // from Davidson's method preconditioned by the open structure, and from thick-restarted
  // Arnoldi (FloquetMultipliers::method; ArnoldiOptions::method says which is taken where).
  long davidson_points = 0;
  long arnoldi_points = 0;
  // Matrix-free: the points whose converged multipliers did not reach below the band of
  // ArnoldiOptions::margin within half Arnoldi's basis (more may lie in it, outside the circle
  // with margin 0, than were reported).
  long uncovered_bands = 0;
  // Steps halved because a multiplier within half the band of the unit circle at one end had no
  // partner of its own at the other (ContinuationOptions::band; see the head of this file), and
  // the narrowest band a step was checked in (narrower than asked where only the leading
  // multipliers were known; infinity: no step was checked).
  long band_cuts = 0;
  // The band asked: ContinuationOptions::band, matrix-free widened to ArnoldiOptions::margin.
  double band = 0.0;
  double narrowest_band = std::numeric_limits<double>::infinity();
  // Steps cut in two because the multipliers' signature changed in a way the events located in
  // them did not explain (several events in one step).
  long step_cuts = 0;
  Corrector corrector = Corrector::newton;  // the one used (chord or newton)
};

// Follows the period-k orbit near `guess` (at p = start) toward `end`. Throws InputError for
// invalid options, ShootingError when no orbit is found at the start; later failures stop the
// branch with a note.
ContinuationResult continue_periodic_orbit(const analysis::PointModel& model, const Vector& guess,
                                           const ContinuationOptions& options,
                                           ContinuationObserver* observer = nullptr);

}  // namespace pwl::orbits
