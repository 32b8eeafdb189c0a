// Stage 4 of the ladder: transient chaos, on a motion that ends on a cycle.
//
// The cycle is the verdict's (the record's period, or Newton's orbit the motion is on), or the one
// the record's search found while λ1 over the whole record came out positive (rule 2 of the
// classifier: uncertain). In that last case the record holds the end of a chaotic transient: when
// the motion then stayed on the cycle for kChaoticTransient periods (and three cycles) the verdict
// is the period.
//
// How the transient is found. `states` are the stroboscopic states from period 1 to the end, whose
// last k repeat. The motion settled at period s + 1, s the last index farther from the cycle (the
// point of the cycle at the same phase) than kSettledDistance of the region the whole motion
// visited (the diagonal of its bounding box): before that it was far from the orbit. When
// s >= kChaoticTransient periods, the finite-time λ1 of that stretch is measured along the motion
// itself (a companion started kSeparation off each stored state for one period, its growth the
// stretch's one-period factor, averaged as the record's λ1 is: lyapunov.hpp), K on the observable
// (also on every k-th point, as for banded chaos) and the torus test on the states. A stretch
// whose λ1 is clearly positive (λ1 − error > the classifier's margin, 0.005 per period), whose K is
// not regular (>= 0.2) and whose states are not on a smooth curve (torus digits < 5, when it has
// 200 points or more) is a chaotic transient, and PointResult::chaotic_transient = s. Not K > 0.8:
// a chaotic transient that ends on a period-k orbit has hovered near it, a banded chaos that holds
// K down (measured on the (θ, α) map, α = 9, θ = 1.718: 3774 periods with λ1 = 0.059 ± 0.005,
// K = 0.76, 3.0 digits, then a period-7 orbit). A companion along the stored states, not a second
// trajectory from the start: chaos amplifies the rounding of a re-run, whose own transient would
// end elsewhere. (Transient chaos: T. Tél and Y.-C. Lai, Transient Chaos, Springer 2011, ch. 1.)
#include <algorithm>
#include <cmath>
#include <iterator>

#include "study/ladder/stages.hpp"
#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/errors.hpp"

namespace pwl::analysis::ladder {

namespace {

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

}  // namespace

void transient_stage(PointRun& run) {
  PointResult& result = run.result;
  const Classification& c = run.classification;
  const PointSettings& s = run.settings;
  const Index n = run.point.structure.dofs();
  const bool keep_history = n <= PointSettings::kRefinedMasses;
  const std::vector<Vector>* motion = &run.points;  // the states the tail comes from
  if (run.classified && keep_history) {
    const bool on_cycle = result.period > 0 && (c.period_search.period == result.period ||
                                                result.settle_periods == 0.0);
    const bool settled_in_record = c.regime == Regime::uncertain && c.period_search.period > 0 &&
                                   result.regime == "uncertain";
    if (on_cycle || settled_in_record) {
      const int k = on_cycle ? result.period : c.period_search.period;
      std::vector<Vector>& history = run.history;
      history.insert(history.end(), run.points.begin(), run.points.end());
      motion = &history;
      const Settling settling =
          find_chaotic_transient(run.point, s.method_for(run.point.period), s.section.phase,
                                 history, k, observable_of(s, n));
      const std::size_t stayed = history.size() - settling.settled;
      if (settling.chaotic && (on_cycle || stayed >= static_cast<std::size_t>(
                                                         std::max(kChaoticTransient, 3 * k)))) {
        result.chaotic_transient = static_cast<int>(settling.settled);
        result.regime = regime_name(Regime::periodic, k);
        result.period = k;
        result.disagreement.clear();
      }
    }
  }
  run.tail.clear();
  if (result.final_state.size() != 0 && !motion->empty()) {
    const std::size_t from = motion->size() - std::min(motion->size(), kTailPoints);
    run.tail.assign(motion->begin() + static_cast<std::ptrdiff_t>(from), motion->end());
  }
}

}  // namespace pwl::analysis::ladder
