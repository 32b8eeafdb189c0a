#pragma once
// The fixed-step driver of the precise-integration steppers (dense, banded, switching), which
// land only on their step grid: how many steps reach t_end, and the loop that takes them with
// the observer calls. Private to pwl_core.
#include <fmt/format.h>

#include <cmath>

#include "pwl/errors.hpp"
#include "pwl/integrators/integrator.hpp"

namespace pwl::detail {

// The number of fixed steps of size eta from t_now to t_end. Throws InputError when t_end is not
// finite or not a whole, non-negative number of steps away (to 1e-6 of a step).
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

// Advances a fixed-step integrator from t_now to t_end: `step()` takes one step and returns the
// time it reached; after each step the observer, if any, sees (t, x, v) once `publish()` has
// brought x and v (the integrator's position and velocity) up to date, and they are brought up
// to date once more at the end. Returns the number of steps. Everything is inlined into the
// caller's loop: the step of the 5-DOF stepper costs a few nanoseconds.
template <class Step, class Publish>
long advance_on_grid(double t_end, double t_now, double eta, const StepObserver& observer,
                     const Vector& x, const Vector& v, Step&& step, Publish&& publish) {
  const long count = fixed_step_count(t_end, t_now, eta);
  for (long k = 0; k < count; ++k) {
    const double t = step();
    if (observer) {
      publish();
      observer(t, x, v);
    }
  }
  publish();
  return count;
}

}  // namespace pwl::detail
