#pragma once
// The number of fixed steps of size eta from t_now to t_end, for the precise-integration
// steppers, which land only on their step grid.
#include <fmt/format.h>

#include <cmath>

#include "pwl/errors.hpp"

namespace pwl::detail {

// Throws InputError when t_end is not finite or not a whole, non-negative number of steps away
// (to 1e-6 of a step).
inline long fixed_step_count(double t_end, double t_now, double eta) {
  const double span = (t_end - t_now) / eta;
  const double whole = std::round(span);
  if (!std::isfinite(t_end) || whole < 0.0 || std::abs(span - whole) > 1e-6) {
    throw InputError(fmt::format(
        "advance_to(t_end = {}): from t = {} that is {} steps of {}; the precise integrator "
        "needs a whole, non-negative number of steps",
        t_end, t_now, span, eta));
  }
  return static_cast<long>(whole);
}

}  // namespace pwl::detail
