#pragma once
// Classification of a motion from its Poincaré points and, when available, its largest Lyapunov
// exponent and the 0-1 test for chaos.
//
// Each indicator alone can mislead: a period search misses a period longer than k_max or one
// still settling; a finite-time Lyapunov exponent of a regular motion is small but not zero; the
// 0-1 test cannot tell a periodic from a quasi-periodic motion and mistakes rounding noise for
// diffusion. So the classifier combines them, says which rule decided, and answers "uncertain"
// when they disagree instead of guessing.
//
// Decision rules, in order:
//
//  1. unbounded: some coordinate of some point (or of the observable series) is not finite or
//     exceeds divergence_bound in magnitude. Checked before anything else, so a diverging
//     sequence is reported before it overflows and a NaN never reaches the other tests.
//  2. The period search (detect_period with options.period). If a period k is found:
//       - uncertain if λ1 is known and clearly positive (λ1 - error > lyapunov_margin);
//       - otherwise period-k, or equilibrium when k = 1 and fixed_point_is_equilibrium.
//     λ1 within the margin of 0 is accepted: a periodic orbit at a bifurcation, or the neutral
//     direction along the orbit of an autonomous flow, has λ1 = 0. K is not consulted: a period
//     that repeats over several cycles is the stronger evidence, and near a fixed point the
//     series is rounding noise, which the 0-1 test reads as chaos.
//  3. uncertain if no period could be tested at all (fewer than cycles + 1 points).
//  4. No period found. λ1 is read as positive (λ1 - error > margin), zero (|λ1| + error <=
//     margin), negative (λ1 + error < -margin), inconclusive (otherwise) or unknown; K as chaotic
//     (K > chaotic_K), regular (K < regular_K), in between, or unknown.
//       - unbounded, by secular growth (rule 4a below), unless λ1 is negative;
//     The torus test (evidence.torus_digits, weighted Birkhoff averages) reads curve (digits >=
//     curve_digits), broken (< broken_digits), in between, or unknown.
//       - positive and chaotic, not a curve     -> chaotic
//       - zero and regular                      -> quasi-periodic
//       - curve, K regular or in between, λ1 zero or inconclusive with |λ1| <= its error
//                                               -> quasi-periodic
//       - curve, positive                       -> uncertain (a curve contradicts chaos)
//       - positive, K unknown, not a curve      -> chaotic        (unless require_all_indicators)
//       - λ1 unknown, chaotic, not a curve      -> chaotic        (unless require_all_indicators)
//       - zero, K unknown                       -> quasi-periodic (unless require_all_indicators)
//       - λ1 unknown, regular                   -> quasi-periodic (unless require_all_indicators)
//       - anything else (disagreement, an inconclusive or in-between value, λ1 < 0 without a
//         period: a period beyond k_max or a transient not yet over) -> uncertain.
//
// Rule 4a, secular growth. A motion can grow without bound and still stay far below
// divergence_bound over the record: an undamped linear resonance, x'' + x = sin t from rest,
// x = (sin t - t cos t) / 2, grows like t and its stroboscopic points march off along a line,
// which the period search does not repeat, λ1 reads as zero (its tangent map is a rotation) and
// the 0-1 test as regular, so that rules 2-4 would call it quasi-periodic. Rule 4a measures the growth itself, on the amplitude r_i = |p_i|
// (the Euclidean norm of point i) against the time since the initial state, t_i =
// evidence.first_point_time + i map iterations:
//
//   - the record is cut into growth_blocks equal blocks (at least 4 points each; fewer points
//     than 4 growth_blocks: no test) and the envelope E_b = max r_i over block b is taken at the
//     time t_b of that maximum. The envelope, not r_i itself, because an oscillation that grows
//     (beating of several modes on top of the growth, a norm that dips at some phase) has a
//     rising envelope while r_i itself goes up and down;
//   - significance: the envelope must rise in every block, E_0 < E_1 < ... (the maxima of a
//     bounded stationary motion over equal blocks are exchangeable, so they rise in all of 8
//     blocks by chance with probability 1/8! = 2.5e-5; a periodic record has equal maxima), and by
//     at least growth_rise in log over the record (log(E_last / E_0) >= 0.1, a rise of 10.5%), so
//     that a growth is never read from a few rounding-level changes;
//   - linear or faster: the least-squares slope p of log E_b on log t_b (the power of t the
//     amplitude grows like: 1 for a resonance from rest) is at least growth_exponent = 0.75, over
//     the whole record and over its second half alike. The second half is what tells a growth
//     from a transient still settling onto a bounded motion: an approach A (1 - exp(-t/τ)) has
//     the local exponent (t/τ) / (exp(t/τ) - 1), which falls below 0.75 once t > 0.55 τ, while a
//     power law keeps its exponent. 0.75 rather than 1 leaves room for a start away from rest:
//     r = sqrt(r0^2 + (c t)^2) grows with the exponent (c t)^2 / r^2 >= 0.75 once c t >= 1.7 r0.
//     A slower, sub-linear rise is not called unbounded: within one record it cannot be told
//     from such an approach;
//   - a negative λ1 rules growth out: a map that contracts every nearby pair of states keeps a
//     forced response bounded, so a rising envelope there is a transient settling, however slow.
//
// The test can only see what the record holds. A beat more than about twice as long as the
// record may rise over all of it like a growth; and a growth like t rises by the factor
// (t_first + N) / t_first over N recorded iterations, which passes growth_rise only when the
// record is at least a tenth of the time before it. More recorded periods settle both.
//
// Where K comes from: evidence.zero_one_K if given; else the 0-1 test on evidence.observable if
// that is not empty; else, if zero_one_from_points, the 0-1 test on coordinate
// observable_component of the points when there are at least zero_one.min_samples of them. It is
// computed only when rule 4 needs it.
//
// λ1 and lyapunov_margin must be in the same units (per iteration of the map, or per unit time).
#include <optional>
#include <string>
#include <vector>

