#include "pwl/study/sweep_point.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <memory>

#include "pwl/analysis/attractor_catalogue.hpp"
#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/orbit_refinement.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/section_sampler.hpp"

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

namespace {

// A fixed unit vector with every component non-zero, so that it has a part along the most
// expanding direction of any orbit (a random frame would do as well; a fixed one keeps every point
// reproducible without a seed).
Matrix initial_tangent(Index size) {
  Matrix y(size, 1);
  for (Index i = 0; i < size; ++i) y(i, 0) = 1.0 + 0.1 * static_cast<double>(i);
  y /= y.norm();
  return y;
}

// The averaging of λ1 over `count` periods: the first min(50, recorded/5) align the tangent
// vector, frame or separation; the rest are averaged in up to 10 blocks.
struct Averaging {
  long transient = 0;
  long iterations = 0;
  int blocks = 0;
  bool enough() const { return blocks >= 2; }
};

Averaging averaging(long count, int recorded) {
  Averaging a;
  a.transient = std::min(50, recorded / 5);
  a.iterations = count - a.transient;
  a.blocks = static_cast<int>(std::min<long>(10, a.iterations));
  return a;
}

// λ1 by two nearby trajectories of the period map from the first recorded point. The loads are
// T-periodic, so every period starts at t = phase T (t = 0 at phase 0). A blow-up of the companion
// leaves λ1 unknown.
void two_trajectory_lyapunov(const PointCase& point, const MethodSettings& method, double phase,
                             const std::vector<Vector>& points, int recorded, PointResult& result) {
  const Averaging a = averaging(recorded, recorded);
  if (!a.enough() || points.empty()) return;
  const Index n = point.structure.dofs();
  auto shadow = make_integrator(point.structure, method);
  const double start = phase * point.period;
  const StateMap map = [&](const Vector& s) {
    shadow->set_state(start, s.head(n), s.tail(n));
    shadow->advance_to(start + point.period);
    Vector image(2 * n);
    image << shadow->position(), shadow->velocity();
    return image;
  };
  TwoTrajectoryOptions l;
  l.transient = a.transient;
  l.iterations = a.iterations;
  l.blocks = a.blocks;
  l.time_per_iteration = point.period;
  l.separation = 1e-7;
  try {
    const LyapunovResult lyapunov = largest_lyapunov_two_trajectories(map, points.front(), l);
    result.lambda1 = lyapunov.largest();
    result.lambda1_error = lyapunov.error[0];
  } catch (const DivergenceError&) {
  } catch (const LcpError&) {
  } catch (const BudgetError&) {
  }
}

Matrix as_rows(const std::vector<Vector>& states) {
  Matrix m(static_cast<Index>(states.size()), states.empty() ? 0 : states.front().size());
  for (std::size_t i = 0; i < states.size(); ++i) m.row(static_cast<Index>(i)) = states[i];
  return m;
}

// Drops all but the last `kept` recorded points (0: keeps them all).
void keep_last_points(int kept, PointResult& result) {
  if (kept <= 0) return;
  const std::size_t rows = result.columns == 0 ? result.section_times.size()
                                               : result.poincare.size() / result.columns;
  if (rows <= static_cast<std::size_t>(kept)) return;
  const std::size_t dropped = rows - static_cast<std::size_t>(kept);
  result.poincare.erase(result.poincare.begin(),
                        result.poincare.begin() + static_cast<std::ptrdiff_t>(dropped) * result.columns);
  if (!result.section_times.empty()) {
    result.section_times.erase(result.section_times.begin(),
                               result.section_times.begin() + static_cast<std::ptrdiff_t>(dropped));
  }
}

// The period q of an orbit locked on a torus, from the rotation number of its points: the
// denominator of the first continued-fraction convergent p/q of ρ with |ρ − p/q| <= kLocked / q²,
// if q <= limit; 0 otherwise. Every irrational ρ has infinitely many p/q within 1/q² (Dirichlet),
// and a typical one no p/q much closer, while an orbit locked at rotation p/q has that rotation to
// the averages' precision (the (θ, α) map's cell α = 5, θ = 1.81 by the exact solver: ρ =
// 0.3013698628 against 22/73 = 0.3013698630, 1e-6 of 1/q²). kLocked = 1e-3 asks a thousand times
// closer than Dirichlet's bound: the torus at θ = 1.8, whose ρ = 0.3063343651 lies 6.6e-9 from
// 295/963 (6e-3 of 1/q²), is not taken for a locked orbit.
constexpr double kLocked = 1e-3;
constexpr int kLockedPeriodLimit = 1000;
int locked_period(double rho, int limit) {
  if (!std::isfinite(rho)) return 0;
  // Convergents h/k of ρ: h_{-1} = 1, h_{-2} = 0; k_{-1} = 0, k_{-2} = 1.
  double x = rho;
  long h0 = 0, h1 = 1, k0 = 1, k1 = 0;
  for (int i = 0; i < 40; ++i) {
    const double a = std::floor(x);
    const long h = static_cast<long>(a) * h1 + h0;
    const long k = static_cast<long>(a) * k1 + k0;
    if (k > limit) return 0;
    const double q = static_cast<double>(k);
    if (k >= 1 && std::abs(rho - static_cast<double>(h) / q) <= kLocked / (q * q)) {
      return static_cast<int>(k);
    }
    const double fraction = x - a;
    if (fraction <= 0.0) return 0;
    x = 1.0 / fraction;
    h0 = h1;
    h1 = h;
    k0 = k1;
    k1 = k;
  }
  return 0;
}

// Orbit refinement (PointSettings::refine_max_period). A quasi-periodic or uncertain record
// becomes period-k when Newton's orbit describes the motion (the motion is on it, or confirmed to
// approach it): first at the near-return candidates up to refine_max_period, then, for a record
// whose rotation number is close to a fraction p/q (locked_period: an orbit locked on a torus,
// beyond the period search), at q up to kLockedPeriodLimit. A long period the record's search found
// (k > kCheckedPeriod, up to the search's limit of 64) is checked the same way at k: two cycles
// that repeat to 1e-6 of the record's size can also be a slow near-return of a torus close to a
// resonance, which Newton tells apart; a period Newton does not confirm is "uncertain". A failure
// of the refinement itself (an iterate that blows up, an unsolvable LCP) leaves the record's
// verdict.
constexpr int kCheckedPeriod = 32;
void refine_regime(const PointCase& point, const PointSettings& s, const std::vector<Vector>& points,
                   PointResult& result) {
  const Index n = point.structure.dofs();
  if (s.refine_max_period <= 0 || n > PointSettings::kRefinedMasses) return;
  const bool long_period = result.period > kCheckedPeriod;
  if (result.regime != "quasi-periodic" && result.regime != "uncertain" && !long_period) return;
  if (result.final_state.size() != 2 * n) return;
  orbits::RefinementOptions options;
  options.max_period = std::max(s.refine_max_period, result.period);
  if (long_period) options.periods = {result.period};
  try {
    orbits::StroboscopicMap map(point, s.method, s.steps_per_period);
    orbits::OrbitRefinement r = orbits::refine_orbit(map, points, result.final_state, options);
    const int locked = long_period ? 0 : locked_period(result.rotation, kLockedPeriodLimit);
    if (!r.explains_motion() && locked > 0 &&
        std::find(r.tried.begin(), r.tried.end(), locked) == r.tried.end()) {
      options.max_period = std::max(options.max_period, locked);
      options.periods = {locked};
      r = orbits::refine_orbit(map, points, result.final_state, options);
    }
    if (!r.explains_motion()) {
      if (long_period) {
        result.disagreement = fmt::format("period:{};newton:not-confirmed", result.period);
        result.regime = regime_name(Regime::uncertain);
        result.period = 0;
      }
      return;
    }
    result.regime = regime_name(Regime::periodic, r.orbit.period);
    result.period = r.orbit.period;
    result.disagreement.clear();
    result.settle_periods = r.on_orbit ? 0.0 : r.periods_to_settle;
  } catch (const DivergenceError&) {
  } catch (const LcpError&) {
  } catch (const BudgetError&) {
  }
}

// Transient chaos: a motion that ends on a period-k cycle may have wandered chaotically before.
// `states` are the stroboscopic states from period 1 to the end, whose last k repeat. The motion
// settled at period s + 1, s the last index farther from the cycle (the point of the cycle at the
// same phase) than kSettledDistance of the region the whole motion visited (the diagonal of its
// bounding box): before that it was far from the orbit. When s >= kChaoticTransient periods, the
// finite-time λ1 of that stretch is measured along the motion itself (a companion started
// kSeparation off each stored state for one period, its growth the stretch's one-period
// factor, averaged as the record's λ1 is: lyapunov.hpp), K on the observable (also on every
// k-th point, as for banded chaos) and the torus test on the states. A stretch whose λ1 is
// clearly positive (λ1 − error > the classifier's margin, 0.005 per period), whose K is not
// regular (>= 0.2) and whose states are not on a smooth curve (torus digits < 5, when it has 200
// points or more) is a chaotic transient, and PointResult::chaotic_transient = s. Not K > 0.8:
// a chaotic transient that ends on a period-k orbit has hovered near it, a banded chaos that
// holds K down (measured on the (θ, α) map, α = 9, θ = 1.718: 3774 periods with λ1 = 0.059 ±
// 0.005, K = 0.76, 3.0 digits, then a period-7 orbit). A companion
// along the stored states, not a second trajectory from the start: chaos amplifies the rounding
// of a re-run, whose own transient would end elsewhere.
constexpr double kSettledDistance = 1e-2;
constexpr int kChaoticTransient = 100;
// The periods before the motion settled on its cycle, and whether they were chaotic.
struct Settling {
  std::size_t settled = 0;
  bool chaotic = false;
};
Settling find_chaotic_transient(const PointCase& point, const MethodSettings& method, double phase,
                                const std::vector<Vector>& states, int k, int observable) {
  Settling out;
  const std::size_t N = states.size();
  if (k < 1 || N < static_cast<std::size_t>(kChaoticTransient + 2 * k)) return out;
  Vector low = states.front(), high = states.front();
  for (const Vector& y : states) {
    low = low.cwiseMin(y);
    high = high.cwiseMax(y);
  }
  const double far = kSettledDistance * (high - low).norm();
  const std::size_t cycle = N - static_cast<std::size_t>(k);
  std::size_t settled = 0;
  for (std::size_t i = cycle; i-- > 0;) {
    const std::size_t kk = static_cast<std::size_t>(k);
    const std::size_t same = cycle + (i % kk + kk - cycle % kk) % kk;  // same phase on the cycle
    if ((states[i] - states[same]).norm() > far) {
      settled = i + 1;
      break;
    }
  }
  out.settled = settled;
  if (settled < static_cast<std::size_t>(kChaoticTransient)) return out;
  // λ1 along the stretch.
  const Index n = point.structure.dofs();
  auto companion = make_integrator(point.structure, method);
  const double start = phase * point.period;
  constexpr double kSeparation = 1e-7;
  Vector direction = initial_tangent(2 * n).col(0);
  std::vector<Matrix> growth;
  growth.reserve(settled);
  try {
    for (std::size_t i = 0; i + 1 < settled; ++i) {
      const Vector y = states[i] + kSeparation * direction;
      companion->set_state(start, y.head(n), y.tail(n));
      companion->advance_to(start + point.period);
      Vector d(2 * n);
      d << companion->position() - states[i + 1].head(n),
          companion->velocity() - states[i + 1].tail(n);
      const double norm = d.norm();
      if (!(norm > 0.0) || !std::isfinite(norm)) return out;
      growth.push_back(Matrix::Constant(1, 1, norm / kSeparation));
      direction = d / norm;
    }
  } catch (const DivergenceError&) {
    return out;
  } catch (const LcpError&) {
    return out;
  } catch (const BudgetError&) {
    return out;
  }
  LyapunovOptions l;
  const Averaging a = averaging(static_cast<long>(growth.size()), static_cast<int>(growth.size()));
  if (!a.enough()) return out;
  l.transient = a.transient;
  l.iterations = a.iterations;
  l.blocks = a.blocks;
  l.time_per_iteration = point.period;
  const LyapunovResult lyapunov = lyapunov_spectrum(growth, l);
  if (!(lyapunov.largest() - lyapunov.error[0] > ClassifierOptions{}.lyapunov_margin)) return out;
  // K on the stretch, and on its every k-th point.
  double K = -1.0;
  for (std::size_t stride : {std::size_t{1}, static_cast<std::size_t>(k)}) {
    std::vector<double> series;
    for (std::size_t i = 0; i < settled; i += stride) series.push_back(states[i][observable]);
    if (series.size() >= static_cast<std::size_t>(ZeroOneOptions{}.min_samples)) {
      K = std::max(K, zero_one_test(series, ZeroOneOptions{}).K);
    }
  }
  // The torus test on the stretch: the points do not lie on a smooth curve.
  double digits = 0.0;  // not measured (under 200 points): no curve seen
  if (settled >= static_cast<std::size_t>(WeightedBirkhoffOptions{}.min_points)) {
    digits = weighted_birkhoff_test(
                 as_rows(std::vector<Vector>(states.begin(),
                                             states.begin() + static_cast<std::ptrdiff_t>(settled))))
                 .digits;
  }
  const ClassifierOptions rules;
  out.chaotic = K >= rules.regular_K && digits < rules.curve_digits;
  return out;
}

// One evaluation with the settings' method: the record, adaptive evidence and refinement.
// `tail`, when given, gets the last stroboscopic states (full [x; v]) the verdict rests on, at
// most kTailPoints (empty for a motion that blew up or failed).
constexpr std::size_t kTailPoints = 64;
PointResult evaluate_record(const PointCase& point, const Vector& initial_state,
                            const PointSettings& s, PointObserver* observer,
                            std::vector<Vector>* tail = nullptr) {
  const GapStructure& structure = point.structure;
  const Index n = structure.dofs();
  std::string why;
  if (!s.is_valid(static_cast<int>(n), &why)) throw InputError("sweep point: " + why);
  if (initial_state.size() != 2 * n || !initial_state.allFinite()) {
    throw InputError(fmt::format("sweep point: the initial state has {} entries (finite: {}); "
                                 "expected {} finite ones",
                                 initial_state.size(), initial_state.allFinite(), 2 * n));
  }
  const double period = point.period;
  const MethodSettings method = s.method_for(period);
  std::unique_ptr<Integrator> integrator = make_integrator(structure, method);
  integrator->set_state(0.0, initial_state.head(n), initial_state.tail(n));
  SectionSampler sampler(*integrator, structure, period, s.section, method, s.steps_per_period);
  if (observer != nullptr) observer->started(*integrator, point);
  const auto steps_of = [&](int k) { return observer ? observer->steps_of_period(k) : nullptr; };

  PointResult result;
  result.columns = static_cast<int>(s.components.size());
  const bool hyperplane = !s.section.stroboscopic();
  if (!hyperplane) {
    result.poincare.reserve(static_cast<std::size_t>(s.recorded_periods) * s.components.size());
  }
  std::vector<Vector> points;
  points.reserve(static_cast<std::size_t>(s.recorded_periods));
  // The transient's stroboscopic states, kept for the search for a chaotic transient (small
  // structures only: a long chain keeps no more than its record).
  const bool keep_history = n <= PointSettings::kRefinedMasses;
  std::vector<Vector> history;
  if (keep_history) history.reserve(static_cast<std::size_t>(s.transient_periods));
  // What the integrator can do decides which estimates are possible, never its name.
  const bool lyapunov = s.lyapunov && s.recorded_periods >= 10;
  const bool tangent = lyapunov && integrator->has_tangent_map() &&
                       s.lyapunov_estimate != LyapunovEstimate::two_trajectories;
  const bool frame = tangent && s.lyapunov_estimate == LyapunovEstimate::tangent_frame;
  Matrix tangent_vector = initial_tangent(2 * n);
  // Per period: |J y| of the renormalised vector as a 1x1 Jacobian, or the whole Jacobian J.
  std::vector<Matrix> jacobians;
  const int total = s.transient_periods + s.recorded_periods;
  // A hyperplane's crossings are kept within the recorded periods, (t_first, t_last]: from the
  // end of the transient (the start when there is none) to the last stroboscopic time. The search
  // starts one period early, so that a grid point past the transient's last strobe time (an
  // interpolated phase) loses nothing.
  const double first_time =
      s.transient_periods == 0 ? 0.0 : sampler.strobe_time(s.transient_periods);
  const double last_time = sampler.strobe_time(total);
  int period_now = 0;  // the period being integrated
  const auto record_crossing = [&](const Crossing& c) {
    if (!(c.t > first_time) || c.t > last_time) return;
    const int k = c.t > sampler.strobe_time(period_now) ? period_now + 1 : period_now;
    for (int component : s.components) result.poincare.push_back(c.state[component]);
    result.section_times.push_back(c.t);
    if (observer != nullptr) observer->poincare_point(k, c.t, c.state);
  };
  // Records periods first..last (1-based from the start) as the record's points.
  const auto record = [&](int first, int last) {
    for (int k = first; k <= last; ++k) {
      period_now = k;
      StrobePoint strobe;
      if (frame) {
        Matrix jacobian = Matrix::Identity(2 * n, 2 * n);
        strobe = sampler.advance_to_strobe(k, &jacobian, steps_of(k));
        jacobians.push_back(std::move(jacobian));
      } else if (tangent) {
        strobe = sampler.advance_to_strobe(k, &tangent_vector, steps_of(k));
        const double norm = tangent_vector.norm();
        jacobians.push_back(Matrix::Constant(1, 1, norm));
        if (norm > 0.0 && std::isfinite(norm)) tangent_vector /= norm;
      } else {
        strobe = sampler.advance_to_strobe(k, nullptr, steps_of(k));
      }
      if (!hyperplane) {
        for (int c : s.components) result.poincare.push_back(strobe.state[c]);
        if (observer != nullptr) observer->poincare_point(k, strobe.t, strobe.state);
      }
      points.push_back(std::move(strobe.state));
    }
  };
  const int observable = s.observable >= 0 ? s.observable : static_cast<int>(n) - 1;
  // Classifies the record so far: λ1 over its Jacobians, K on the observable, the classifier.
  const auto classify = [&]() {
    const int recorded = static_cast<int>(points.size());
    result.lambda1 = result.lambda1_error = result.K = std::numeric_limits<double>::quiet_NaN();
    MotionEvidence evidence;
    // The first classified point is the strobe of period transient + 1, at
    // (transient + 1 + phase) T from the initial state: the time the growth test (rule 4a of the
    // classifier) measures the amplitude's power of t against.
    evidence.first_point_time = sampler.strobe_time(s.transient_periods + 1) / period;
    if (tangent) {
      LyapunovOptions l;
      const Averaging a = averaging(static_cast<long>(jacobians.size()), recorded);
      l.transient = a.transient;
      l.iterations = a.iterations;
      l.blocks = a.blocks;
      l.time_per_iteration = period;
      if (a.enough()) {
        const LyapunovResult spectrum = lyapunov_spectrum(jacobians, l);
        result.lambda1 = spectrum.largest();
        result.lambda1_error = spectrum.error[0];
      }
    } else if (lyapunov && s.lyapunov_estimate == LyapunovEstimate::two_trajectories) {
      two_trajectory_lyapunov(point, method, s.section.phase, points, recorded, result);
    }
    if (std::isfinite(result.lambda1) && std::isfinite(result.lambda1_error)) {
      evidence.lyapunov = result.lambda1;
      evidence.lyapunov_error = result.lambda1_error;
    } else {
      result.lambda1 = result.lambda1_error = std::numeric_limits<double>::quiet_NaN();
    }
    ZeroOneOptions zero_one;
    // K of the observable sampled every `stride` points.
    const auto K_every = [&](int stride) {
      std::vector<double> series;
      series.reserve(points.size() / static_cast<std::size_t>(stride) + 1);
      for (std::size_t i = points.size() % stride; i < points.size(); i += stride) {
        series.push_back(points[i][observable]);
      }
      return zero_one_test(series, zero_one).K;
    };
    if (recorded >= zero_one.min_samples) {
      result.K = K_every(1);
      evidence.zero_one_K = result.K;
    }
    ClassifierOptions options;
    options.fixed_point_is_equilibrium = false;  // a stroboscopic map: a fixed point is period-1
    options.observable_component = observable;
    options.zero_one_from_points = false;
    Classification verdict = classify_motion(points, evidence, options);
    // Banded chaos: a chaotic motion that visits k bands in turn (near a period-k orbit) has a
    // strong period-k component that holds K of the whole series near 0 over any practical
    // record (Gottwald and Melbourne, "The 0-1 test for chaos: a review", Lect. Notes Phys. 915,
    // 2016, on signals with a strong periodic component). An uncertain verdict with λ1 > 0 is
    // therefore tested again on every k-th point, k the period search's best near-return: the
    // band hopping is gone from that series, the chaos within a band is not, and a torus stays
    // regular. The larger K is the one reported.
    const int stride = verdict.period_search.best_k;
    if (verdict.regime == Regime::uncertain && stride > 1 && evidence.lyapunov &&
        *evidence.lyapunov - evidence.lyapunov_error > options.lyapunov_margin &&
        recorded / stride >= zero_one.min_samples) {
      const double banded = K_every(stride);
      if (banded > result.K) {
        result.K = banded;
        evidence.zero_one_K = banded;
        verdict = classify_motion(points, evidence, options);
      }
    }
    // The torus test of a record without a period (weighted_birkhoff.hpp), one more indicator
    // for rule 4 of the classifier: a smooth invariant curve or not.
    result.torus_digits = result.rotation = std::numeric_limits<double>::quiet_NaN();
    WeightedBirkhoffOptions torus;
    if (verdict.period_search.period == 0 && verdict.regime != Regime::unbounded &&
        recorded >= torus.min_points) {
      const WeightedBirkhoffResult w = weighted_birkhoff_test(as_rows(points), torus);
      result.torus_digits = w.digits;
      if (w.has_rotation) result.rotation = w.rotation_number;
      evidence.torus_digits = w.digits;
      verdict = classify_motion(points, evidence, options);
    }
    return verdict;
  };
  Classification c;
  try {
    for (int k = 1; k <= s.transient_periods; ++k) {
      period_now = k;
      if (hyperplane && k == s.transient_periods) sampler.record_crossings(record_crossing);
      StrobePoint strobe = sampler.advance_to_strobe(k, nullptr, steps_of(k));
      if (keep_history) history.push_back(std::move(strobe.state));
    }
    if (hyperplane && s.transient_periods == 0) sampler.record_crossings(record_crossing);
    record(s.transient_periods + 1, total);
    if (hyperplane) sampler.record_crossings(nullptr);
    c = classify();
    // Adaptive evidence: an uncertain record is carried on, each time doubling it, until the
    // indicators agree or the budget is spent (stroboscopic sections only: a hyperplane's
    // crossings are recorded over the periods set in advance).
    int end = total;
    while (c.regime == Regime::uncertain && !hyperplane && result.extra_periods < s.evidence_periods) {
      const int add = std::min(static_cast<int>(points.size()),
                               s.evidence_periods - result.extra_periods);
      record(end + 1, end + add);
      end += add;
      result.extra_periods += add;
      c = classify();
    }
    keep_last_points(s.kept_points, result);
    if (s.section.phase == 0.0) {
      result.final_state = points.back();
    } else {
      // On to the next whole period, where the loads are at phase 0 again.
      sampler.advance_to(static_cast<double>(end + 1) * period);
      result.final_state.resize(2 * n);
      result.final_state << integrator->position(), integrator->velocity();
    }
  } catch (const DivergenceError&) {
    result.regime = "unbounded";
    result.final_state.resize(0);
    result.lambda1 = result.lambda1_error = result.K = std::numeric_limits<double>::quiet_NaN();
    return result;
  } catch (const LcpError&) {
    result.regime = "failed";
    result.final_state.resize(0);
    result.lambda1 = result.lambda1_error = result.K = std::numeric_limits<double>::quiet_NaN();
    return result;
  } catch (const BudgetError&) {
    // The exact solver spent its work budget on one period (contacts too stiff for it): this
    // point failed, the study goes on.
    result.regime = "failed";
    result.final_state.resize(0);
    result.lambda1 = result.lambda1_error = result.K = std::numeric_limits<double>::quiet_NaN();
    return result;
  }
  result.regime = c.name();
  result.period = c.regime == Regime::periodic ? c.period : 0;
  result.disagreement = c.readings;
  if (c.regime == Regime::unbounded || !result.final_state.allFinite()) result.final_state.resize(0);
  refine_regime(point, s, points, result);
  // Transient chaos, on a motion that ends on a cycle: one the verdict is (the record's period,
  // or refinement's orbit the motion is on), or the one the record's search found while λ1 over
  // the whole record came out positive (rule 2 of the classifier: uncertain). In that last case
  // the record holds the end of a chaotic transient: when the motion then stayed on the cycle for
  // kChaoticTransient periods (and three cycles) the verdict is the period.
  const bool on_cycle = result.period > 0 && (c.period_search.period == result.period ||
                                              result.settle_periods == 0.0);
  const bool settled_in_record = c.regime == Regime::uncertain && c.period_search.period > 0 &&
                                 result.regime == "uncertain";
  const std::vector<Vector>* motion = &points;  // the states the tail comes from
  if (keep_history && (on_cycle || settled_in_record)) {
    const int k = on_cycle ? result.period : c.period_search.period;
    history.insert(history.end(), std::make_move_iterator(points.begin()),
                   std::make_move_iterator(points.end()));
    motion = &history;
    const Settling settling =
        find_chaotic_transient(point, method, s.section.phase, history, k, observable);
    const std::size_t stayed = history.size() - settling.settled;
    if (settling.chaotic && (on_cycle || stayed >= static_cast<std::size_t>(
                                                       std::max(kChaoticTransient, 3 * k)))) {
      result.chaotic_transient = static_cast<int>(settling.settled);
      result.regime = regime_name(Regime::periodic, k);
      result.period = k;
      result.disagreement.clear();
    }
  }
  if (tail != nullptr && result.final_state.size() != 0) {
    const std::size_t from = motion->size() - std::min(motion->size(), kTailPoints);
    tail->assign(motion->begin() + static_cast<std::ptrdiff_t>(from), motion->end());
  }
  if (observer != nullptr) observer->classified(c, result);
  return result;
}

bool needs_confirmation(const PointSettings& s, const PointResult& r) {
  switch (s.confirm) {
    case Confirmation::none:
      return false;
    case Confirmation::uncertain:
      return r.regime == "uncertain";
    case Confirmation::aperiodic:
      return r.regime == "uncertain" || r.regime == "chaotic" || r.regime == "quasi-periodic";
  }
  return false;
}

}  // namespace

