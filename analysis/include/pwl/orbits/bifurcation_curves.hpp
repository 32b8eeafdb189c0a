#pragma once
// Bifurcation curves in two parameters: each fold, period doubling, Neimark–Sacker point and
// grazing that a branch in the parameter P located, followed in the plane (P, Q) by
// pseudo-arclength continuation on the continuation core (arclength_continuation.hpp), as the
// solution curve of a minimally extended defining system: the orbit's equations
// F(y; P, Q) = φ_kT(y; P, Q) − y = 0 plus the condition of the bifurcation (SPEC §8).
//
//  - fold: g = 0 from [M − I, b; c^T, 0] [w; g] = [0; 1] (M the monodromy of the period-k map);
//    period doubling: the same with M + I. The bordered test function is regular where M ∓ I has a
//    one-dimensional null space and never a determinant (W. Govaerts, Numerical Methods for
//    Bifurcations of Dynamical Equilibria, SIAM 2000; Y. A. Kuznetsov, Elements of Applied
//    Bifurcation Theory, 3rd ed., Springer 2004, ch. 10). Its derivatives dg = −v^T (dM) w come
//    from directional derivatives of the monodromy: along the state, by the symmetry of the second
//    derivative of the map, v^T D²φ[e_j, w] = (v^T DM[w])_j, one derivative of M along w (two
//    monodromies), and along each parameter from the tangent of w there.
//  - Neimark–Sacker: M² − 2κM + I singular with κ = cos ω an extra unknown, two conditions: two
//    entries of the 2 × 2 G of the doubly bordered matrix, the pair chosen at each point where the
//    problem is best conditioned (W. Govaerts, Yu. A. Kuznetsov and B. Sijnave, "Numerical methods
//    for the generalized Hopf bifurcation", SIAM J. Numer. Anal. 38, 2000, and MatContM for maps).
//    Where κ leaves [−1, 1] the same equations describe a neutral saddle (real μ and 1/μ), which is
//    not a bifurcation: the curve ends there (a 1:1 or 1:2 resonance) and says so.
//  - grazing of spring s: γ(y; P, Q) = the largest (or smallest) value of the gap function g_s
//    along the orbit is zero, which is g_s(t*) = 0 with ġ_s(t*) = 0 and t* ∈ [0, kT): the extreme's
//    time t* is eliminated by taking the extreme itself (located on the exact motion by the orbit's
//    profile), and by the envelope theorem ∂γ/∂y = ∂g_s(t*)/∂y, the gap function's row of the
//    state transition matrix at t*.
//
// Codimension-two points are zeros of test functions along the curves, located on the curve by
// regula falsi on its arclength to 1e-10 in both parameters:
//  - smooth: fold–flip (+1 and −1 at once: on a fold curve the sign of det(M + I), on a flip curve
//    that of det(M − I)); 1:1 (a second multiplier +1 on a fold curve, κ = 1 on a Neimark–Sacker
//    curve) and 1:2 (a second −1 on a flip curve, κ = −1), 1:3 (κ = −1/2), 1:4 (κ = 0); fold–NS and
//    flip–NS on a Neimark–Sacker curve; the cusp on a fold curve and the generalised period
//    doubling on a flip curve, where their normal-form coefficients (Kuznetsov, §9.4 and §9.5:
//    a = ½⟨p, B(q, q)⟩, c = (1/6)⟨p, C(q, q, q)⟩ + ½⟨p, B(q, (I − A)⁻¹ B(q, q))⟩) pass through zero.
//    B and C come from central differences of the map along q, which the map's smoothness between
//    contact changes allows; where a gap extreme of the orbit changes sign within the differences'
//    reach (a contact appears or disappears there), the coefficient is not computed and the curve
//    says so, rather than trust a difference across a kink.
//  - non-smooth (no smooth tool has them): on a grazing curve, another spring's extreme gap through
//    zero (a double grazing) or the multipliers' signature changing (the grazing curve meets a fold,
//    flip or Neimark–Sacker curve); on a fold, flip or Neimark–Sacker curve, any spring's extreme
//    gap through zero (the curve meets a grazing curve: F. Colombo and F. Dercole, SIAM J. Appl. Dyn.
//    Syst. 9(1), 2010, where a third curve issues from the point).
//
// A curve is followed from its start in both directions, each until it leaves the Q range or the
// P range, closes on itself, reaches its largest number of points, or cannot go on; the reason is
// kept.
//
// Dense or matrix-free. Up to ShootingOptions::dense_state_limit state components (or at any size
// where the solver is dense) every curve forms the monodromy. Beyond the limit (unless the solver
// is dense), or wherever ShootingOptions::solver is krylov, every curve is followed matrix-free:
// Newton–Krylov on the same defining systems, the rows of their conditions known only by products
// (a gap's gradient: matrix_free_grazing.hpp; the bordered test functions' derivatives:
// matrix_free_bordered.hpp), and the leading multipliers by Arnoldi for the codimension-two tests:
// det(I ∓ M) over the leading multipliers (fold–flip, fold– and flip–grazing, fold– and
// flip–Neimark–Sacker), which changes sign where the full determinant does
// (FloquetMultipliers::shifted_determinant), a second multiplier at ±1 among them (1:1, 1:2), κ
// for the resonances on a Neimark–Sacker curve, and the same grazing and Neimark–Sacker–grazing
// tests as dense. The cusp and the generalised period doubling need the left null vector and are
// not looked for there (a note says so). Where Arnoldi did not converge or did not reach below
// the band of its margin (every multiplier outside the circle with the default margin of 0), the
// multipliers' tests are not evaluated (a note says where), as the branch claims no stability
// change there.
#include <complex>
#include <string>
#include <vector>

