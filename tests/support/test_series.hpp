#pragma once
// Sequences and maps of known behaviour that the analysis tests share (the logistic map, the
// Hénon map), and the measured order of a convergence study.
#include <cmath>
#include <vector>

#include "pwl/analysis/lyapunov.hpp"

namespace pwl::test {

// The logistic map x -> r x (1 - x) from x, its first `transient` values left out, then `count`
// values.
inline std::vector<double> logistic_series(double r, int count, int transient, double x) {
  for (int i = 0; i < transient; ++i) x = r * x * (1.0 - x);
  std::vector<double> values;
  for (int i = 0; i < count; ++i) {
    x = r * x * (1.0 - x);
    values.push_back(x);
  }
  return values;
}

// The logistic map with its Jacobian r (1 - 2x), as a tangent map.
inline analysis::TangentMap logistic_map(double r) {
  return [r](const Vector& x, Matrix* J) {
    if (J != nullptr) *J = Matrix::Constant(1, 1, r * (1.0 - 2.0 * x[0]));
    return Vector::Constant(1, r * x[0] * (1.0 - x[0]));
  };
}

// Hénon (1976): (x, y) -> (1 - a x^2 + y, b x); det J = -b everywhere.
inline analysis::TangentMap henon_map(double a = 1.4, double b = 0.3) {
  return [a, b](const Vector& s, Matrix* J) {
    if (J != nullptr) {
      J->resize(2, 2);
      *J << -2.0 * a * s[0], 1.0, b, 0.0;
    }
    Vector next(2);
    next << 1.0 - a * s[0] * s[0] + s[1], b * s[0];
    return next;
  };
}

// Least-squares slope of log(error) against log(step): the measured order of a method.
inline double fitted_order(const std::vector<double>& steps, const std::vector<double>& errors) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(steps.size());
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double x = std::log(steps[i]), y = std::log(errors[i]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace pwl::test
