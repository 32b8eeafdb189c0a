#include "pwl/analysis/period_detection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/point_checks.hpp"
#include "pwl/errors.hpp"

namespace pwl::analysis {

namespace {

bool fail(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

}  // namespace

namespace detail {

void check_points(const std::vector<Vector>& points, bool finite) {
  if (points.empty()) throw InputError("points: the sequence is empty (size 0)");
  const Index dim = points.front().size();
  if (dim == 0) throw InputError("points[0]: a point has dimension 0");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (points[i].size() != dim) {
      throw InputError(fmt::format("points[{}]: dimension {} differs from points[0]'s {}", i,
                                   points[i].size(), dim));
    }
    for (Index j = 0; finite && j < dim; ++j) {
      if (!std::isfinite(points[i][j])) {
        throw InputError(fmt::format("points[{}][{}] = {} is not finite", i, j, points[i][j]));
      }
    }
  }
}

}  // namespace detail

namespace {

// Greedy clustering: a point joins the first representative within `radius`.
int count_distinct(const std::vector<Vector>& points, std::size_t first, double radius) {
  std::vector<std::size_t> representatives;
  for (std::size_t i = first; i < points.size(); ++i) {
    bool seen = false;
    for (std::size_t r : representatives) {
      if ((points[i] - points[r]).norm() <= radius) {
        seen = true;
        break;
      }
    }
    if (!seen) representatives.push_back(i);
  }
  return static_cast<int>(representatives.size());
}

}  // namespace

bool PeriodOptions::is_valid(std::string* why) const {
  if (k_max < 1) return fail(why, fmt::format("PeriodOptions.k_max = {} must be >= 1", k_max));
  if (cycles < 1) return fail(why, fmt::format("PeriodOptions.cycles = {} must be >= 1", cycles));
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    return fail(why, fmt::format("PeriodOptions.tolerance = {} must be finite and > 0", tolerance));
  }
  if (!(relative_floor >= 0.0) || !std::isfinite(relative_floor)) {
    return fail(why, fmt::format("PeriodOptions.relative_floor = {} must be finite and >= 0",
                                 relative_floor));
  }
  if (!(absolute_floor >= 0.0) || !std::isfinite(absolute_floor)) {
    return fail(why, fmt::format("PeriodOptions.absolute_floor = {} must be finite and >= 0",
                                 absolute_floor));
  }
  if (!(scale >= 0.0) || !std::isfinite(scale)) {
    return fail(why, fmt::format("PeriodOptions.scale = {} must be finite and >= 0", scale));
  }
  return true;
}

PeriodResult detect_period(const std::vector<Vector>& points, const PeriodOptions& options) {
  std::string why;
  if (!options.is_valid(&why)) throw InputError(why);
  detail::check_points(points, true);

  const std::size_t n = points.size();
  PeriodResult result;

  Vector lo = points.front();
  Vector hi = points.front();
  double largest = 0.0;
  for (const Vector& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    largest = std::max(largest, p.norm());
  }
  result.diameter = (hi - lo).norm();
  result.scale = options.scale > 0.0
                     ? options.scale
                     : std::max({result.diameter, options.relative_floor * largest,
                                 options.absolute_floor});
  const double radius = options.tolerance * result.scale;

  result.mismatch = std::numeric_limits<double>::infinity();
  std::size_t used = 0;
  for (int k = 1; k <= options.k_max; ++k) {
    const std::size_t compared = static_cast<std::size_t>(options.cycles) * k;
    if (compared + k > n) break;  // larger k need even more points
    used = compared + k;
    double worst = 0.0;
    for (std::size_t j = 0; j < compared; ++j) {
      const std::size_t a = n - 1 - j;
      worst = std::max(worst, (points[a] - points[a - k]).norm());
    }
    // scale is 0 only when every point is identical and both floors are 0.
    const double relative = result.scale > 0.0 ? worst / result.scale : 0.0;
    if (worst <= radius) {
      result.period = k;
      result.best_k = k;
      result.mismatch = relative;
      result.fixed_point = (k == 1);
      result.points_used = static_cast<int>(used);
      result.distinct_points = count_distinct(points, n - k, radius);
      return result;
    }
    if (relative < result.mismatch) {
      result.mismatch = relative;
      result.best_k = k;
    }
  }
  result.points_used = static_cast<int>(used);
  const std::size_t window =
      std::min(n, static_cast<std::size_t>(options.cycles + 1) * options.k_max);
  result.distinct_points = count_distinct(points, n - window, radius);
  return result;
}

PeriodResult detect_period(const std::vector<double>& values, const PeriodOptions& options) {
  std::vector<Vector> points;
  points.reserve(values.size());
  for (double v : values) points.push_back(Vector::Constant(1, v));
  return detect_period(points, options);
}

}  // namespace pwl::analysis
