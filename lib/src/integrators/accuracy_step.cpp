// The step for a requested accuracy (accuracy_step.hpp): step doubling on a probe stretch.
#include "pwl/integrators/accuracy_step.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "pwl/errors.hpp"
#include "pwl/integrators/step_guard.hpp"

namespace pwl {

bool AccuracyRequest::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  const auto bad = [why](const std::string& message) {
    *why = message;
    return false;
  };
  if (!(relative_tolerance > 0.0) || !std::isfinite(relative_tolerance) || relative_tolerance >= 1.0) {
    return bad(fmt::format("relative_tolerance = {} must be in (0, 1)", relative_tolerance));
  }
  if (relative_tolerance < kSmallestRelativeTolerance) {
    return bad(fmt::format("relative_tolerance = {} is below {}: the rounding of a run of many "
                           "steps in double precision",
                           relative_tolerance, kSmallestRelativeTolerance));
  }
  if (!(period > 0.0) || !std::isfinite(period)) {
    return bad(fmt::format("period = {} must be positive and finite", period));
  }
  if (!(probe > 0.0) || !std::isfinite(probe)) {
    return bad(fmt::format("probe = {} must be positive and finite", probe));
  }
  if (max_steps_per_period < 1) {
    return bad(fmt::format("max_steps_per_period = {} must be at least 1", max_steps_per_period));
  }
  for (int d : force_degrees) {
    if (d < 0 || d > 8) return bad(fmt::format("force_degrees: degree {} is not in 0 .. 8", d));
  }
  return true;
}

namespace {

// The states [x; x'] at every `stride`-th multiple of η over the probe.
std::vector<Vector> probe_states(const GapStructure& structure, MethodSettings settings,
                                 double step, double t0, const Vector& x0, const Vector& v0,
                                 long points, long stride) {
  settings.step = step;
  std::unique_ptr<Integrator> integrator = make_integrator(structure, settings);
  integrator->set_state(t0, x0, v0);
  std::vector<Vector> states;
  states.reserve(static_cast<std::size_t>(points));
  const Index n = structure.dofs();
  for (long k = 1; k <= points; ++k) {
    integrator->advance_to(t0 + static_cast<double>(k * stride) * step);
    Vector y(2 * n);
    y << integrator->position(), integrator->velocity();
    states.push_back(std::move(y));
  }
  return states;
}

// The relative difference of two sets of probe states: the largest position difference over the
// largest position, the same for the velocities, the larger of the two.
double relative_difference(const std::vector<Vector>& a, const std::vector<Vector>& b, Index n) {
  double dx = 0.0, dv = 0.0, sx = 0.0, sv = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    dx = std::max(dx, (a[k].head(n) - b[k].head(n)).cwiseAbs().maxCoeff());
    dv = std::max(dv, (a[k].tail(n) - b[k].tail(n)).cwiseAbs().maxCoeff());
    sx = std::max(sx, b[k].head(n).cwiseAbs().maxCoeff());
    sv = std::max(sv, b[k].tail(n).cwiseAbs().maxCoeff());
  }
  const double ex = sx > 0.0 ? dx / sx : dx;
  const double ev = sv > 0.0 ? dv / sv : dv;
  return std::max(ex, ev);
}

// The estimated relative error of the step period / steps for `settings` on the probe: twice the
// difference of the runs at η and η/2 at about 50 common grid points (multiples of η); the
// difference itself in *difference.
double estimate_error(const GapStructure& structure, const MethodSettings& settings, long steps,
                      double t0, const Vector& x0, const Vector& v0,
                      const AccuracyRequest& request, double* difference) {
  const double step = request.period / static_cast<double>(steps);
  const long total = std::max<long>(1, static_cast<long>(std::ceil(request.probe / step - 1e-9)));
  const long stride = std::max<long>(1, total / 50);
  const long points = std::max<long>(1, total / stride);
  const std::vector<Vector> coarse =
      probe_states(structure, settings, step, t0, x0, v0, points, stride);
  const std::vector<Vector> fine =
      probe_states(structure, settings, step / 2, t0, x0, v0, points, 2 * stride);
  *difference = relative_difference(coarse, fine, structure.dofs());
  return 2.0 * *difference;
}

