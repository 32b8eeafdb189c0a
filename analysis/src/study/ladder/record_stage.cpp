// Stage 1 of the ladder: the record. The point is integrated from its initial state past its
// transient, its stroboscopic states are recorded (and the section's points kept), and the record
// is classified by indicator_stage. Adaptive evidence (PointSettings::evidence_periods): a record
// the classifier calls uncertain is carried on, each time doubling it, until the indicators agree
// or the budget is spent.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "study/ladder/stages.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/section_sampler.hpp"

namespace pwl::analysis::ladder {

Matrix initial_tangent(Index size) {
  // A fixed unit vector with every component non-zero, so that it has a part along the most
  // expanding direction of any orbit (a random frame would do as well; a fixed one keeps every
  // point reproducible without a seed).
  Matrix y(size, 1);
  for (Index i = 0; i < size; ++i) y(i, 0) = 1.0 + 0.1 * static_cast<double>(i);
  y /= y.norm();
  return y;
}

Averaging averaging(long count, int recorded) {
  Averaging a;
  a.transient = std::min(50, recorded / 5);
  a.iterations = count - a.transient;
  a.blocks = static_cast<int>(std::min<long>(10, a.iterations));
  return a;
}

Matrix as_rows(const std::vector<Vector>& states) {
  Matrix m(static_cast<Index>(states.size()), states.empty() ? 0 : states.front().size());
  for (std::size_t i = 0; i < states.size(); ++i) m.row(static_cast<Index>(i)) = states[i];
  return m;
}

namespace {

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

// A motion that ended without a verdict of its record: "unbounded" or "failed".
void ended(PointRun& run, const char* regime) {
  run.result.regime = regime;
  run.result.final_state.resize(0);
  run.result.lambda1 = run.result.lambda1_error = run.result.K =
      std::numeric_limits<double>::quiet_NaN();
  run.points.clear();
  run.jacobians.clear();
  run.classified = false;
}

}  // namespace

void record_stage(PointRun& run) {
  const PointSettings& s = run.settings;
  const PointCase& point = run.point;
  const GapStructure& structure = point.structure;
  const Index n = structure.dofs();
  std::string why;
  if (!s.is_valid(static_cast<int>(n), &why)) throw InputError("sweep point: " + why);
  const Vector& initial_state = run.initial_state;
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
  PointObserver* observer = run.observer;
  if (observer != nullptr) observer->started(*integrator, point);
  const auto steps_of = [&](int k) {
    if (observer == nullptr) return StepObserver();
    observer->checkpoint();
    return observer->steps_of_period(k);
  };

  PointResult& result = run.result;
  result = PointResult{};
  result.decided_by = std::string(method_traits(method.method).name);
  result.columns = static_cast<int>(s.components.size());
  const bool hyperplane = !s.section.stroboscopic();
  if (!hyperplane) {
    result.poincare.reserve(static_cast<std::size_t>(s.recorded_periods) * s.components.size());
  }
  std::vector<Vector>& points = run.points;
  points.clear();
  points.reserve(static_cast<std::size_t>(s.recorded_periods));
  // The transient's stroboscopic states, kept for the search for a chaotic transient (small
  // structures only: a long chain keeps no more than its record).
  const bool keep_history = n <= PointSettings::kRefinedMasses;
  std::vector<Vector>& history = run.history;
  history.clear();
  if (keep_history) history.reserve(static_cast<std::size_t>(s.transient_periods));
  // What the integrator can do decides which estimates are possible, never its name.
  const bool lyapunov = s.lyapunov && s.recorded_periods >= 10;
  const bool tangent = lyapunov && integrator->has_tangent_map() &&
                       s.lyapunov_estimate != LyapunovEstimate::two_trajectories;
  const bool frame = tangent && s.lyapunov_estimate == LyapunovEstimate::tangent_frame;
  Matrix tangent_vector = initial_tangent(2 * n);
  // Per period: |J y| of the renormalised vector as a 1x1 Jacobian, or the whole Jacobian J.
  std::vector<Matrix>& jacobians = run.jacobians;
  jacobians.clear();
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
  // The first classified point is the strobe of period transient + 1, at
  // (transient + 1 + phase) T from the initial state: the time the growth test (rule 4a of the
  // classifier) measures the amplitude's power of t against.
  const double first_point_time = sampler.strobe_time(s.transient_periods + 1) / period;
  run.first_point_time = first_point_time;
  const RecordIndicators indicators{point, s, method, tangent};
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
    c = indicator_stage(indicators, points, jacobians, first_point_time, result);
    // Adaptive evidence: an uncertain record is carried on, each time doubling it, until the
    // indicators agree or the budget is spent (stroboscopic sections only: a hyperplane's
    // crossings are recorded over the periods set in advance).
    int end = total;
    while (c.regime == Regime::uncertain && !hyperplane &&
           result.extra_periods < s.evidence_periods) {
      const int add = std::min(static_cast<int>(points.size()),
                               s.evidence_periods - result.extra_periods);
      record(end + 1, end + add);
      end += add;
      result.extra_periods += add;
      c = indicator_stage(indicators, points, jacobians, first_point_time, result);
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
    ended(run, "unbounded");
    return;
  } catch (const LcpError&) {
    ended(run, "failed");
    return;
  } catch (const BudgetError&) {
    // The exact solver spent its work budget on one period (contacts too stiff for it): this
    // point failed, the study goes on.
    ended(run, "failed");
    return;
  }
  run.classification = c;
  run.classified = true;
  result.observed_periods = static_cast<int>(points.size());
  result.regime = c.name();
  result.period = c.regime == Regime::periodic ? c.period : 0;
  result.record_period = c.period_search.period;
  result.disagreement = c.readings;
  if (c.regime == Regime::unbounded || !result.final_state.allFinite()) result.final_state.resize(0);
}

}  // namespace pwl::analysis::ladder