#include "pwl/orbits/continuation.hpp"

namespace pwl::orbits {

enum class CurveType { fold, period_doubling, neimark_sacker, grazing };
// "fold", "period-doubling", "neimark-sacker", "grazing" (bifurcation_name's words);
// parse_curve_type throws InputError naming the value for any other text.
std::string curve_type_name(CurveType type);
CurveType parse_curve_type(const std::string& name);
// The curve type of a bifurcation a branch located.
CurveType curve_type_of(BifurcationType type);

struct CurvesOptions {
  analysis::SweepParameter first;   // P: the branch's parameter
  analysis::SweepParameter second;  // Q
  double p_from = 0.0, p_to = 1.0;  // the P range (the branch's); a curve leaving it ends
  double q_from = 0.0, q_to = 1.0;  // the Q range; the base model's Q must lie in it
  std::vector<CurveType> types{CurveType::fold, CurveType::period_doubling,
                               CurveType::neimark_sacker, CurveType::grazing};
  // The arclength step in the normalised plane (P / |P range|, Q / |Q range|): 0 picks 1/100
  // (first), 1e-7 (smallest) and 1/25 (largest).
  double initial_step = 0.0, min_step = 0.0, max_step = 0.0;
  int max_points = 1000;  // per direction of each curve
  // Dense curves only: a matrix-free curve corrects by Newton–Krylov.
  Corrector corrector = Corrector::automatic;
  int max_corrections = 7;
  double locate_tolerance = 1e-10;  // of both parameters, for codimension-two points
  bool codim2 = true;
  int profile_samples = 256;
  MethodSettings method{Method::exact};
  int steps_per_period = 200;
  ShootingOptions shooting;  // tolerance of the orbits on the curves
  bool is_valid(std::string* why) const;
};

// One point of a curve: a row of curves.csv.
struct CurvePointRecord {
  int curve = 0;
  CurveType type = CurveType::fold;
  double p = 0.0, q = 0.0;
  int period = 1;
  int spring = -1;                        // grazing: the spring (0-based)
  bool at_largest_gap = true;             // grazing: the largest value of its gap function
  std::complex<double> multiplier{0, 0};  // fold +1, flip −1, Neimark–Sacker e^{iω}
  double kappa = 0.0;                     // Neimark–Sacker: cos ω (NaN for the others)
  Vector state;                           // the orbit's state at t = 0 mod kT
  Vector amplitude;                       // max |x_i(t)| over the orbit
};

// A codimension-two point: a row of codim2.csv.
struct Codim2Point {
  std::string type;  // "fold-flip", "cusp", "resonance-1:1", ..., "double-grazing",
                     // "fold-grazing", "grazing-period-doubling", ...
  double p = 0.0, q = 0.0;
  std::vector<int> curves;  // the curves it was found on
  std::string detail;
  Vector state;
  int period = 1;
};

struct CurveSummary {
  int curve = 0;
  CurveType type = CurveType::fold;
  int period = 1;
  int spring = -1;
  bool at_largest_gap = true;
  double start_p = 0.0, start_q = 0.0;
  int points = 0;
  std::string ends[2];  // why each direction ended (toward larger Q first)
};

struct CurvesResult {
  std::vector<CurvePointRecord> points;  // every curve's points, in the order computed
  std::vector<Codim2Point> codim2;
  std::vector<CurveSummary> curves;
  std::vector<std::string> notes;
  long monodromies = 0;   // integrations with every tangent column
  long integrations = 0;  // others (with one or a few tangent columns, or none)
  // Matrix-free curves: products with the bordered system in GMRES (each one tangent product over
  // the period, mostly replayed), products in Arnoldi, and points whose Arnoldi stopped short of
  // its tolerance.
  long krylov_products = 0;
  long arnoldi_products = 0;
  int unconverged_multipliers = 0;  // corrected points (trial points of a location included)
  int uncovered_bands = 0;          // converged, but not below the band of the margin
  // Matrix-free curves: corrected points whose leading multipliers came from Davidson's method
  // preconditioned by the open structure, and from thick-restarted Arnoldi.
  int davidson_points = 0;
  int arnoldi_points = 0;
};

// Hooks for writing as the curves grow (every hook optional).
class CurvesObserver {
 public:
  virtual ~CurvesObserver() = default;
  virtual void point(const CurvePointRecord& /*point*/) {}
  virtual void codim2(const Codim2Point& /*point*/) {}
  virtual void note(const std::string& /*message*/) {}
};

// Follows in (P, Q) the curve of each bifurcation of `starts` (located on branches in P at the
// base model's Q) whose type `options.types` holds and which was located. Throws InputError for
// invalid options (Q the same parameter as P, a Q range without the base model's Q, a parameter
// the model lacks); a curve that cannot start is noted and skipped.
CurvesResult follow_bifurcation_curves(const analysis::PointModel& model,
                                       const std::vector<Bifurcation>& starts,
                                       const CurvesOptions& options,
                                       CurvesObserver* observer = nullptr);

}  // namespace pwl::orbits
