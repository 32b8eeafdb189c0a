// Stage 6 of the ladder: a verdict of the system, not of the step.
//
// A fixed-step method's verdict can be a property of its step: the PIM's O(η²) error can turn a
// stable period-4 orbit into a small chaotic motion around it (the (θ, α) map of figure 5's chain,
// α = 10, θ = 0.82: λ1 = +0.10 by the PIM at T/200, a period-4 orbit with λ1 = −0.17 by the exact
// solver), or lock a motion on a period the structure does not have (α = 9.3, θ = 1.83: period 155
// by the PIM at T/200; the exact motion is on a period-329 orbit, and Newton at 155 on the exact
// map stalls). The verdict is therefore checked by a method whose error cannot move it
// (accurate_method_for): the exact event-driven solver up to kRefinedMasses degrees of freedom,
// the switching PIM (located switches, order 5) beyond, for a method that does not locate its
// switches.
//
//  - A period-k verdict (PointSettings::confirm regular or all): Newton on the accurate method's
//    stroboscopic map at k from the motion's last state, and the approach to its orbit checked by
//    that method's motion (orbit_refinement.hpp, steps 2-4). An orbit of minimal period k that
//    the motion is on or approaches confirms the verdict (PointResult::confirmation "newton",
//    its multiplier the accurate one).
//  - Where that Newton fails or finds another orbit, and for the verdicts the setting names
//    (uncertain always; quasi-periodic for aperiodic, regular, all; chaotic for aperiodic, all),
//    the point is run again from its initial state by the accurate method through the whole
//    ladder, and that run decides (confirmation "motion").
// A confirming run that fails (the exact solver's work budget) leaves the method's verdict.
// PointResult::decided_by names the method the verdict rests on.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "study/ladder/stages.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/orbit_refinement.hpp"

namespace pwl::analysis::ladder {

namespace {

bool reruns(Confirmation confirm, const std::string& regime) {
  if (confirm == Confirmation::none) return false;
  if (regime == "uncertain") return true;
  if (regime == "quasi-periodic") return confirm != Confirmation::uncertain;
  if (regime == "chaotic") return confirm == Confirmation::aperiodic || confirm == Confirmation::all;
  return false;
}

bool checks_periods(Confirmation confirm) {
  return confirm == Confirmation::regular || confirm == Confirmation::all;
}

// Whether the accurate motion from `state` (the fixed-step motion's last state, within that
// method's error of the accurate orbit `r`, not on it) reaches the orbit. refine_orbit's own check
// compares the distance over two short windows, P + W periods for the multiplier to halve it:
// from a state off the orbit along every mode (the fixed-step error is not along the slowest one)
// the fast modes and the turning of a complex pair make a few periods' maxima rise and fall
// (measured on figure 5's chain, α = 2.5, θ = 0.9487: a stable period-2 orbit of the exact map,
// |μ| = 0.874 a period, 6.6e-4 from the PIM's state at T/200, the distance 1.44 times larger after
// the 8 periods of that check). Here the motion is followed until the multiplier predicts a
// thousandfold shrinking (at most kReachPeriods), and must have come 100 times closer, or onto
// the orbit.
constexpr int kReachPeriods = 20000;
bool reaches(orbits::StroboscopicMap& map, const orbits::OrbitRefinement& r, const Vector& state) {
  if (!r.found || !r.attracting) return false;
  const int k = r.orbit.period;
  const double rho = r.orbit.multipliers.largest_modulus();  // per k periods
  const int cycles =
      rho > 0.0 ? static_cast<int>(std::ceil(std::log(1e-3) / std::log(rho))) : 1;
  if (cycles < 1 || static_cast<long>(cycles) * k > kReachPeriods) return false;
  std::vector<Vector> orbit{r.orbit.state};
  for (int j = 1; j < k; ++j) orbit.push_back(map.advance(orbit.back(), 1));
  Vector y = state;
  for (int c = 0; c < cycles; ++c) y = map.advance(y, k);
  double distance = std::numeric_limits<double>::infinity();
  for (const Vector& p : orbit) distance = std::min(distance, (y - p).lpNorm<Eigen::Infinity>());
  return distance <= std::max(1e-2 * r.distance, r.tolerance);
}

}  // namespace

AccurateMethod accurate_method_for(const PointCase& point, const PointSettings& settings) {
  const MethodTraits& row = method_traits(settings.method.method);
  AccurateMethod out;
  if (row.exact) return out;
  const Index n = point.structure.dofs();
  std::string why;
  const auto accepts = [&](Method m) {
    PointSettings s = settings;
    s.method = MethodSettings{m};
    s.method.banded_above = settings.method.banded_above;
    return s.method_for(point.period).is_valid(point.structure, &why);
  };
  if (n <= PointSettings::kRefinedMasses && accepts(Method::exact)) {
    out.has = true;
    out.method = Method::exact;
  } else if (!row.locates_switches && row.fixed_grid && accepts(Method::pim_switching)) {
    out.has = true;
    out.method = Method::pim_switching;
  }
  return out;
}

bool rerun_by_accurate_method(const PointRun& run) {
  return run.classified && reruns(run.settings.confirm, run.result.regime) &&
         accurate_method_for(run.point, run.settings).has;
}

void confirmation_stage(PointRun& run) {
  const PointSettings& s = run.settings;
  PointResult& result = run.result;
  if (s.confirm == Confirmation::none || !run.classified) return;
  const bool check = checks_periods(s.confirm) && result.period > 0 &&
                     result.final_state.size() == 2 * run.point.structure.dofs();
  bool rerun = reruns(s.confirm, result.regime);
  if (!check && !rerun) return;
  const AccurateMethod accurate = accurate_method_for(run.point, s);
  if (!accurate.has) return;
  PointSettings settings = s;
  settings.method = MethodSettings{accurate.method};
  settings.method.lcp = s.method.lcp;
  settings.method.banded_above = s.method.banded_above;
  settings.confirm = Confirmation::none;
  const std::string name(method_traits(accurate.method).name);
  if (check) {
    const int k = result.period;
    const orbits::RefinementOptions options = period_check(k, run.point.structure.dofs());
    try {
      orbits::StroboscopicMap map(run.point, settings.method, settings.steps_per_period);
      run.watch(map);
      const orbits::OrbitRefinement r =
          orbits::refine_orbit(map, run.points, result.final_state, options);
      if (r.orbit.period == k && (r.explains_motion() || reaches(map, r, result.final_state))) {
        result.confirmed_by = name;
        result.confirmation = "newton";
        result.decided_by = name;
        result.minimal_period = k;
        result.multiplier = r.orbit.multipliers.largest_modulus();
        return;
      }
    } catch (const DivergenceError&) {
    } catch (const LcpError&) {
    } catch (const BudgetError&) {
    }
    rerun = true;
  }
  if (!rerun) return;
  CheckpointsOnly checkpoints(run.observer);
  PointRun again(run.point, run.initial_state, settings, &checkpoints);
  run_with_method(again);
  if (again.result.regime == "failed") return;
  again.result.confirmed_by = name;
  again.result.confirmation = "motion";
  run.result = std::move(again.result);
  run.points = std::move(again.points);
  run.history = std::move(again.history);
  run.jacobians = std::move(again.jacobians);
  run.classification = again.classification;
  run.classified = again.classified;
  run.tail = std::move(again.tail);
}

}  // namespace pwl::analysis::ladder
