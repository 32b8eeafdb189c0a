// Stage 3 of the ladder: Newton on the stroboscopic map (orbits/orbit_refinement.hpp).
//
// A period verdict is checked at its period (PointSettings::check_periods; always for a period
// above kCheckedPeriod when refinement is on): Newton from the motion's last state, reduced to the
// orbit's minimal period, decides whether the motion is on the orbit or approaching it (with the
// periods it still needs) and gives its leading multiplier. A record's period search can take
// seven turns of a slow spiral onto a period-1 orbit for a period-7 cycle (a complex pair near the
// unit circle turning about 2/7 of a circle a period), or a slow near-return of a torus near a
// resonance for a long period: Newton tells both apart. A period Newton does not confirm is
// "uncertain" (disagreement "period:k;newton:not-confirmed").
//
// A record without a period (quasi-periodic or uncertain) is refined (refine_max_period): Newton
// at the near-return candidates, then, for a record whose rotation number is close to a fraction
// p/q (locked_period: an orbit locked on a torus, beyond the period search), at q. An orbit the
// motion is on, or is confirmed to approach, makes it period-k.
//
// A failure of Newton itself (an iterate that blows up, an unsolvable LCP) leaves the verdict.
// Parker and Chua, Practical Numerical Algorithms for Chaotic Systems, Springer 1989, ch. 5
// (shooting); Lathrop and Kostelich, Phys. Rev. A 40 (1989) 4028 (close returns).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "study/ladder/stages.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/orbit_refinement.hpp"
#include "pwl/analysis/period_detection.hpp"
#include "pwl/analysis/rotation_fraction.hpp"

namespace pwl::analysis::ladder {

namespace {

constexpr int kCheckedPeriod = 32;

// The verdict of an orbit that describes the motion.
void take_orbit(const orbits::OrbitRefinement& r, PointResult& result) {
  result.regime = regime_name(Regime::periodic, r.orbit.period);
  result.period = r.orbit.period;
  result.minimal_period = r.orbit.period;
  result.multiplier = r.orbit.multipliers.largest_modulus();
  result.disagreement.clear();
  result.settle_periods = r.on_orbit ? 0.0 : r.periods_to_settle;
}

// The record's own precision: its period search calls two points the same within 1e-6 of the
// record's scale (period_detection.hpp), the diagonal of the points' bounding box. A motion that
// close to an attracting orbit of the record's period is on it for the verdict, even when it does
// not come closer at the rate the multiplier predicts: at distances of 1e-8 an orbit near a
// grazing contact is not smooth enough for that (measured on figure 5's chain, α = 2,
// θ = 2.8718: a stable period-6 orbit, |μ| = 0.932, with the motion 1.6e-8 from it for good).
bool on_to_record_precision(const orbits::OrbitRefinement& r, int period,
                            const std::vector<Vector>& points) {
  if (!r.found || !r.attracting || r.orbit.period != period || points.empty()) return false;
  Vector low = points.front(), high = points.front();
  for (const Vector& y : points) {
    low = low.cwiseMin(y);
    high = high.cwiseMax(y);
  }
  const PeriodOptions search;
  return r.distance <= search.tolerance * (high - low).norm();
}

}  // namespace

orbits::RefinementOptions period_check(int period, Index dofs) {
  orbits::RefinementOptions options;
  options.periods = {period};
  options.max_period = period;
  if (dofs > PointSettings::kRefinedMasses) options.max_check_periods = kLargeCheckPeriods;
  return options;
}

void newton_stage(PointRun& run) {
  const PointSettings& s = run.settings;
  PointResult& result = run.result;
  const Index n = run.point.structure.dofs();
  if (!run.classified || result.final_state.size() != 2 * n) return;
  if (!s.section.stroboscopic() && run.points.empty()) return;
  const bool small = n <= PointSettings::kRefinedMasses;
  const bool periodic = result.period > 0;
  const bool long_period =
      periodic && small && result.period > kCheckedPeriod && s.refine_max_period > 0;
  const bool check = periodic && (s.check_periods || long_period);
  // A record without a period that the accurate method will run again is refined on that run's
  // map, not on this one (the same Newton, on the map that decides).
  const bool refine = !periodic && s.refine_max_period > 0 && small &&
                      (result.regime == "quasi-periodic" || result.regime == "uncertain") &&
                      !rerun_by_accurate_method(run);
  if (!check && !refine) return;
  orbits::RefinementOptions options = period_check(std::max(1, result.period), n);
  options.max_period = std::max({1, s.refine_max_period, result.period});
  if (!check) options.periods.clear();  // refinement: the record's candidates
  try {
    orbits::StroboscopicMap map(run.point, s.method, s.steps_per_period);
    run.watch(map);
    orbits::OrbitRefinement r = orbits::refine_orbit(map, run.points, result.final_state, options);
    if (refine && !r.explains_motion()) {
      const int locked = locked_denominator(result.rotation, kLockedPeriodLimit);
      if (locked > 0 && std::find(r.tried.begin(), r.tried.end(), locked) == r.tried.end()) {
        options.max_period = std::max(options.max_period, locked);
        options.periods = {locked};
        r = orbits::refine_orbit(map, run.points, result.final_state, options);
      }
    }
    if (r.explains_motion()) {
      take_orbit(r, result);
    } else if (check && on_to_record_precision(r, result.period, run.points)) {
      take_orbit(r, result);
      result.settle_periods = 0.0;
    } else if (check) {
      result.disagreement = fmt::format("period:{};newton:not-confirmed", result.period);
      result.regime = regime_name(Regime::uncertain);
      result.period = 0;
    }
  } catch (const DivergenceError&) {
  } catch (const LcpError&) {
  } catch (const BudgetError&) {
  } catch (const InputError&) {
    // A method without a tangent map (dopri5, rkf78) has no Newton: the record's verdict stays.
  }
}

}  // namespace pwl::analysis::ladder
