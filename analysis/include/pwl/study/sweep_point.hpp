#pragma once
// The motion-analysis pipeline: one case integrated from a given state past its transient, its
// Poincaré points recorded and its motion classified. `pwl sweep`, `pwl map` and
// `pwl analyze` all evaluate their points here, so the same case with the same settings gives the
// same regime, period, λ1 and K whichever job asks.
//
// A bifurcation diagram or a regime map evaluates thousands of points, so a point keeps only what
// a study needs: the Poincaré points of the chosen state components, its indicators (the regime,
// its period, λ1 and K of the 0-1 test; indicators.hpp lists them) and the final state, from which
// the next point of a continuation starts. A caller that wants more (`pwl analyze` writes the
// trajectory and the full Poincaré points and prints the evidence of the classification) passes a
// PointObserver, which sees the integrator, every step of the periods it asks for, every recorded
// Poincaré point and the classification, without a second integration or a second classification.
//
// Sections. The regime, its period, λ1 and K are properties of the motion, defined on its
// stroboscopic map: they are always classified on the points at t = (k + phase) T, the phase of
// settings.section. What the section changes is which points are recorded (PointResult::poincare
// and the observer's poincare_point): those same stroboscopic points for a stroboscopic section,
// every crossing of the hyperplane during the recorded periods for a hyperplane one
// (section_sampler.hpp says how both are sampled). The default, the strobe at phase 0, is what
// every job did before sections were chosen, step for step.
//
// The result depends only on the case, the initial state and the settings: no clock, no thread,
// no random seed that is not fixed here. That is what makes a serial, a multithreaded, a
// distributed and a resumed study write identical files.
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/analysis/poincare_section.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/point_model.hpp"
#include "pwl/types.hpp"

