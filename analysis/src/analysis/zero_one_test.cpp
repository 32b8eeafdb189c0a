// The 0-1 test for chaos, correlation form with the modified mean-square displacement
// (Gottwald & Melbourne 2004; Gottwald & Melbourne, SIAM J. Appl. Dyn. Syst. 8 (2009) 129).
#include "pwl/analysis/zero_one_test.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

// Pearson correlation; 0 when either argument is constant (no growth to correlate with).
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const std::size_t n = a.size();
  double mean_a = 0.0;
  double mean_b = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(n);
  mean_b /= static_cast<double>(n);
  double cov = 0.0;
  double var_a = 0.0;
  double var_b = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    cov += (a[i] - mean_a) * (b[i] - mean_b);
    var_a += (a[i] - mean_a) * (a[i] - mean_a);
    var_b += (b[i] - mean_b) * (b[i] - mean_b);
  }
  if (!(var_a > 0.0) || !(var_b > 0.0)) return 0.0;
  return cov / std::sqrt(var_a * var_b);
}

double median(std::vector<double> values) {
  const std::size_t n = values.size();
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (n % 2 == 1) return *middle;
  const double upper = *middle;
  const double lower = *std::max_element(values.begin(), middle);
  return 0.5 * (lower + upper);
}

}  // namespace

bool ZeroOneOptions::is_valid(std::string* why) const {
  if (frequencies < 1) {
    return fail(why, fmt::format("ZeroOneOptions.frequencies = {} must be >= 1", frequencies));
  }
  if (!(c_min > 0.0) || !(c_min < c_max) || !(c_max < std::numbers::pi)) {
    return fail(why, fmt::format("ZeroOneOptions.c_min = {}, c_max = {}: need 0 < c_min < c_max < π",
                                 c_min, c_max));
  }
  if (!(lag_fraction > 0.0) || !(lag_fraction <= 0.5)) {
    return fail(why, fmt::format("ZeroOneOptions.lag_fraction = {} must be in (0, 0.5]",
                                 lag_fraction));
  }
  if (min_samples < 20) {
    return fail(why, fmt::format("ZeroOneOptions.min_samples = {} must be >= 20", min_samples));
  }
  if (!(constant_tolerance >= 0.0) || !std::isfinite(constant_tolerance)) {
    return fail(why, fmt::format("ZeroOneOptions.constant_tolerance = {} must be finite and >= 0",
                                 constant_tolerance));
  }
  return true;
}

ZeroOneResult zero_one_test(std::span<const double> series, const ZeroOneOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  const std::size_t N = series.size();
  if (N < static_cast<std::size_t>(options.min_samples)) {
    throw InputError(fmt::format("series: {} samples, fewer than ZeroOneOptions.min_samples = {}",
                                 N, options.min_samples));
  }
  double mean = 0.0;
  for (std::size_t i = 0; i < N; ++i) {
    if (!std::isfinite(series[i])) {
      throw InputError(fmt::format("series[{}] = {} is not finite", i, series[i]));
    }
    mean += series[i];
  }
  mean /= static_cast<double>(N);
  double variance = 0.0;
  for (double v : series) variance += (v - mean) * (v - mean);
  variance /= static_cast<double>(N);

  ZeroOneResult result;
  const std::size_t lags =
      std::max<std::size_t>(2, static_cast<std::size_t>(options.lag_fraction * static_cast<double>(N)));
  result.lags = static_cast<int>(lags);

  // The c's are drawn first, so that they do not depend on the series.
  std::mt19937_64 rng(options.seed);
  result.c.resize(options.frequencies);
  for (double& c : result.c) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;  // [0, 1), library-independent
    c = options.c_min + (options.c_max - options.c_min) * u;
  }

  const double magnitude = std::max(std::abs(mean), std::numeric_limits<double>::min());
  if (std::sqrt(variance) <= options.constant_tolerance * magnitude) {
    result.constant_series = true;
    result.K = 0.0;
    result.K_c.assign(result.c.size(), 0.0);
    return result;
  }

  std::vector<double> p(N);
  std::vector<double> q(N);
  std::vector<double> lag_index(lags);
  std::vector<double> D(lags);
  for (std::size_t n = 0; n < lags; ++n) lag_index[n] = static_cast<double>(n + 1);

  result.K_c.reserve(result.c.size());
  for (double c : result.c) {
    // The walk (p_c, q_c), with j counted from 1 as in the papers.
    double sum_p = 0.0;
    double sum_q = 0.0;
    for (std::size_t j = 0; j < N; ++j) {
      const double angle = static_cast<double>(j + 1) * c;
      sum_p += series[j] * std::cos(angle);
      sum_q += series[j] * std::sin(angle);
      p[j] = sum_p;
      q[j] = sum_q;
    }
    const double oscillation_scale = mean * mean / (1.0 - std::cos(c));
    for (std::size_t n = 1; n <= lags; ++n) {
      double msd = 0.0;
      const std::size_t terms = N - n;
      for (std::size_t j = 0; j < terms; ++j) {
        const double dp = p[j + n] - p[j];
        const double dq = q[j + n] - q[j];
        msd += dp * dp + dq * dq;
      }
      msd /= static_cast<double>(terms);
      D[n - 1] = msd - oscillation_scale * (1.0 - std::cos(static_cast<double>(n) * c));
    }
    result.K_c.push_back(correlation(lag_index, D));
  }
  result.K = median(result.K_c);
  return result;
}

}  // namespace pwl::analysis
