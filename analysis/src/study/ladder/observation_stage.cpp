// Stage 5 of the ladder: what the verdict was seen over.
//
// A chaotic verdict is what a record saw, not a property proven for all time: a motion can wander
// chaotically for thousands of periods and then settle on a torus or a cycle (transient chaos).
// So the verdict says how long it looked (PointResult::observed_periods, set by the record stage)
// and whether it held over both halves of that record: the indicators (λ1, K, the torus test) are
// measured again on each half, and each reading (λ1 positive, zero or negative beyond its error;
// K chaotic, regular or between; the torus test a curve, broken or between) compared with the
// whole record's. PointResult::halves is "agree" when every reading of both halves is the whole's,
// else "differ:" and the indicators that changed ("differ:lambda1+K"). A quasi-periodic verdict
// gets the same check (a torus stays a torus over both halves).
//
// A long period (more than kDrawnPeriods, what the maps colour apart) or a period found at the
// rotation number's denominator gets its rotation as p/q (rotation_fraction.hpp), measured by the
// weighted Birkhoff average on the record (weighted_birkhoff.hpp): a period-q orbit that turns p
// times about its centre before it closes.
#include <fmt/format.h>

#include <cmath>
#include <string>

#include "study/ladder/stages.hpp"
#include "pwl/analysis/rotation_fraction.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"

namespace pwl::analysis::ladder {

namespace {

constexpr int kDrawnPeriods = 8;

// Each indicator's reading, as the classifier's rules name them.
struct Readings {
  int lambda1 = 0;  // +1 positive, 0 zero, -1 negative, 2 not measured
  int K = 0;        // +1 chaotic, 0 between, -1 regular, 2 not measured
  int torus = 0;    // +1 curve, 0 between, -1 broken, 2 not measured
};

Readings readings_of(const PointResult& r) {
  const ClassifierOptions rules;
  Readings out;
  if (!std::isfinite(r.lambda1)) {
    out.lambda1 = 2;
  } else if (r.lambda1 - r.lambda1_error > rules.lyapunov_margin) {
    out.lambda1 = 1;
  } else if (r.lambda1 + r.lambda1_error < -rules.lyapunov_margin) {
    out.lambda1 = -1;
  }
  if (!std::isfinite(r.K)) {
    out.K = 2;
  } else if (r.K > rules.chaotic_K) {
    out.K = 1;
  } else if (r.K < rules.regular_K) {
    out.K = -1;
  }
  if (!std::isfinite(r.torus_digits)) {
    out.torus = 2;
  } else if (r.torus_digits >= rules.curve_digits) {
    out.torus = 1;
  } else if (r.torus_digits < rules.broken_digits) {
    out.torus = -1;
  }
  return out;
}

// "agree" or "differ:..." of the two halves against the whole record.
std::string compare_halves(PointRun& run) {
  const std::size_t N = run.points.size();
  const std::size_t half = N / 2;
  const PointSettings& s = run.settings;
  const MethodSettings method = s.method_for(run.point.period);
  const bool tangent = run.jacobians.size() == N;
  const RecordIndicators indicators{run.point, s, method, tangent};
  const Readings whole = readings_of(run.result);
  std::string differ;
  const auto note = [&](const char* name) {
    if (differ.find(name) != std::string::npos) return;
    if (!differ.empty()) differ.push_back('+');
    differ.append(name);
  };
  for (int h = 0; h < 2; ++h) {
    const std::size_t from = h == 0 ? 0 : half, to = h == 0 ? half : N;
    const std::vector<Vector> points(run.points.begin() + static_cast<std::ptrdiff_t>(from),
                                     run.points.begin() + static_cast<std::ptrdiff_t>(to));
    std::vector<Matrix> jacobians;
    if (tangent) {
      jacobians.assign(run.jacobians.begin() + static_cast<std::ptrdiff_t>(from),
                       run.jacobians.begin() + static_cast<std::ptrdiff_t>(to));
    }
    PointResult scratch;
    indicator_stage(indicators, points, jacobians,
                    run.first_point_time + static_cast<double>(from), scratch);
    const Readings r = readings_of(scratch);
    if (r.lambda1 != whole.lambda1) note("lambda1");
    if (r.K != whole.K) note("K");
    if (r.torus != whole.torus) note("torus");
  }
  if (differ.empty()) return "agree";
  differ.insert(0, "differ:");
  return differ;
}

}  // namespace

void observation_stage(PointRun& run) {
  PointResult& result = run.result;
  if (!run.classified || !run.settings.section.stroboscopic()) return;
  const std::size_t N = run.points.size();
  if ((result.regime == "chaotic" || result.regime == "quasi-periodic") &&
      N >= 2 * static_cast<std::size_t>(WeightedBirkhoffOptions{}.min_points)) {
    result.halves = compare_halves(run);
  }
  const int k = result.period;
  const bool locked = k > 0 && locked_denominator(result.rotation, kLockedPeriodLimit) == k;
  if (k > kDrawnPeriods || locked) {
    double rho = result.rotation;
    if (!std::isfinite(rho) && N >= static_cast<std::size_t>(WeightedBirkhoffOptions{}.min_points)) {
      const WeightedBirkhoffResult w = weighted_birkhoff_test(as_rows(run.points));
      if (w.has_rotation) rho = w.rotation_number;
    }
    result.rotation_pq = rotation_fraction(rho, k);
  }
}

}  // namespace pwl::analysis::ladder