// From `steps` per period on, the largest step whose estimate meets the request, for a method of
// order `order` (the loop of the file comment). Adds its candidates to out.candidates.
void search_step(const GapStructure& structure, const MethodSettings& settings, int order,
                 long steps, double t0, const Vector& x0, const Vector& v0,
                 const AccuracyRequest& request, AccuracyStep& out) {
  const std::string_view name = method_traits(settings.method).name;
  double best = -1.0;
  long best_steps = 0;
  while (true) {
    if (steps > request.max_steps_per_period) {
      throw InputError(fmt::format(
          "relative tolerance = {:.3g}: {} does not reach it on this structure within {} steps "
          "per period (the best estimate, at T/{}, is {:.3g})",
          request.relative_tolerance, name, request.max_steps_per_period, best_steps, best));
    }
    double difference = 0.0;
    const double estimate =
        estimate_error(structure, settings, steps, t0, x0, v0, request, &difference);
    ++out.candidates;
    if (best < 0.0 || estimate < best) {
      best = estimate;
      best_steps = steps;
    }
    if (estimate <= request.relative_tolerance) {
      out.steps_per_period = steps;
      out.step = request.period / static_cast<double>(steps);
      out.estimated_error = estimate;
      return;
    }
    // At rounding the halving no longer changes the motion: smaller steps cannot help.
    if (difference < 1e-13) {
      throw InputError(fmt::format(
          "relative tolerance = {:.3g}: below what {} reaches on this structure (the estimate "
          "stays at {:.3g}, rounding)",
          request.relative_tolerance, name, estimate));
    }
    // The step the estimate asks for, and at least a tenth shorter (an estimate outside its
    // asymptotic range can promise too much).
    const double factor = std::pow(0.8 * request.relative_tolerance / estimate, 1.0 / order);
    const auto next = static_cast<long>(std::ceil(static_cast<double>(steps) / std::min(0.9, factor)));
    steps = std::max(next, steps + 1);
  }
}

}  // namespace

AccuracyStep step_for_accuracy(const GapStructure& structure, const MethodSettings& base,
                               double t0, const Vector& x0, const Vector& v0,
                               const AccuracyRequest& request) {
  std::string why;
  if (!request.is_valid(&why)) throw InputError("accuracy request: " + why);
  const MethodTraits& traits = method_traits(base.method);
  if (!traits.fixed_grid) {
    throw InputError(fmt::format(
        "a relative tolerance chooses the step of a fixed-step method (the PIM family); {} "
        "chooses its own steps: give it its tolerance instead",
        traits.name));
  }
  const bool switching = takes_force_degree(traits);
  if (!request.force_degrees.empty() && !switching) {
    throw InputError(fmt::format("accuracy request: force_degrees = [{}]: {} takes no force "
                                 "degree (the switching PIM does)",
                                 fmt::join(request.force_degrees, ", "), traits.name));
  }
  const double omega = contact_frequency(structure).omega_max;
  AccuracyStep out;
  out.largest_step =
      traits.step_warning > 0.0 && omega > 0.0 ? traits.step_warning / omega : request.period;
  const long first =
      std::max<long>(1, static_cast<long>(std::ceil(request.period / out.largest_step - 1e-9)));
  // With degrees to choose from, the highest finds the step and the lower ones are tried at it.
  MethodSettings settings = base;
  std::vector<int> degrees = request.force_degrees;
  std::sort(degrees.begin(), degrees.end(), std::greater<>());
  degrees.erase(std::unique(degrees.begin(), degrees.end()), degrees.end());
  if (!degrees.empty()) settings.force_degree = degrees.front();
  const int order = switching ? settings.force_degree + 3 : std::max(1, traits.order);
  try {
    search_step(structure, settings, order, first, t0, x0, v0, request, out);
  } catch (const InputError& e) {
    if (degrees.empty()) throw;
    throw InputError(fmt::format("force degree {} (the highest asked): {}", degrees.front(),
                                 e.what()));
  }
  out.force_degree = switching ? settings.force_degree : -1;
  for (std::size_t k = 1; k < degrees.size(); ++k) {
    settings.force_degree = degrees[k];
    double difference = 0.0;
    const double estimate = estimate_error(structure, settings, out.steps_per_period, t0, x0, v0,
                                           request, &difference);
    ++out.degree_checks;
    if (!(estimate <= request.relative_tolerance)) break;
    out.force_degree = degrees[k];
    out.estimated_error = estimate;
  }
  return out;
}

}  // namespace pwl
