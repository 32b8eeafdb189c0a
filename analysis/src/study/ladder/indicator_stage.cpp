// Stage 2 of the ladder: the indicators of a record and the classifier's verdict on them. λ1 from
// the tangent growth the record stage collected (or by two nearby trajectories), K of the 0-1 test
// on the observable, K again on every k-th point for banded chaos, and the torus test of a record
// without a period (motion_classifier.hpp says how they combine).
#include <cmath>
#include <limits>
#include <memory>

#include "study/ladder/stages.hpp"
#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/errors.hpp"

namespace pwl::analysis::ladder {

namespace {

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

}  // namespace

int observable_of(const PointSettings& settings, Index dofs) {
  return settings.observable >= 0 ? settings.observable : static_cast<int>(dofs) - 1;
}

Classification indicator_stage(const RecordIndicators& record, const std::vector<Vector>& points,
                               const std::vector<Matrix>& jacobians, double first_point_time,
                               PointResult& result) {
  const PointSettings& s = record.settings;
  const double period = record.point.period;
  const int observable = observable_of(s, record.point.structure.dofs());
  const int recorded = static_cast<int>(points.size());
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  result.lambda1 = result.lambda1_error = result.K = kNaN;
  MotionEvidence evidence;
  evidence.first_point_time = first_point_time;
  const bool lyapunov = s.lyapunov && s.recorded_periods >= 10;
  if (record.tangent) {
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
    two_trajectory_lyapunov(record.point, record.method, s.section.phase, points, recorded, result);
  }
  if (std::isfinite(result.lambda1) && std::isfinite(result.lambda1_error)) {
    evidence.lyapunov = result.lambda1;
    evidence.lyapunov_error = result.lambda1_error;
  } else {
    result.lambda1 = result.lambda1_error = kNaN;
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
  // strong period-k component that holds K of the whole series near 0 over any practical record
  // (Gottwald and Melbourne, "The 0-1 test for chaos: a review", Lect. Notes Phys. 915, 2016, on
  // signals with a strong periodic component). An uncertain verdict with λ1 > 0 is therefore
  // tested again on every k-th point, k the period search's best near-return: the band hopping is
  // gone from that series, the chaos within a band is not, and a torus stays regular. The larger
  // K is the one reported.
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
  // The torus test of a record without a period (weighted_birkhoff.hpp), one more indicator for
  // rule 4 of the classifier: a smooth invariant curve or not.
  result.torus_digits = result.rotation = kNaN;
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
}

}  // namespace pwl::analysis::ladder
