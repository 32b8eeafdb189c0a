#include "pwl/study/sweep_point.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_integrator.hpp"
#include "pwl/integrators/reference_integrator.hpp"

namespace pwl::analysis {

std::string parameter_name(SweepParameter parameter) {
  switch (parameter) {
    case SweepParameter::theta: return "theta";
    case SweepParameter::alpha: return "alpha";
    case SweepParameter::zeta: return "zeta";
    case SweepParameter::gap: return "gap";
    case SweepParameter::amplitude: return "amplitude";
  }
  return "theta";
}

SweepParameter parse_sweep_parameter(const std::string& name) {
  if (name == "theta") return SweepParameter::theta;
  if (name == "alpha") return SweepParameter::alpha;
  if (name == "zeta") return SweepParameter::zeta;
  if (name == "gap" || name == "delta") return SweepParameter::gap;
  if (name == "amplitude") return SweepParameter::amplitude;
  throw InputError(fmt::format(
      "parameter = \"{}\" is not known; use theta, alpha, zeta, gap (or delta) or amplitude", name));
}

NondimensionalChain with_parameter(const NondimensionalChain& base, SweepParameter parameter,
                                   double value) {
  NondimensionalChain c = base;
  switch (parameter) {
    case SweepParameter::theta: c.theta = value; break;
    case SweepParameter::alpha: c.alpha = {value}; break;
    case SweepParameter::zeta: c.zeta = value; break;
    case SweepParameter::gap: c.gap = {value}; break;
    case SweepParameter::amplitude:
      for (double& q : c.amplitude) q *= value;
      break;
  }
  return c;
}

bool PointSettings::is_valid(int masses, std::string* why) const {
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
  if (steps_per_period < 1) {
    *why = fmt::format("steps per period = {} must be >= 1", steps_per_period);
    return false;
  }
  for (int c : components) {
    if (c < 0 || c >= 2 * masses) {
      *why = fmt::format("component {} is out of range: the state has {} components (0..{})", c,
                         2 * masses, 2 * masses - 1);
      return false;
    }
  }
  if (observable < -1 || observable >= 2 * masses) {
    *why = fmt::format("observable = {} is out of range (-1 or 0..{})", observable, 2 * masses - 1);
    return false;
  }
  if (method != "pim" && method != "dopri5") {
    *why = fmt::format("method = \"{}\" must be \"pim\" or \"dopri5\"", method);
    return false;
  }
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    *why = fmt::format("tolerance = {} must be positive", tolerance);
    return false;
  }
  return true;
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

}  // namespace

PointResult evaluate_point(const NondimensionalChain& chain, const Vector& initial_state,
                           const PointSettings& s) {
  std::string why;
  if (!s.is_valid(chain.masses, &why)) throw InputError("sweep point: " + why);
  const GapStructure structure = make_chain(chain);
  const Index n = structure.dofs();
  if (initial_state.size() != 2 * n || !initial_state.allFinite()) {
    throw InputError(fmt::format("sweep point: the initial state has {} entries (finite: {}); "
                                 "expected {} finite ones",
                                 initial_state.size(), initial_state.allFinite(), 2 * n));
  }
  const double period = chain.period();
  std::unique_ptr<Integrator> integrator;
  const bool pim = s.method == "pim";
  if (pim) {
    PimOptions p;
    p.step = period / s.steps_per_period;
    integrator = make_pim_integrator(structure, p);
  } else {
    ReferenceOptions r;
    r.method = RungeKuttaMethod::dopri5;
    r.relative_tolerance = r.absolute_tolerance = s.tolerance;
    r.locate_kinks = true;
    r.max_step = period / 8;
    integrator = make_reference_integrator(structure, r);
  }
  integrator->set_state(0.0, initial_state.head(n), initial_state.tail(n));

  PointResult result;
  result.columns = static_cast<int>(s.components.size());
  result.poincare.reserve(static_cast<std::size_t>(s.recorded_periods) * s.components.size());
  std::vector<Vector> points;
  points.reserve(static_cast<std::size_t>(s.recorded_periods));
  const bool with_lyapunov = pim && s.lyapunov && s.recorded_periods >= 10;
  Matrix tangent = initial_tangent(2 * n);
  std::vector<Matrix> growth;  // |J y| per period, as 1x1 Jacobians of the renormalised vector
  try {
    for (int k = 1; k <= s.transient_periods; ++k) integrator->advance_to(k * period);
    const int total = s.transient_periods + s.recorded_periods;
    for (int k = s.transient_periods + 1; k <= total; ++k) {
      if (with_lyapunov) {
        integrator->advance_with_tangent(k * period, tangent);
        const double norm = tangent.norm();
        growth.push_back(Matrix::Constant(1, 1, norm));
        if (norm > 0.0 && std::isfinite(norm)) tangent /= norm;
      } else {
        integrator->advance_to(k * period);
      }
      Vector state(2 * n);
      state << integrator->position(), integrator->velocity();
      for (int c : s.components) result.poincare.push_back(state[c]);
      points.push_back(std::move(state));
    }
  } catch (const DivergenceError&) {
    result.regime = "unbounded";
    return result;
  } catch (const LcpError&) {
    result.regime = "failed";
    return result;
  }
  result.final_state = points.back();

  MotionEvidence evidence;
  if (with_lyapunov) {
    LyapunovOptions l;
    l.transient = std::min(50, s.recorded_periods / 5);
    l.iterations = static_cast<long>(growth.size()) - l.transient;
    l.blocks = static_cast<int>(std::min<long>(10, l.iterations));
    if (l.blocks >= 2) {
      const LyapunovResult lyapunov = lyapunov_spectrum(growth, l);
      if (std::isfinite(lyapunov.largest()) && std::isfinite(lyapunov.error[0])) {
        result.lambda1 = lyapunov.largest();
        result.lambda1_error = lyapunov.error[0];
        evidence.lyapunov = result.lambda1;
        evidence.lyapunov_error = result.lambda1_error;
      }
    }
  }
  const int observable = s.observable >= 0 ? s.observable : static_cast<int>(n) - 1;
  ZeroOneOptions zero_one;
  if (static_cast<int>(points.size()) >= zero_one.min_samples) {
    std::vector<double> series;
    series.reserve(points.size());
    for (const Vector& p : points) series.push_back(p[observable]);
    result.K = zero_one_test(series, zero_one).K;
    evidence.zero_one_K = result.K;
  }
  ClassifierOptions options;
  options.fixed_point_is_equilibrium = false;  // a stroboscopic map: a fixed point is period-1
  options.observable_component = observable;
  options.zero_one_from_points = false;
  const Classification c = classify_motion(points, evidence, options);
  result.regime = c.name();
  result.period = c.regime == Regime::periodic ? c.period : 0;
  if (c.regime == Regime::unbounded || !result.final_state.allFinite()) result.final_state.resize(0);
  return result;
}

}  // namespace pwl::analysis
