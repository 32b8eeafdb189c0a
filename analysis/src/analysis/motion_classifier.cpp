#include "pwl/analysis/motion_classifier.hpp"

#include <fmt/format.h>

#include <cmath>

#include "analysis/point_checks.hpp"
#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

enum class Sign { positive, zero, negative, inconclusive, unknown };
enum class ZeroOne { chaotic, regular, between, unknown };

Sign read_lyapunov(const Classification& c, double margin) {
  if (!c.lyapunov) return Sign::unknown;
  const double l = *c.lyapunov;
  const double e = c.lyapunov_error;
  if (l - e > margin) return Sign::positive;
  if (l + e < -margin) return Sign::negative;
  if (std::abs(l) + e <= margin) return Sign::zero;
  return Sign::inconclusive;
}

ZeroOne read_zero_one(const std::optional<double>& K, const ClassifierOptions& options) {
  if (!K) return ZeroOne::unknown;
  if (*K > options.chaotic_K) return ZeroOne::chaotic;
  if (*K < options.regular_K) return ZeroOne::regular;
  return ZeroOne::between;
}

std::string describe(const Classification& c) {
  std::string text;
  if (c.lyapunov) {
    text += fmt::format("λ1 = {:.4g} ± {:.2g}", *c.lyapunov, c.lyapunov_error);
  } else {
    text += "λ1 unknown";
  }
  if (c.zero_one_K) {
    text += fmt::format(", K = {:.3f} ({})", *c.zero_one_K, c.zero_one_source);
  } else {
    text += ", K unknown";
  }
  return text;
}

// Rule 1: the first coordinate that is not finite or beyond the bound, if any.
bool find_unbounded(const std::vector<Vector>& points, const std::vector<double>& observable,
                    double bound, std::string* where) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (Index j = 0; j < points[i].size(); ++j) {
      const double v = points[i][j];
      if (!std::isfinite(v) || std::abs(v) > bound) {
        *where = fmt::format("points[{}][{}] = {} (bound {})", i, j, v, bound);
        return true;
      }
    }
  }
  for (std::size_t i = 0; i < observable.size(); ++i) {
    const double v = observable[i];
    if (!std::isfinite(v) || std::abs(v) > bound) {
      *where = fmt::format("observable[{}] = {} (bound {})", i, v, bound);
      return true;
    }
  }
  return false;
}

void check_evidence(const MotionEvidence& evidence) {
  if (evidence.lyapunov && !std::isfinite(*evidence.lyapunov)) {
    throw InputError(fmt::format("MotionEvidence.lyapunov = {} is not finite", *evidence.lyapunov));
  }
  if (!(evidence.lyapunov_error >= 0.0) || !std::isfinite(evidence.lyapunov_error)) {
    throw InputError(fmt::format("MotionEvidence.lyapunov_error = {} must be finite and >= 0",
                                 evidence.lyapunov_error));
  }
  if (evidence.zero_one_K &&
      !(std::isfinite(*evidence.zero_one_K) && std::abs(*evidence.zero_one_K) <= 1.0)) {
    throw InputError(fmt::format("MotionEvidence.zero_one_K = {} must be finite and in [-1, 1]",
                                 *evidence.zero_one_K));
  }
}

}  // namespace

std::string regime_name(Regime regime, int period) {
  switch (regime) {
    case Regime::equilibrium:
      return "equilibrium";
    case Regime::periodic:
      return fmt::format("period-{}", period);
    case Regime::quasi_periodic:
      return "quasi-periodic";
    case Regime::chaotic:
      return "chaotic";
    case Regime::unbounded:
      return "unbounded";
    case Regime::uncertain:
      return "uncertain";
  }
  return "uncertain";
}

bool ClassifierOptions::is_valid(std::string* why) const {
  if (!period.is_valid(why)) return false;
  if (!zero_one.is_valid(why)) return false;
  if (!(lyapunov_margin > 0.0) || !std::isfinite(lyapunov_margin)) {
    return fail(why, fmt::format("ClassifierOptions.lyapunov_margin = {} must be finite and > 0",
                                 lyapunov_margin));
  }
  if (!(regular_K > 0.0 && regular_K <= chaotic_K && chaotic_K < 1.0)) {
    return fail(why, fmt::format("ClassifierOptions.regular_K = {}, chaotic_K = {}: need "
                                 "0 < regular_K <= chaotic_K < 1",
                                 regular_K, chaotic_K));
  }
  if (!(divergence_bound > 0.0)) {
    return fail(why, fmt::format("ClassifierOptions.divergence_bound = {} must be > 0",
                                 divergence_bound));
  }
  if (observable_component < 0) {
    return fail(why, fmt::format("ClassifierOptions.observable_component = {} must be >= 0",
                                 observable_component));
  }
  return true;
}

