// The state checks of state_checks.hpp.
#include "pwl/numerics/state_checks.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pwl/errors.hpp"

namespace pwl {

void check_initial_state(double t, const Eigen::Ref<const Vector>& x,
                         const Eigen::Ref<const Vector>& v, Index n) {
  if (x.size() != n || v.size() != n) {
    throw InputError(fmt::format("state has {} displacements and {} velocities, expected {} "
                                 "(the structure's degrees of freedom)",
                                 x.size(), v.size(), n));
  }
  if (!std::isfinite(t)) throw InputError(fmt::format("initial state: t = {} is not finite", t));
  for (Index i = 0; i < n; ++i) {
    if (!std::isfinite(x[i])) {
      throw InputError(fmt::format("initial state at t = {}: x[{}] = {} is not finite", t, i, x[i]));
    }
    if (!std::isfinite(v[i])) {
      throw InputError(fmt::format("initial state at t = {}: v[{}] = {} is not finite", t, i, v[i]));
    }
  }
}

void throw_divergence(double t, double largest, double bound) {
  if (std::isnan(largest)) {
    throw DivergenceError(fmt::format("the motion blew up at t = {}: the state is not finite", t));
  }
  throw DivergenceError(fmt::format(
      "the motion blew up at t = {}: largest |x| or |x'| is {} (divergence_bound {})", t, largest,
      bound));
}

bool check_step_settings(double step, double divergence_bound, std::string* why) {
  if (!std::isfinite(step) || step <= 0.0) {
    *why = fmt::format("step = {} must be positive and finite", step);
    return false;
  }
  if (!(divergence_bound > 0.0)) {
    *why = fmt::format("divergence_bound = {} must be positive", divergence_bound);
    return false;
  }
  return true;
}

bool check_nested(bool valid, std::string_view field, std::string* why) {
  if (!valid) *why = std::string(field) + "." + *why;
  return valid;
}

}  // namespace pwl