namespace pwl::analysis {

// How λ1 is estimated.
enum class LyapunovEstimate {
  // One tangent vector pushed through the integrator's exact tangent map and renormalised every
  // period (the QR method with one column). A study's default: it costs one extra column.
  tangent_vector,
  // The whole tangent frame: the Jacobian of every period, QR method on a seeded random frame
  // (lyapunov.hpp), λ1 the largest of the spectrum. 2n columns.
  tangent_frame,
  // Two nearby trajectories (separation 1e-7, renormalised every period): for methods without a
  // tangent map (dopri5, rkf78, the exact solver). Costs a second integration of the record.
  two_trajectories,
};

// "tangent-vector", "tangent-frame", "two-trajectories".
std::string lyapunov_estimate_name(LyapunovEstimate estimate);
// The inverse. Throws InputError naming the value and the accepted names.
LyapunovEstimate parse_lyapunov_estimate(const std::string& name);
// The estimate every job uses unless told otherwise, so that `pwl analyze` and a one-point sweep
// of the same case answer alike: one tangent vector for a method with an exact tangent map, two
// nearby trajectories for one without.
LyapunovEstimate default_lyapunov_estimate(Method method);

// Which verdicts of an approximate fixed-grid method (the PIM at its step) are checked by the exact
// event-driven solver: the PIM's O(η²) error can turn a stable period-4 orbit into a small chaotic
// motion around it (measured on the (θ, α) map: α = 10, θ = 0.82, λ1 = +0.10 by the PIM at T/200,
// a period-4 orbit with λ1 = −0.17 by the exact solver), or move a long period or a torus.
enum class Confirmation {
  none,       // the method's verdict stands
  uncertain,  // a point still uncertain (after adaptive evidence and refinement) is run again
  aperiodic,  // so are chaotic and quasi-periodic points
  // A period verdict is checked by Newton on the accurate method's map at that period (its
  // motion from the same start where Newton fails or finds another orbit), and uncertain and
  // quasi-periodic points are run again: every regular verdict rests on the accurate method.
  regular,
  all,  // regular, and chaotic points are run again too
};
// "none", "uncertain", "aperiodic", "regular", "all"; the inverse throws InputError naming the
// value.
std::string confirmation_name(Confirmation confirmation);
Confirmation parse_confirmation(const std::string& name);

struct PointSettings {
  int transient_periods = 500;  // forcing periods integrated and discarded (>= 0)
  int recorded_periods = 500;   // Poincaré points recorded and classified (>= 1)
  // Steps per forcing period of a fixed-grid method (method_traits(m).fixed_grid):
  // η = T / steps_per_period.
  int steps_per_period = 200;
  // 0-based state components kept in PointResult::poincare: 0..n-1 are x1..xn, n..2n-1 are
  // v1..vn. May be empty (a regime map keeps only the indicators).
  std::vector<int> components;
  // Adaptive evidence: a record classified "uncertain" (its indicators disagree) is carried on,
  // doubling it each time (500 recorded: 1000, 2000, 4000 in all), and classified again, until a
  // verdict or until this many periods beyond recorded_periods are spent; 0 (the default): the
  // record is what is set. PointResult::extra_periods says how many were used. Stroboscopic
  // sections only. Refinement (below) runs after it, on the last record.
  int evidence_periods = 0;
  // Coexisting attractors: besides `initial_state` the point is started from starts − 1 more
  // states, reproducible pseudo-random ones in boxes about the motion that grow from 1.5 to 6
  // times the largest |x| and |v| over the tail of the first motion, each evaluated with these
  // settings, and
  // PointResult::attractors counts the distinct attractors they end on (attractor_catalogue.hpp).
  // The point's own indicators stay those of the first start. 1: not counted.
  int starts = 1;
  // Which verdicts the exact event-driven solver checks (see Confirmation): the point is run
  // again from its initial state with the same settings but the exact solver, and that run's
  // result is the point's (PointResult::confirmed_by says so). Only for a method that is not
  // exact and a structure the exact solver takes (up to kRefinedMasses degrees of freedom); a
  // confirming run that fails (the solver's work budget) leaves the method's verdict.
  Confirmation confirm = Confirmation::none;
  // Orbit refinement (orbits/orbit_refinement.hpp) of a motion classified "quasi-periodic" or
  // "uncertain": Newton on the stroboscopic map from the motion's final state, at candidate
  // periods up to this many forcing periods; 0 (the library's default) leaves the verdict to the
  // record alone. When it finds a periodic orbit the motion is on, or an attracting one the
  // motion is confirmed to approach, the point is "period-k" with the periods it still needs in
  // PointResult::settle_periods. Two more checks ride on it: a record whose rotation number
  // (PointResult::rotation) lies within 1e-3/q² of a fraction p/q with q <= 1000 is tried at q (an orbit
  // locked on a torus, beyond the period search), and a period the record's search found above
  // 32 is checked by Newton at that period (not confirmed: "uncertain"). Structures of more than
  // kRefinedMasses degrees of freedom are not refined (Newton carries 2n tangent columns through
  // up to this many periods).
  int refine_max_period = 0;
  static constexpr int kRefinedMasses = 20;
  // Every period verdict checked by Newton on the stroboscopic map at its period, from the
  // motion's last state (dense up to 400 state components, Newton–Krylov beyond): the verdict
  // becomes the orbit's minimal period (PointResult::minimal_period), with its leading multiplier
  // and whether the motion is on it or approaching it (settle_periods); a period Newton does not
  // confirm is "uncertain". Off: the record's period stands (as before this setting existed).
  bool check_periods = false;
  // The evidence ladder every job runs unless asked for the plain record (`--quick`): adaptive
  // evidence up to kLadderEvidencePeriods more periods, refinement up to kLadderRefinePeriod,
  // every period checked by Newton, and regular verdicts confirmed by the accurate method
  // (Confirmation::regular). The library's defaults stay the plain record.
  static constexpr int kLadderEvidencePeriods = 3500;
  static constexpr int kLadderRefinePeriod = 150;
  void use_ladder();
  // Whether any step of the ladder is on.
  bool ladder_on() const {
    return evidence_periods > 0 || refine_max_period > 0 || check_periods ||
           confirm != Confirmation::none;
  }
  // How many of the recorded points are kept: 0 every one, N > 0 only the last N (the last N
  // periods of a stroboscopic section, the last N crossings of a hyperplane). All of them are
  // classified either way. A basin map matches attractors on a short tail of each cell's motion
  // and keeps no more than that.
  int kept_points = 0;
  // The section recorded; its phase is also that of the stroboscopic points classified. Period k
  // (1-based) of the integration ends at t = (k + phase) T.
  PoincareSection section;
  int observable = -1;  // component the 0-1 test reads; -1: x of the last degree of freedom
  bool lyapunov = true;  // compute λ1 (at least 10 recorded periods)
  // The tangent estimates need a method with an exact tangent map (has_tangent_map()); with one
  // that has none, λ1 is not computed unless the estimate is two_trajectories.
  LyapunovEstimate lyapunov_estimate = LyapunovEstimate::tangent_vector;
  // The method and its settings (method_table.hpp). Its step (fixed-grid methods) and largest
  // step (adaptive ones: T/8) are set per point from the point's period; see method_for.
  MethodSettings method;

