// The invariant-curve test by weighted Birkhoff averages: Das, Sander, Yorke & Meiss, Nonlinearity
// 30 (2017) 4111 (the weighted average, the digits from two halves of a record); Das & Yorke,
// Nonlinearity 31 (2018) 491 (super-convergence on smooth quasi-periodic orbits); Sander & Meiss,
// Physica D 411 (2020) 132569 (the rotation number as a weighted average of angle increments
// around the weighted centre of an invariant circle).
#include "pwl/analysis/weighted_birkhoff.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <utility>

#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();
constexpr double kTwoPi = 2.0 * std::numbers::pi;

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

// -log10 of a relative difference, floored at machine epsilon (a difference of zero means the
// halves agree to rounding, not to infinitely many digits).
double digits_of(double relative_difference) {
  return -std::log10(std::max(relative_difference, kEpsilon));
}

// The normalised weights for each length used, computed once.
class WeightCache {
 public:
  const std::vector<double>& get(std::size_t n) {
    auto it = cache_.find(n);
    if (it == cache_.end()) {
      it = cache_.emplace(n, weighted_birkhoff_weights(static_cast<int>(n))).first;
    }
    return it->second;
  }

 private:
  std::map<std::size_t, std::vector<double>> cache_;
};

// Σ w_j v[begin + j] over j < count, with the normalised weights for length count.
double weighted_sum(const std::vector<double>& values, std::size_t begin, std::size_t count,
                    WeightCache& weights) {
  const std::vector<double>& w = weights.get(count);
  double sum = 0.0;
  for (std::size_t j = 0; j < count; ++j) sum += w[j] * values[begin + j];
  return sum;
}

struct SeriesStatistics {
  double average = 0.0;            // WB over all values
  double half_difference = 0.0;    // |WB first half - WB second half|
  double spread = 0.0;             // max - min
  double largest_magnitude = 0.0;  // max |v|
};

// The averages of one series. The values are shifted by their mid-range before summing, so that a
// large offset (a coordinate oscillating far from 0) does not cost digits to rounding.
SeriesStatistics statistics(std::vector<double>& values, WeightCache& weights) {
  SeriesStatistics s;
  const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
  const double low = *lowest;
  const double high = *highest;
  s.spread = high - low;
  s.largest_magnitude = std::max(std::abs(low), std::abs(high));
  const double mid = 0.5 * (low + high);
  for (double& v : values) v -= mid;
  const std::size_t n = values.size();
  const std::size_t half = n / 2;
  s.average = mid + weighted_sum(values, 0, n, weights);
  s.half_difference = std::abs(weighted_sum(values, 0, half, weights) -
                               weighted_sum(values, half, n - half, weights));
  return s;
}

}  // namespace

bool WeightedBirkhoffOptions::is_valid(std::string* why) const {
  if (min_points < 20) {
    return fail(why,
                fmt::format("WeightedBirkhoffOptions.min_points = {} must be >= 20", min_points));
  }
  if (!(torus_digits > 0.0) || !(torus_digits <= 15.0)) {
    return fail(why, fmt::format("WeightedBirkhoffOptions.torus_digits = {} must be in (0, 15]",
                                 torus_digits));
  }
  if (rotation) {
    if (plane_first < 0) {
      return fail(
          why, fmt::format("WeightedBirkhoffOptions.plane_first = {} must be >= 0", plane_first));
    }
    if (plane_second < 0) {
      return fail(
          why, fmt::format("WeightedBirkhoffOptions.plane_second = {} must be >= 0", plane_second));
    }
    if (plane_first == plane_second) {
      return fail(why, fmt::format("WeightedBirkhoffOptions.plane_first = plane_second = {}: the "
                                   "plane needs two distinct coordinates",
                                   plane_first));
    }
  }
  if (!(constant_tolerance >= 0.0) || !(constant_tolerance < 1.0)) {
    return fail(why, fmt::format("WeightedBirkhoffOptions.constant_tolerance = {} must be in "
                                 "[0, 1)",
                                 constant_tolerance));
  }
  for (std::size_t k = 0; k < observables.size(); ++k) {
    if (!observables[k]) {
      return fail(why, fmt::format("WeightedBirkhoffOptions.observables[{}] is empty (not "
                                   "callable)",
                                   k));
    }
  }
  return true;
}

