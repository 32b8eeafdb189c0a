#include "pwl/analysis/motion_classifier.hpp"

#include <fmt/format.h>

#include <algorithm>
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
enum class Torus { curve, broken, between, unknown };

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

Torus read_torus(const std::optional<double>& digits, const ClassifierOptions& options) {
  if (!digits) return Torus::unknown;
  if (*digits >= options.curve_digits) return Torus::curve;
  if (*digits < options.broken_digits) return Torus::broken;
  return Torus::between;
}

const char* sign_word(Sign s) {
  switch (s) {
    case Sign::positive: return "positive";
    case Sign::zero: return "zero";
    case Sign::negative: return "negative";
    case Sign::inconclusive: return "inconclusive";
    case Sign::unknown: return "unknown";
  }
  return "unknown";
}

const char* zero_one_word(ZeroOne z) {
  switch (z) {
    case ZeroOne::chaotic: return "chaotic";
    case ZeroOne::regular: return "regular";
    case ZeroOne::between: return "between";
    case ZeroOne::unknown: return "unknown";
  }
  return "unknown";
}

const char* torus_word(Torus t) {
  switch (t) {
    case Torus::curve: return "curve";
    case Torus::broken: return "broken";
    case Torus::between: return "between";
    case Torus::unknown: return "unknown";
  }
  return "unknown";
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
  if (c.torus_digits) text += fmt::format(", torus test {:.2f} digits", *c.torus_digits);
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

// Least-squares slope of y on x.
double slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t from,
             std::size_t to) {
  const double n = static_cast<double>(to - from);
  double mx = 0.0, my = 0.0;
  for (std::size_t i = from; i < to; ++i) mx += x[i], my += y[i];
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = from; i < to; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

// What rule 4a measured: the envelope of the amplitude block by block and its power of t.
struct Growth {
  bool ran = false;            // enough points to test
  bool growing = false;        // the verdict
  double exponent = 0.0;       // over the whole record
  double late_exponent = 0.0;  // over its second half
  double rise = 0.0;           // log(E_last / E_first)
  bool monotone = false;       // the envelope rises in every block
  int blocks = 0;
  double first = 0.0, last = 0.0;            // E_0 and E_last
  double first_time = 0.0, last_time = 0.0;  // their times
};

// Rule 4a (see the header): the envelope of |p_i| over equal blocks, its rise and its power of t.
Growth measure_growth(const std::vector<Vector>& points, double first_point_time,
                      const ClassifierOptions& options) {
  Growth g;
  const std::size_t n = points.size();
  const auto blocks = static_cast<std::size_t>(options.growth_blocks);
  if (!options.detect_growth || n < 4 * blocks) return g;
  g.ran = true;
  g.blocks = options.growth_blocks;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = points[i].norm();
  std::vector<double> log_t(blocks), log_e(blocks), envelope(blocks);
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::size_t from = b * n / blocks, to = (b + 1) * n / blocks;
    std::size_t at = from;
    for (std::size_t i = from; i < to; ++i) {
      if (r[i] > r[at]) at = i;
    }
    envelope[b] = r[at];
    const double t = first_point_time + static_cast<double>(at);
    log_t[b] = std::log(t);
    if (b == 0) g.first_time = t;
    if (b + 1 == blocks) g.last_time = t;
  }
  g.first = envelope.front();
  g.last = envelope.back();
  // A motion at rest (a zero envelope somewhere) does not grow; its logarithms are not taken.
  if (*std::min_element(envelope.begin(), envelope.end()) <= 0.0) return g;
  for (std::size_t b = 0; b < blocks; ++b) log_e[b] = std::log(envelope[b]);
  g.monotone = true;
  for (std::size_t b = 1; b < blocks; ++b) g.monotone = g.monotone && envelope[b] > envelope[b - 1];
  g.rise = log_e.back() - log_e.front();
  g.exponent = slope(log_t, log_e, 0, blocks);
  g.late_exponent = slope(log_t, log_e, blocks / 2, blocks);
  g.growing = g.monotone && g.rise >= options.growth_rise &&
              g.exponent >= options.growth_exponent && g.late_exponent >= options.growth_exponent;
  return g;
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
  if (evidence.torus_digits &&
      !(std::isfinite(*evidence.torus_digits) && *evidence.torus_digits >= 0.0)) {
    throw InputError(fmt::format("MotionEvidence.torus_digits = {} must be finite and >= 0",
                                 *evidence.torus_digits));
  }
  if (!(evidence.first_point_time > 0.0) || !std::isfinite(evidence.first_point_time)) {
    throw InputError(fmt::format("MotionEvidence.first_point_time = {} must be finite and > 0",
                                 evidence.first_point_time));
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
  if (!(broken_digits > 0.0 && broken_digits <= curve_digits && curve_digits <= 15.0)) {
    return fail(why, fmt::format("ClassifierOptions.broken_digits = {}, curve_digits = {}: need "
                                 "0 < broken_digits <= curve_digits <= 15",
                                 broken_digits, curve_digits));
  }
  if (!(divergence_bound > 0.0)) {
    return fail(why, fmt::format("ClassifierOptions.divergence_bound = {} must be > 0",
                                 divergence_bound));
  }
  if (growth_blocks < 4 || !(growth_exponent > 0.0) || !std::isfinite(growth_exponent) ||
      !(growth_rise > 0.0) || !std::isfinite(growth_rise)) {
    return fail(why, fmt::format("ClassifierOptions.growth_blocks = {}, growth_exponent = {}, "
                                 "growth_rise = {}: need blocks >= 4 and a finite exponent and "
                                 "rise > 0",
                                 growth_blocks, growth_exponent, growth_rise));
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
  c.torus_digits = evidence.torus_digits;

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
      c.readings = fmt::format("period:{};lambda1:positive", k);
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
    c.readings = "points:too-few";
    return c;
  }

  // Rule 4a: secular growth, unless λ1 says the map contracts (see the header).
  if (lyapunov != Sign::negative) {
    const Growth g = measure_growth(points, evidence.first_point_time, options);
    if (g.ran) c.growth_exponent = g.exponent;
    if (g.growing) {
      c.regime = Regime::unbounded;
      c.reason = fmt::format(
          "unbounded: the amplitude grows like t^{:.2f} over the record (t^{:.2f} over its second "
          "half): the envelope of |y| rises in each of {} blocks, from {:.4g} at t = {:g} to "
          "{:.4g} at t = {:g} iterations; no period up to {} (best k = {}, mismatch {:.2g}); {}",
          g.exponent, g.late_exponent, g.blocks, g.first, g.first_time, g.last, g.last_time,
          options.period.k_max, c.period_search.best_k, c.period_search.mismatch, describe(c));
      return c;
    }
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

  const Torus torus = read_torus(c.torus_digits, options);
  // A smooth invariant curve contradicts chaos.
  if (torus != Torus::curve &&
      ((lyapunov == Sign::positive && zero_one == ZeroOne::chaotic) ||
       (lenient && lyapunov == Sign::positive && zero_one == ZeroOne::unknown) ||
       (lenient && lyapunov == Sign::unknown && zero_one == ZeroOne::chaotic))) {
    c.regime = Regime::chaotic;
    c.reason = "chaotic: " + numbers;
    return c;
  }
  // A smooth invariant curve settles a λ1 whose error bar straddles the margin but holds 0, or a
  // K in between, when neither reads chaos. A λ1 whose error bar excludes 0 (below it: a long
  // period approached slowly; above it) is left to more evidence.
  const bool holds_zero = c.lyapunov && std::abs(*c.lyapunov) <= c.lyapunov_error;
  if ((lyapunov == Sign::zero && zero_one == ZeroOne::regular) ||
      (torus == Torus::curve &&
       (lyapunov == Sign::zero || (lyapunov == Sign::inconclusive && holds_zero)) &&
       (zero_one == ZeroOne::regular || zero_one == ZeroOne::between)) ||
      (lenient && lyapunov == Sign::zero && zero_one == ZeroOne::unknown) ||
      (lenient && lyapunov == Sign::unknown && zero_one == ZeroOne::regular)) {
    c.regime = Regime::quasi_periodic;
    c.reason = "quasi-periodic: " + numbers;
    return c;
  }
  c.regime = Regime::uncertain;
  c.readings = fmt::format("period:none;lambda1:{};K:{};torus:{}", sign_word(lyapunov),
                           zero_one_word(zero_one), torus_word(torus));
  if (lyapunov == Sign::negative && zero_one != ZeroOne::chaotic) {
    c.reason = "uncertain: λ1 < 0 but " + numbers +
               ": a period beyond k_max, or a transient not yet over";
  } else if (torus == Torus::curve && lyapunov == Sign::positive) {
    c.reason = "uncertain: the points lie on a smooth invariant curve but λ1 > 0: " + numbers;
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