  // The method's settings for a point of forcing period `period`.
  MethodSettings method_for(double period) const;
  // Ceres-style check for a state of 2 `dofs` components: false with a message naming the field.
  bool is_valid(int dofs, std::string* why) const;
  // Every setting, one "key = value" per line in a fixed order (part of a study's description).
  // The section and its phase are stated when they are not the default (the strobe at phase 0),
  // so that the descriptions of studies from before sections existed read the same.
  std::string describe() const;
};

struct PointResult {
  // The indicators (indicators.hpp registers each one: its column, its journal token).
  std::string regime;  // regime_name(...) of the classifier, "unbounded", or "failed" (an
                       // unsolvable LCP, or the exact solver's work budget spent: BudgetError)
  int period = 0;      // k for period-k, 0 otherwise
  double lambda1 = std::numeric_limits<double>::quiet_NaN();  // per forcing period; NaN: none
  double lambda1_error = std::numeric_limits<double>::quiet_NaN();
  double K = std::numeric_limits<double>::quiet_NaN();  // 0-1 test; NaN when not computed
  // Set when orbit refinement settled the regime (PointSettings::refine_max_period): the forcing
  // periods the motion still needs to come within 1e-8 of the orbit, 0 when it is on it; NaN
  // when the regime is the record's own.
  double settle_periods = std::numeric_limits<double>::quiet_NaN();
  // Adaptive evidence (PointSettings::evidence_periods): the periods recorded beyond the setting.
  int extra_periods = 0;
  // The accurate method that checked the verdict (PointSettings::confirm): "exact" or
  // "pim-switching"; empty when none did.
  std::string confirmed_by;
  // How it checked it: "newton" (its orbit at the verdict's period, which the motion is on or
  // approaches) or "motion" (its own motion from the same start decided); empty when not checked.
  std::string confirmation;
  // The method the verdict rests on: the point's own, or the one that confirmed it.
  std::string decided_by;
  // Newton's check of a period verdict (check_periods, refinement, or confirmation): the orbit's
  // minimal period (= period) and the largest modulus of its Floquet multipliers at that period;
  // 0 and NaN when no Newton checked the period.
  int minimal_period = 0;
  double multiplier = std::numeric_limits<double>::quiet_NaN();
  // The period the record's own search found (0: none); differs from `period` when Newton
  // reduced it (seven turns of a slow spiral onto a period-1 orbit) or refinement found one.
  int record_period = 0;
  // The forcing periods the verdict's indicators were measured over (the record with its
  // adaptive evidence, of the run that decided); 0 for a motion that blew up or failed.
  int observed_periods = 0;
  // A chaotic or quasi-periodic verdict: "agree" when λ1, K and the torus test read the same over
  // both halves of the record as over the whole, else "differ:" and the indicators that changed
  // ("differ:lambda1+K"); empty otherwise.
  std::string halves;
  // The rotation of a long period (above 8) or of an orbit locked on a torus as "p/q" (q its
  // period); empty otherwise or when not measured.
  std::string rotation_pq;
  // The torus test (weighted_birkhoff.hpp) of a record without a period: the digits on which the
  // weighted Birkhoff averages of its two halves agree (high on a smooth invariant curve, about 1
  // to 2 on chaos), and the rotation number in the plane of the first two state components, in
  // turns per forcing period; NaN when not measured (a period found, or fewer than 200 points).
  double torus_digits = std::numeric_limits<double>::quiet_NaN();
  double rotation = std::numeric_limits<double>::quiet_NaN();
  // For an uncertain point, which indicators disagree: the classifier's readings
  // (Classification::readings), or "period:k;newton:not-confirmed" for a long period Newton did
  // not confirm; empty otherwise.
  std::string disagreement;
  // Transient chaos: a motion that settled on its period-k orbit after wandering chaotically
  // (finite-time λ1 clearly positive and K > 0.8 over the stretch) for this many forcing periods
  // from the start; 0 when none was found (or not looked for: more than kRefinedMasses degrees
  // of freedom, or no period).
  int chaotic_transient = 0;
  // Distinct attractors reached from the point's starts (PointSettings::starts > 1, the
  // attractor at infinity counted); 0 when not counted.
  int attractors = 0;