std::vector<double> weighted_birkhoff_weights(int N) {
  if (N < 2) throw InputError(fmt::format("weighted_birkhoff_weights: N = {} must be >= 2", N));
  std::vector<double> w(static_cast<std::size_t>(N), 0.0);
  double total = 0.0;
  for (int n = 1; n < N; ++n) {
    const double t = static_cast<double>(n) / static_cast<double>(N);
    w[static_cast<std::size_t>(n)] = std::exp(-1.0 / (t * (1.0 - t)));
    total += w[static_cast<std::size_t>(n)];
  }
  for (double& v : w) v /= total;
  return w;
}

double weighted_birkhoff_average(const std::vector<double>& values) {
  if (values.size() < 2) {
    throw InputError(
        fmt::format("weighted_birkhoff_average: values has {} entries, need >= 2", values.size()));
  }
  const std::vector<double> w = weighted_birkhoff_weights(static_cast<int>(values.size()));
  double sum = 0.0;
  for (std::size_t n = 0; n < values.size(); ++n) sum += w[n] * values[n];
  return sum;
}

WeightedBirkhoffResult weighted_birkhoff_test(const Matrix& points,
                                              const WeightedBirkhoffOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  const Index N = points.rows();
  const Index dim = points.cols();
  if (N < options.min_points) {
    throw InputError(
        fmt::format("points: {} rows, fewer than WeightedBirkhoffOptions.min_points "
                    "= {}",
                    N, options.min_points));
  }
  if (dim == 0) throw InputError("points: 0 columns (points of dimension 0)");
  for (Index j = 0; j < dim; ++j) {
    for (Index i = 0; i < N; ++i) {
      if (!std::isfinite(points(i, j))) {
        throw InputError(fmt::format("points({}, {}) = {} is not finite", i, j, points(i, j)));
      }
    }
  }
  if (options.rotation) {
    for (const auto& [name, index] : {std::pair{"plane_first", options.plane_first},
                                      std::pair{"plane_second", options.plane_second}}) {
      if (index >= dim) {
        throw InputError(
            fmt::format("WeightedBirkhoffOptions.{} = {} is not a coordinate of "
                        "points of dimension {}",
                        name, index, dim));
      }
    }
  }

  const auto count = static_cast<std::size_t>(N);
  WeightCache weights;
  WeightedBirkhoffResult result;
  result.points = static_cast<int>(N);
  result.centre.resize(dim);

  // One observable's series: averages, digits, and whether it counts.
  // `scale`: the observable's natural size. The coordinates and the caller's observables have
  // only their own spread; cos(π u) and sin(π u) have 1, and their half difference is measured
  // against it: on a record of a few distinct points (a periodic orbit: u = 0 or 1 up to the
  // rounding of the integration, about 1e-12 after division by the range) sin(π u) varies by
  // rounding only, and relative to that spread its halves would disagree in the first digit.
  auto record = [&](std::vector<double>& values, double scale) {
    const SeriesStatistics s = statistics(values, weights);
    const bool varies =
        s.spread > options.constant_tolerance * std::max(s.largest_magnitude, scale);
    const double relative = varies ? s.half_difference / std::max(s.spread, scale) : 0.0;
    result.averages.push_back(s.average);
    result.relative_differences.push_back(relative);
    result.observable_digits.push_back(digits_of(relative));
    result.observable_used.push_back(varies);
    return s.average;
  };

  std::vector<double> values(count);
  if (options.observables.empty()) {
    // Coordinate-major: x_i, cos(π u_i), sin(π u_i).
    for (Index j = 0; j < dim; ++j) {
      for (std::size_t i = 0; i < count; ++i) values[i] = points(static_cast<Index>(i), j);
      const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
      const double low = *lowest;
      const double range = *highest - low;
      result.centre[j] = record(values, 0.0);
      for (int which = 0; which < 2; ++which) {
        for (std::size_t i = 0; i < count; ++i) {
          const double x = points(static_cast<Index>(i), j);
          const double u = range > 0.0 ? (x - low) / range : 0.0;
          values[i] = which == 0 ? std::cos(std::numbers::pi * u) : std::sin(std::numbers::pi * u);
        }
        record(values, 1.0);
      }
    }
  } else {
    // The centre is needed for the rotation number (and reported) whatever the observables.
    std::vector<double> coordinate(count);
    for (Index j = 0; j < dim; ++j) {
      for (std::size_t i = 0; i < count; ++i) coordinate[i] = points(static_cast<Index>(i), j);
      result.centre[j] = statistics(coordinate, weights).average;
    }
    Vector point(dim);
    for (std::size_t k = 0; k < options.observables.size(); ++k) {
      for (std::size_t i = 0; i < count; ++i) {
        point = points.row(static_cast<Index>(i)).transpose();
        values[i] = options.observables[k](point);
        if (!std::isfinite(values[i])) {
          throw InputError(
              fmt::format("WeightedBirkhoffOptions.observables[{}] returned {} at "
                          "points row {}",
                          k, values[i], i));
        }
      }
      record(values, 0.0);
    }
  }

  result.digits = digits_of(0.0);
  for (std::size_t k = 0; k < result.observable_digits.size(); ++k) {
    if (!result.observable_used[k]) continue;
    ++result.observables_used;
    result.digits = std::min(result.digits, result.observable_digits[k]);
  }
  result.smooth_invariant_curve =
      result.observables_used > 0 && result.digits >= options.torus_digits;

  if (options.rotation) {
    const Index a = options.plane_first;
    const Index b = options.plane_second;
    const double cx = result.centre[a];
    const double cy = result.centre[b];
    // Increments of the angle around the centre, first in [0, 2π).
    const std::size_t m = count - 1;
    std::vector<double> increments(m);
    double previous = std::atan2(points(0, b) - cy, points(0, a) - cx);
    for (std::size_t i = 0; i < m; ++i) {
      const double angle = std::atan2(points(static_cast<Index>(i + 1), b) - cy,
                                      points(static_cast<Index>(i + 1), a) - cx);
      double d = angle - previous;  // in (-2π, 2π)
      if (d < 0.0) d += kTwoPi;
      if (d >= kTwoPi) d -= kTwoPi;
      increments[i] = d;
      previous = angle;
    }
    // The cut: the middle of the widest arc no increment takes (including the arc that wraps
    // around from the largest increment back to the smallest).
    std::vector<double> sorted = increments;
    std::sort(sorted.begin(), sorted.end());
    double cut = 0.5 * (sorted.back() + sorted.front() + kTwoPi);
    double widest = sorted.front() + kTwoPi - sorted.back();
    for (std::size_t i = 0; i + 1 < m; ++i) {
      const double gap = sorted[i + 1] - sorted[i];
      if (gap > widest) {
        widest = gap;
        cut = 0.5 * (sorted[i] + sorted[i + 1]);
      }
    }
    // Each increment into (cut - 2π, cut], in turns.
    for (double& d : increments) {
      if (d > cut) d -= kTwoPi;
      d /= kTwoPi;
    }
    const std::size_t half = m / 2;
    const double rho = weighted_sum(increments, 0, m, weights);
    result.rotation_difference = std::abs(weighted_sum(increments, 0, half, weights) -
                                          weighted_sum(increments, half, m - half, weights));
    double turns = rho - std::floor(rho);
    if (turns >= 1.0) turns = 0.0;  // a tiny negative ρ rounds to 1
    result.has_rotation = true;
    result.rotation_number = turns;
    result.rotation_digits = digits_of(result.rotation_difference);
  }
  return result;
}

}  // namespace pwl::analysis