Classification classify_motion(const std::vector<Vector>& points, const MotionEvidence& evidence,
                               const ClassifierOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  detail::check_points(points, false);  // non-finite points are evidence: unbounded motion
  const Index dim = points.front().size();
  check_evidence(evidence);

  Classification c;
  c.lyapunov = evidence.lyapunov;
  c.lyapunov_error = evidence.lyapunov_error;
  if (evidence.zero_one_K) {
    c.zero_one_K = evidence.zero_one_K;
    c.zero_one_source = "given";
  }

  // Rule 1.
  std::string where;
  if (find_unbounded(points, evidence.observable, options.divergence_bound, &where)) {
    c.regime = Regime::unbounded;
    c.reason = "unbounded: " + where;
    return c;
  }

  // Rule 2.
  c.period_search = detect_period(points, options.period);
  const Sign lyapunov = read_lyapunov(c, options.lyapunov_margin);
  if (c.period_search.period > 0) {
    const int k = c.period_search.period;
    const std::string found =
        fmt::format("period {} repeats over {} cycles (mismatch {:.2g} of tolerance {:.2g})", k,
                    options.period.cycles, c.period_search.mismatch, options.period.tolerance);
    if (lyapunov == Sign::positive) {
      c.regime = Regime::uncertain;
      c.reason = fmt::format("uncertain: {} but λ1 = {:.4g} ± {:.2g} is clearly positive", found,
                             *c.lyapunov, c.lyapunov_error);
      return c;
    }
    if (k == 1 && options.fixed_point_is_equilibrium) {
      c.regime = Regime::equilibrium;
      c.period = 1;
      c.reason = "equilibrium: fixed point, " + found;
      return c;
    }
    c.regime = Regime::periodic;
    c.period = k;
    c.reason = regime_name(Regime::periodic, k) + ": " + found;
    return c;
  }

  // Rule 3.
  if (c.period_search.points_used == 0) {
    c.regime = Regime::uncertain;
    c.reason = fmt::format("uncertain: {} points are too few to test any period (need {})",
                           points.size(), options.period.cycles + 1);
    return c;
  }

  // Rule 4: bring in the 0-1 test.
  if (!c.zero_one_K) {
    if (!evidence.observable.empty()) {
      c.zero_one_K = zero_one_test(evidence.observable, options.zero_one).K;
      c.zero_one_source = "observable";
    } else if (options.zero_one_from_points &&
               points.size() >= static_cast<std::size_t>(options.zero_one.min_samples)) {
      if (options.observable_component >= dim) {
        throw InputError(fmt::format("ClassifierOptions.observable_component = {} is out of "
                                     "range for points of dimension {}",
                                     options.observable_component, dim));
      }
      std::vector<double> series(points.size());
      for (std::size_t i = 0; i < points.size(); ++i) {
        series[i] = points[i][options.observable_component];
      }
      c.zero_one_K = zero_one_test(series, options.zero_one).K;
      c.zero_one_source = "points";
    }
  }
  const ZeroOne zero_one = read_zero_one(c.zero_one_K, options);
  const std::string numbers =
      fmt::format("no period up to {} (best k = {}, mismatch {:.2g}); {}", options.period.k_max,
                  c.period_search.best_k, c.period_search.mismatch, describe(c));
  const bool lenient = !options.require_all_indicators;

  if ((lyapunov == Sign::positive && zero_one == ZeroOne::chaotic) ||
      (lenient && lyapunov == Sign::positive && zero_one == ZeroOne::unknown) ||
      (lenient && lyapunov == Sign::unknown && zero_one == ZeroOne::chaotic)) {
    c.regime = Regime::chaotic;
    c.reason = "chaotic: " + numbers;
    return c;
  }
  if ((lyapunov == Sign::zero && zero_one == ZeroOne::regular) ||
      (lenient && lyapunov == Sign::zero && zero_one == ZeroOne::unknown) ||
      (lenient && lyapunov == Sign::unknown && zero_one == ZeroOne::regular)) {
    c.regime = Regime::quasi_periodic;
    c.reason = "quasi-periodic: " + numbers;
    return c;
  }
  c.regime = Regime::uncertain;
  if (lyapunov == Sign::negative && zero_one != ZeroOne::chaotic) {
    c.reason = "uncertain: λ1 < 0 but " + numbers +
               ": a period beyond k_max, or a transient not yet over";
  } else if (lyapunov == Sign::unknown && zero_one == ZeroOne::unknown) {
    c.reason = "uncertain: " + numbers + ": no indicator beyond the period search";
  } else {
    c.reason = "uncertain: the indicators disagree or are inconclusive: " + numbers;
  }
  return c;
}

Classification classify_motion(const std::vector<double>& values, const MotionEvidence& evidence,
                               const ClassifierOptions& options) {
  std::vector<Vector> points;
  points.reserve(values.size());
  for (double v : values) points.push_back(Vector::Constant(1, v));
  return classify_motion(points, evidence, options);
}

}  // namespace pwl::analysis