  int columns = 0;              // = settings.components.size()
  std::vector<double> poincare; // recorded points x columns, row-major
  // The time of each recorded point of a hyperplane section (one per row, also when columns is
  // 0); empty for a stroboscopic section, whose row k is the period transient + k + 1.
  std::vector<double> section_times;
  // [x; v] at a whole number of forcing periods after the record, where the loads are at phase 0
  // again, so that the next point of a continuation starts where every point starts: the last
  // stroboscopic point at phase 0, else the state at t = (transient + recorded + 1) T. Empty when
  // the motion blew up or failed.
  Vector final_state;

  int rows() const { return columns == 0 ? 0 : static_cast<int>(poincare.size()) / columns; }
};

// A small integer per regime for colour maps and legends: 1..8 period-k, 9 a longer period,
// 10 quasi-periodic, 11 chaotic, 12 unbounded, 13 uncertain or failed.
int regime_code(const std::string& regime, int period);

// Hooks into one point's evaluation. Every hook is optional; all are called on the evaluating
// thread, in the order of the motion.
class PointObserver {
 public:
  virtual ~PointObserver() = default;
  // Once, with the integrator at the initial state, before the first period.
  virtual void started(const Integrator& /*integrator*/, const PointCase& /*point*/) {}
  // Before period k (1-based from the initial state) is integrated: what sees its steps (an
  // empty observer: nothing).
  virtual StepObserver steps_of_period(int /*k*/) { return {}; }
  // Every recorded point of the section, the full state [x; v] at time t in period k: for a
  // stroboscopic section t = (k + phase) T, for a hyperplane the crossing's time.
  virtual void poincare_point(int /*k*/, double /*t*/, const Vector& /*state*/) {}
  // Once, when the recorded points are classified (not for a motion that blew up or failed; a
  // growth found by the classifier is classified, and "unbounded").
  virtual void classified(const Classification& /*classification*/,
                          const PointResult& /*result*/) {}
  // After each stage of the ladder ("record", "newton", "observation", "confirmation",
  // "attractors"; a confirming run by the accurate method reports none): for a caller that
  // measures what each stage costs. Never changes the result.
  virtual void stage_finished(std::string_view /*stage*/) {}
  // Called often while the point is evaluated, by every run and stage of the ladder (before every
  // forcing period of a record, and before every integration of a Newton stage's map), also in a
  // confirming run that is not otherwise observed: a caller that abandons points on a signal
  // throws from here, and the point's evaluation ends at once.
  virtual void checkpoint() {}
};

// Integrates `point` from `initial_state` ([x; v], 2n; the loads start at phase 0) over
// transient_periods + recorded_periods forcing periods, records the section over the recorded ones
// and classifies their stroboscopic points: the period search on the full state, λ1 over the recorded periods as settings.lyapunov_estimate says (the
// first min(50, recorded/5) periods align the tangent vector or frame, the rest are averaged in
// min(10, ...) blocks), and K on the observable when at least 100 points are recorded. A motion
// that blows up is "unbounded" (not an exception), and so is one that grows without bound while
// staying finite over the record, such as an undamped resonance: the classifier's secular-growth
// rule (motion_classifier.hpp, rule 4a) measures the amplitude's power of t against the time since
// the initial state; its final state is then left empty, as for a blow-up. Then the evidence
// ladder, as far as the settings ask (each step off by default here; PointSettings::use_ladder
// turns all on, as every job does unless --quick): adaptive evidence, Newton's check of a period
// and refinement of a record without one, transient chaos, what the verdict was seen over, the
// confirmation by an accurate method, more starts (analysis/src/study/ladder/ has one file per
// stage). The observer sees the first run's record; a confirming run by the accurate method is
// not observed, but `classified` gets the classification of the run the verdict rests on. Throws
// InputError for invalid settings or state.
PointResult evaluate_point(const PointCase& point, const Vector& initial_state,
                           const PointSettings& settings, PointObserver* observer = nullptr);

}  // namespace pwl::analysis
