#include "pwl/study/sweep_point.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>

#include "study/ladder/stages.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"

namespace pwl::analysis {

std::string lyapunov_estimate_name(LyapunovEstimate estimate) {
  switch (estimate) {
    case LyapunovEstimate::tangent_vector: return "tangent-vector";
    case LyapunovEstimate::tangent_frame: return "tangent-frame";
    case LyapunovEstimate::two_trajectories: return "two-trajectories";
  }
  return "tangent-vector";
}

LyapunovEstimate default_lyapunov_estimate(Method method) {
  return method_traits(method).tangent_map ? LyapunovEstimate::tangent_vector
                                           : LyapunovEstimate::two_trajectories;
}

LyapunovEstimate parse_lyapunov_estimate(const std::string& name) {
  for (LyapunovEstimate e : {LyapunovEstimate::tangent_vector, LyapunovEstimate::tangent_frame,
                             LyapunovEstimate::two_trajectories}) {
    if (lyapunov_estimate_name(e) == name) return e;
  }
  throw InputError(fmt::format(
      "lyapunov = \"{}\" is not known; use tangent-vector, tangent-frame or two-trajectories",
      name));
}

MethodSettings PointSettings::method_for(double period) const {
  return method.for_period(period, steps_per_period);
}

bool PointSettings::is_valid(int dofs, std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (transient_periods < 0) {
    *why = fmt::format("transient periods = {} must be >= 0", transient_periods);
    return false;
  }
  if (recorded_periods < 1) {
    *why = fmt::format("recorded periods = {} must be >= 1", recorded_periods);
    return false;
  }
  const MethodTraits& row = method_traits(method.method);
  if (row.fixed_grid && steps_per_period < 1) {
    *why = fmt::format("steps per period = {} must be >= 1 ({} steps on a fixed grid)",
                       steps_per_period, row.name);
    return false;
  }
  if (starts < 1 || starts > 1000) {
    *why = fmt::format("starts = {} must be in 1..1000", starts);
    return false;
  }
  if (evidence_periods < 0) {
    *why = fmt::format("evidence periods = {} must be >= 0 (0: no longer records)",
                       evidence_periods);
    return false;
  }
  if (refine_max_period < 0 || refine_max_period > 1000) {
    *why = fmt::format("refine max period = {} must be in 0..1000 (0: no orbit refinement)",
                       refine_max_period);
    return false;
  }
  if (kept_points < 0) {
    *why = fmt::format("kept points = {} must be >= 0 (0: every recorded point)", kept_points);
    return false;
  }
  for (int c : components) {
    if (c < 0 || c >= 2 * dofs) {
      *why = fmt::format("component {} is out of range: the state has {} components (0..{})", c,
                         2 * dofs, 2 * dofs - 1);
      return false;
    }
  }
  if (observable < -1 || observable >= 2 * dofs) {
    *why = fmt::format("observable = {} is out of range (-1 or 0..{})", observable, 2 * dofs - 1);
    return false;
  }
  if (row.adaptive && (!(method.tolerance > 0.0) || !std::isfinite(method.tolerance))) {
    *why = fmt::format("tolerance = {} of {} must be positive and finite", method.tolerance,
                       row.name);
    return false;
  }
  if (!section.is_valid(dofs, why)) return false;
  if (method.banded_above < 0) {
    *why = fmt::format("banded_above = {} must be >= 0", method.banded_above);
    return false;
  }
  return true;
}

std::string PointSettings::describe() const {
  const MethodTraits& row = method_traits(method.method);
  std::string s = fmt::format(
      "transient_periods = {}\nrecorded_periods = {}\nsteps_per_period = {}\n"
      "components = {}\nobservable = {}\nlyapunov = {}\nlyapunov_estimate = {}\nmethod = {}\n",
      transient_periods, recorded_periods, steps_per_period, fmt::join(components, ","),
      observable, lyapunov, lyapunov_estimate_name(lyapunov_estimate), method_label(method));
  if (row.lcp) s += fmt::format("lcp = {}\n", lcp_algorithm_name(method.lcp));
  if (row.chooses_form) s += fmt::format("banded_above = {}\n", method.banded_above);
  // Only a section other than the default is stated (see the header). The hyperplane's component
  // is 0-based here: the description knows no number of masses.
  if (!section.stroboscopic()) {
    const char* direction = section.hyperplane.direction == CrossingDirection::up     ? "up"
                            : section.hyperplane.direction == CrossingDirection::down ? "down"
                                                                                       : "both";
    s += fmt::format("section = hyperplane\nsection_component = {}\nsection_level = {:.17g}\n"
                     "section_direction = {}\n",
                     section.hyperplane.component, section.hyperplane.level, direction);
  }
  if (section.phase != 0.0) s += fmt::format("phase = {:.17g}\n", section.phase);
  // Stated only when set, as the section: descriptions from before it read the same.
  if (kept_points != 0) s += fmt::format("kept_points = {}\n", kept_points);
  if (refine_max_period != 0) s += fmt::format("refine_max_period = {}\n", refine_max_period);
  if (evidence_periods != 0) s += fmt::format("evidence_periods = {}\n", evidence_periods);
  if (confirm != Confirmation::none) s += fmt::format("confirm = {}\n", confirmation_name(confirm));
  if (check_periods) s += "check_periods = true\n";
  if (starts != 1) s += fmt::format("starts = {}\n", starts);
  return s;
}

int regime_code(const std::string& regime, int period) {
  if (regime.rfind("period-", 0) == 0) return period >= 1 && period <= 8 ? period : 9;
  if (regime == "equilibrium") return 1;
  if (regime == "quasi-periodic") return 10;
  if (regime == "chaotic") return 11;
  if (regime == "unbounded") return 12;
  return 13;
}


std::string confirmation_name(Confirmation confirmation) {
  switch (confirmation) {
    case Confirmation::none:
      return "none";
    case Confirmation::uncertain:
      return "uncertain";
    case Confirmation::aperiodic:
      return "aperiodic";
    case Confirmation::regular:
      return "regular";
    case Confirmation::all:
      return "all";
  }
  return "none";
}

Confirmation parse_confirmation(const std::string& name) {
  for (Confirmation c : {Confirmation::none, Confirmation::uncertain, Confirmation::aperiodic,
                         Confirmation::regular, Confirmation::all}) {
    if (confirmation_name(c) == name) return c;
  }
  throw InputError(fmt::format(
      "confirmation '{}': expected none, uncertain, aperiodic, regular or all", name));
}

void PointSettings::use_ladder() {
  evidence_periods = kLadderEvidencePeriods;
  refine_max_period = kLadderRefinePeriod;
  check_periods = true;
  confirm = Confirmation::regular;
}

namespace ladder {

// The ladder with the settings' method, up to the confirmation by a more accurate one: what the
// confirmation runs again with that method.
void run_with_method(PointRun& run) {
  record_stage(run);       // the motion, its record, the indicators, adaptive evidence
  run.finished("record");
  newton_stage(run);       // every period checked by Newton; refinement of what has none
  run.finished("newton");
  transient_stage(run);    // a chaotic transient before the cycle
  observation_stage(run);  // what the verdict was seen over
  run.finished("observation");
}

// Everything but the attractors: what every start of a point goes through.
void evaluate_ladder(PointRun& run) {
  run_with_method(run);
  confirmation_stage(run);  // a method whose error cannot move the verdict
  run.finished("confirmation");
}

}  // namespace ladder

PointResult evaluate_point(const PointCase& point, const Vector& initial_state,
                           const PointSettings& s, PointObserver* observer) {
  ladder::PointRun run(point, initial_state, s, observer);
  ladder::evaluate_ladder(run);
  ladder::attractor_stage(run);  // more starts: the attractors that coexist
  run.finished("attractors");
  if (observer != nullptr && run.classified) observer->classified(run.classification, run.result);
  return run.result;
}

}  // namespace pwl::analysis