#include "pwl/analysis/period_detection.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/types.hpp"

namespace pwl::analysis {

enum class Regime {
  equilibrium,
  periodic,  // period-k, k in Classification::period
  quasi_periodic,
  chaotic,
  unbounded,
  uncertain,
};

// "equilibrium", "period-3", "quasi-periodic", "chaotic", "unbounded", "uncertain". The period is
// used only for Regime::periodic.
std::string regime_name(Regime regime, int period = 0);

// Indicators computed elsewhere, all optional.
struct MotionEvidence {
  std::optional<double> lyapunov;        // λ1, finite
  double lyapunov_error = 0.0;           // its uncertainty (>= 0), e.g. LyapunovResult::error
  std::optional<double> zero_one_K;      // K from an earlier 0-1 test, in [-1, 1]
  // The torus test's digits (weighted_birkhoff.hpp, WeightedBirkhoffResult::digits), >= 0.
  std::optional<double> torus_digits;
  std::vector<double> observable;        // a scalar series for the 0-1 test, if K is not given
  // The time of points[0] since the initial state, in iterations of the map (forcing periods of
  // a stroboscopic map); the points are one iteration apart. Rule 4a measures growth against it:
  // for points recorded after a transient of m iterations it is m + 1 (> 0).
  double first_point_time = 1.0;
};

struct ClassifierOptions {
  PeriodOptions period;
  ZeroOneOptions zero_one;
  double lyapunov_margin = 5e-3;    // |λ1| within this counts as zero (> 0)
  double chaotic_K = 0.8;           // K above this is chaotic
  double regular_K = 0.2;           // K below this is regular (0 < regular_K <= chaotic_K < 1)
  // The torus test, when its digits are given (rule 4): at least curve_digits reads a smooth
  // invariant curve, below broken_digits no curve (0 < broken_digits <= curve_digits <= 15).
  // A curve vetoes chaos and settles a λ1 or K that are inconclusive; the lack of one is not
  // enough to call chaos without λ1 and K (tori of these structures can score low: below).
  // Why 5 and 2.5: on the paper's 5-DOF chain (weighted_birkhoff.hpp) a loop scores 3.8 digits
  // from 500 points and 5.9 from 4000, chaos 1.3 to 1.9; over the 1160 cells of the (θ, α) map
  // (500 to 4000 points) 90% of the chaotic cells score below 2.2 and the quasi-periodic ones
  // 1.0 to 6.0, median 3.5. So a high score is strong evidence of a curve, a low one is evidence
  // against it only together with λ1.
  double curve_digits = 5.0;
  double broken_digits = 2.5;
  double divergence_bound = 1e12;   // |coordinate| beyond this is unbounded (> 0)
  // A fixed point of the map is an equilibrium (autonomous system sampled in time) or, when
  // false, a period-1 response (stroboscopic map of a forced system).
  bool fixed_point_is_equilibrium = true;
  bool zero_one_from_points = true;
  Index observable_component = 0;
  // Demand both λ1 and K before calling a motion chaotic or quasi-periodic.
  bool require_all_indicators = false;
  // Rule 4a, secular growth (see above): whether it runs, its blocks (>= 4), the smallest power
  // of t called growth (> 0) and the smallest rise of the envelope, in log, over the record (> 0).
  bool detect_growth = true;
  int growth_blocks = 8;
  double growth_exponent = 0.75;
  double growth_rise = 0.1;

  bool is_valid(std::string* why) const;
};

struct Classification {
  Regime regime = Regime::uncertain;
  int period = 0;                       // k for periodic; 1 for equilibrium; 0 otherwise
  PeriodResult period_search;           // not run (default) when unbounded
  std::optional<double> lyapunov;       // as given
  double lyapunov_error = 0.0;
  std::optional<double> zero_one_K;     // given or computed; empty when not available or not needed
  std::string zero_one_source;          // "given", "observable", "points", or empty
  std::optional<double> torus_digits;   // as given
  std::string reason;                   // the rule that decided, with the numbers
  // For an uncertain verdict, what each indicator read, as one token without spaces or commas
  // (for result files): "period:none;lambda1:positive;K:between;torus:broken" (rule 4; lambda1
  // positive|zero|negative|inconclusive|unknown, K chaotic|regular|between|unknown, torus
  // curve|broken|between|unknown), "period:7;lambda1:positive" (rule 2), "points:too-few"
  // (rule 3); empty for other verdicts.
  std::string readings;
  // Rule 4a's fitted power of t of the amplitude's envelope over the whole record, when it ran
  // (no period found, enough points, λ1 not negative).
  std::optional<double> growth_exponent;

  std::string name() const { return regime_name(regime, period); }
};

// Throws InputError for invalid options, no points, points of differing dimensions, a non-finite
// λ1 or K, negative or non-finite torus digits, a negative lyapunov_error, K outside [-1, 1], a first_point_time that is not positive
// and finite, or an observable_component out of range when K is to be computed from the points.
// Non-finite points are not an error: they are rule 1.
Classification classify_motion(const std::vector<Vector>& points,
                               const MotionEvidence& evidence = {},
                               const ClassifierOptions& options = {});

// Scalar maps: each point one number.
Classification classify_motion(const std::vector<double>& values,
                               const MotionEvidence& evidence = {},
                               const ClassifierOptions& options = {});

}  // namespace pwl::analysis