std::string confirmation_name(Confirmation confirmation) {
  switch (confirmation) {
    case Confirmation::none:
      return "none";
    case Confirmation::uncertain:
      return "uncertain";
    case Confirmation::aperiodic:
      return "aperiodic";
  }
  return "none";
}

Confirmation parse_confirmation(const std::string& name) {
  for (Confirmation c : {Confirmation::none, Confirmation::uncertain, Confirmation::aperiodic}) {
    if (confirmation_name(c) == name) return c;
  }
  throw InputError(fmt::format("confirmation '{}': expected none, uncertain or aperiodic", name));
}

namespace {

// The record, then the exact solver's run when the verdict asks for it (PointSettings::confirm).
PointResult evaluate_confirmed(const PointCase& point, const Vector& initial_state,
                               const PointSettings& s, PointObserver* observer,
                               std::vector<Vector>* tail) {
  PointResult result = evaluate_record(point, initial_state, s, observer, tail);
  const Index n = point.structure.dofs();
  if (!needs_confirmation(s, result) || s.method.method == Method::exact ||
      n > PointSettings::kRefinedMasses) {
    return result;
  }
  PointSettings exact = s;
  exact.method = MethodSettings{Method::exact};
  exact.confirm = Confirmation::none;
  std::string why;
  if (!exact.method_for(point.period).is_valid(point.structure, &why)) return result;
  std::vector<Vector> exact_tail;
  PointResult confirmed =
      evaluate_record(point, initial_state, exact, observer, tail ? &exact_tail : nullptr);
  if (confirmed.regime == "failed") return result;
  confirmed.confirmed_by = "exact";
  if (tail != nullptr) *tail = std::move(exact_tail);
  return confirmed;
}

// A reproducible uniform number in [-1, 1] for start m, component c (splitmix64 of both; no
// generator state, so that every point and thread draws the same starts).
double start_coordinate(int m, Index c) {
  std::uint64_t z = 0x9e3779b97f4a7c15ULL * (static_cast<std::uint64_t>(m) * 1000003ULL +
                                            static_cast<std::uint64_t>(c) + 1ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return 2.0 * (static_cast<double>(z >> 11) * 0x1.0p-53) - 1.0;
}

}  // namespace

PointResult evaluate_point(const PointCase& point, const Vector& initial_state,
                           const PointSettings& s, PointObserver* observer) {
  if (s.starts <= 1) return evaluate_confirmed(point, initial_state, s, observer, nullptr);
  std::vector<Vector> tail;
  PointResult result = evaluate_confirmed(point, initial_state, s, observer, &tail);
  // Coexisting attractors: starts − 1 more initial states in boxes about the motion that grow
  // from 1.5 to 6 times the largest |x| and |v| of its tail (1 when it has none), so that basins
  // near the motion and far from it are both sampled; each is classified the same way and
  // matched to the attractors found so far (attractor_catalogue.hpp).
  const Index n = point.structure.dofs();
  double x_scale = 0.0, v_scale = 0.0;
  for (const Vector& y : tail) {
    x_scale = std::max(x_scale, y.head(n).cwiseAbs().maxCoeff());
    v_scale = std::max(v_scale, y.tail(n).cwiseAbs().maxCoeff());
  }
  x_scale = x_scale > 0.0 ? 1.5 * x_scale : 1.0;
  v_scale = v_scale > 0.0 ? 1.5 * v_scale : 1.0;
  AttractorCatalogue catalogue;
  const auto match = [&](const PointResult& r, const std::vector<Vector>& t) {
    if (r.regime == "failed") return;
    if (r.regime != "unbounded" && t.size() < static_cast<std::size_t>(std::max(2, r.period))) return;
    catalogue.match({r.regime, r.period, as_rows(t)});
  };
  match(result, tail);
  PointSettings other = s;
  other.starts = 1;
  other.components.clear();
  other.kept_points = 0;
  for (int m = 1; m < s.starts; ++m) {
    const double grow =
        s.starts > 2 ? 1.0 + 3.0 * static_cast<double>(m - 1) / static_cast<double>(s.starts - 2)
                     : 1.0;
    Vector start(2 * n);
    for (Index c = 0; c < 2 * n; ++c) {
      start[c] = grow * (c < n ? x_scale : v_scale) * start_coordinate(m, c);
    }
    std::vector<Vector> other_tail;
    const PointResult r = evaluate_confirmed(point, start, other, observer, &other_tail);
    match(r, other_tail);
  }
  result.attractors = static_cast<int>(catalogue.attractors().size());
  return result;
}

}  // namespace pwl::analysis
