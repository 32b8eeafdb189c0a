#include "pwl/study/section_sampler.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <string>
#include <utility>

#include "pwl/errors.hpp"

namespace pwl::analysis {

StateRate::StateRate(const GapStructure& structure)
    : structure_(structure), directions_(structure.spring_directions_sparse()) {
  mass_.compute(structure.mass);
  if (mass_.info() != Eigen::Success) {
    throw InputError("the mass matrix is not positive definite: no accelerations");
  }
}

Vector StateRate::acceleration(double t, const Vector& x, const Vector& v) const {
  Vector force = structure_.load(t);
  force.noalias() -= structure_.damping * v;
  force.noalias() -= structure_.stiffness * x;
  if (structure_.spring_count() > 0) force.noalias() -= directions_ * structure_.spring_forces(x);
  return mass_.solve(force);
}

SectionSampler::SectionSampler(Integrator& integrator, const GapStructure& structure, double period,
                               const PoincareSection& section, const MethodSettings& method,
                               int steps_per_period)
    : integrator_(integrator),
      period_(period),
      section_(section),
      rate_(structure),
      origin_(integrator.time()),
      fixed_grid_(method_traits(method.method).fixed_grid),
      step_(method.step),
      sample_step_(steps_per_period > 0 ? period / steps_per_period : period) {
  std::string why;
  if (!section.is_valid(integrator.dofs(), &why)) throw InputError(why);
  if (!(period > 0.0) || !std::isfinite(period)) {
    throw InputError(
        fmt::format("SectionSampler: period = {} must be positive and finite", period));
  }
  if (fixed_grid_ && !(step_ > 0.0)) {
    throw InputError(
        fmt::format("SectionSampler: the fixed grid's step {} must be positive", step_));
  }
}

double SectionSampler::strobe_time(long k) const {
  // At phase 0 exactly `k * period` from the origin, the time every job integrated to before
  // sections had a phase, so that its results stay the same to the bit.
  const double offset = section_.phase == 0.0 ? static_cast<double>(k) * period_
                                              : (static_cast<double>(k) + section_.phase) * period_;
  return origin_ == 0.0 ? offset : origin_ + offset;
}

StateSample SectionSampler::sample() const {
  StateSample s;
  s.t = integrator_.time();
  s.x = integrator_.position();
  s.v = integrator_.velocity();
  s.a = rate_.acceleration(s.t, s.x, s.v);
  return s;
}

StrobePoint SectionSampler::advance_to_strobe(long k, Matrix* tangent, const StepObserver& steps) {
  const double target = strobe_time(k);
  const Index n = integrator_.dofs();
  StrobePoint point;
  bool on_grid = !fixed_grid_;
  double before = target;
  if (fixed_grid_) {
    // Within 1e-7 of a step of the grid: the integrator (which accepts 1e-6) lands there.
    const double steps_from_origin = (target - origin_) / step_;
    const double whole = std::round(steps_from_origin);
    on_grid = std::abs(steps_from_origin - whole) <= 1e-7;
    before = origin_ + std::floor(steps_from_origin) * step_;
  }
  if (on_grid) {
    advance_to(target, tangent, steps);
    point.t = integrator_.time();
    point.state.resize(2 * n);
    point.state << integrator_.position(), integrator_.velocity();
    return point;
  }
  advance_to(before, tangent, steps);
  const StateSample a = sample();
  advance_to(before + step_, tangent, steps);
  const StateSample b = sample();
  const StateSample s = interpolate_state(a, b, target);
  point.t = target;
  point.state.resize(2 * n);
  point.state << s.x, s.v;
  point.interpolated = true;
  return point;
}

void SectionSampler::advance_piece(double t_end, Matrix* tangent, const StepObserver& observer) {
  if (tangent != nullptr) {
    integrator_.advance_with_tangent(t_end, *tangent, observer);
  } else {
    integrator_.advance_to(t_end, observer);
  }
}

void SectionSampler::advance_to(double t_end, Matrix* tangent, const StepObserver& steps) {
  if (!sink_) {
    advance_piece(t_end, tangent, steps);
    return;
  }
  const StepObserver observer = [&](double t, const Vector& x, const Vector& v) {
    if (steps) steps(t, x, v);
    observe(t, x, v);
  };
  if (fixed_grid_) {
    advance_piece(t_end, tangent, observer);
    return;
  }
  // Pieces of at most sample_step_, the last one ending exactly at t_end.
  while (integrator_.time() < t_end) {
    double next = integrator_.time() + sample_step_;
    if (next > t_end - 1e-9 * sample_step_) next = t_end;
    advance_piece(next, tangent, observer);
  }
}

void SectionSampler::observe(double t, const Vector& x, const Vector& v) {
  if (!(t > last_t_)) return;  // a repeated sample (an event at the end of a piece)
  const Index n = x.size();
  state_.resize(2 * n);
  state_ << x, v;
  if (!state_.allFinite()) {
    throw DivergenceError(fmt::format("the state is not finite at t = {}", t));
  }
  rate_of_state_.resize(2 * n);
  rate_of_state_ << v, rate_.acceleration(t, x, v);
  std::optional<Crossing> crossing = find_crossing(section_.hyperplane, last_t_, last_state_,
                                                   last_rate_, t, state_, rate_of_state_);
  last_t_ = t;
  std::swap(last_state_, state_);
  std::swap(last_rate_, rate_of_state_);
  if (crossing) sink_(*crossing);
}

void SectionSampler::record_crossings(CrossingSink sink) {
  if (sink && section_.stroboscopic()) {
    throw InputError("SectionSampler: a stroboscopic section has no crossings to record");
  }
  sink_ = std::move(sink);
  if (!sink_) return;
  const StateSample s = sample();
  last_t_ = s.t;
  last_state_.resize(2 * s.x.size());
  last_state_ << s.x, s.v;
  last_rate_.resize(2 * s.x.size());
  last_rate_ << s.v, s.a;
}

}  // namespace pwl::analysis
