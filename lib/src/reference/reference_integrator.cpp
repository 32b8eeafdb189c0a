// Reference integrators: embedded Runge-Kutta pairs with adaptive step size from Boost.Odeint,
// on the continuous right-hand side of a GapStructure (reference_rhs.hpp).
//
// Methods and the sources they follow:
//  - dopri5: J. R. Dormand and P. J. Prince, "A family of embedded Runge-Kutta formulae",
//    J. Comput. Appl. Math. 6 (1980) 19-26; 5th-order solution, 4th-order error estimate,
//    first-same-as-last, with the 4th-order continuous extension given in Hairer, Nørsett and
//    Wanner §II.6.
//  - rkf78: E. Fehlberg, "Classical fifth-, sixth-, seventh- and eighth-order Runge-Kutta
//    formulas with stepsize control", NASA TR R-287 (1968); 13 stages, no dense output.
//  - Event location: E. Hairer, S. P. Nørsett and G. Wanner, Solving Ordinary Differential
//    Equations I (2nd ed., Springer 1993), §II.6 (dense output; discontinuous right-hand sides
//    are integrated accurately only when the steps stop at the discontinuities); L. F. Shampine
//    and S. Thompson, "Event location for ordinary differential equations", Comput. Math.
//    Appl. 39 (2000) 43-54 (sample the event functions inside each step so that a pair of
//    crossings within one step is not missed; locate on the continuous extension).
//  - Root search: the Illinois variant of regula falsi (M. Dowell and P. Jarratt, BIT 11
//    (1971) 168-174) over several event functions at once, as in the root finder of SUNDIALS'
//    CVODE, with a bisection safeguard.
#include "pwl/integrators/reference_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

// odeint's Eigen adaptor needs the core algebra dispatcher declared first.
#include <boost/numeric/odeint/algebra/algebra_dispatcher.hpp>
#include <boost/numeric/odeint/algebra/default_operations.hpp>
#include <boost/numeric/odeint/algebra/vector_space_algebra.hpp>
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_fehlberg78.hpp>
#include <boost/numeric/odeint/external/eigen/eigen.hpp>
#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/numerics/state_checks.hpp"
#include "reference/reference_rhs.hpp"

namespace pwl {
namespace {

namespace odeint = boost::numeric::odeint;
using reference_detail::GapRhs;

using State = Vector;
using Dopri5 =
    odeint::runge_kutta_dopri5<State, double, State, double, odeint::vector_space_algebra>;
using Fehlberg78 =
    odeint::runge_kutta_fehlberg78<State, double, State, double, odeint::vector_space_algebra>;

// The step's error as odeint's controller wants it, max_i |err_i| / (atol + rtol |y_i|) with y
// the state at the start of the step (as odeint's default_error_checker with a_x = 1,
// a_dxdt = 0, whose unit helpers would copy the state vectors on every step). A NaN error is
// passed on, so that the step is accepted and its non-finite state reported.
class ErrorChecker {
 public:
  ErrorChecker(double absolute, double relative) : absolute_(absolute), relative_(relative) {}
  template <class Algebra>
  double error(Algebra& /*algebra*/, const State& x_old, const State& /*dxdt_old*/,
               State& x_err, double /*dt*/) const {
    return (x_err.array().abs() / (absolute_ + relative_ * x_old.array().abs()))
        .maxCoeff<Eigen::PropagateNaN>();
  }

 private:
  double absolute_;
  double relative_;
};
using StepAdjuster = odeint::default_step_adjuster<double, double>;

// Backstops so that a hopeless integration ends with an error instead of running forever.
constexpr long kMaxAttemptsPerAdvance = 50'000'000;
constexpr int kMaxConsecutiveRejections = 500;
// A gap function within this many tolerance units (atol + rtol |terms of g|) of zero counts as
// "on the kink": its sign is not trusted, so a sign change that starts there is not an event.
// It covers the error with which a located crossing lands (the root search stops within half of
// it, the continuous extension adds a few units); a crossing it hides moves the kink by at most
// the threshold, a second-order effect.
constexpr double kOnKinkFactor = 10.0;
constexpr int kMaxRootIterations = 200;

// odeint copies the system functor, so it only points at the right-hand side.
struct SystemRef {
  GapRhs* rhs;
  void operator()(const State& y, State& dydt, double t) const { rhs->evaluate(y, dydt, t); }
};

template <class Stepper>
struct RungeKuttaTraits;
template <>
struct RungeKuttaTraits<Dopri5> {
  static constexpr const char* name = "dopri5";
  static constexpr bool first_same_as_last = true;  // and has a continuous extension
};
template <>
struct RungeKuttaTraits<Fehlberg78> {
  static constexpr const char* name = "rkf78";
  static constexpr bool first_same_as_last = false;
};

// Quintic Hermite interpolation on [0, 1] from value, first and second derivative (already
// scaled by h and h^2) at both ends: a cheap, accurate guess of a gap function inside an rkf78
// step, used only to decide where to look; every bracket is confirmed with a true step.
double quintic_hermite(double th, double p0, double d0, double a0, double p1, double d1,
                       double a1) {
  const double t2 = th * th;
  const double t3 = t2 * th;
  const double t4 = t3 * th;
  const double t5 = t4 * th;
  const double h0 = 1.0 - 10.0 * t3 + 15.0 * t4 - 6.0 * t5;
  const double h1 = th - 6.0 * t3 + 8.0 * t4 - 3.0 * t5;
  const double h2 = 0.5 * (t2 - 3.0 * t3 + 3.0 * t4 - t5);
  const double h3 = 10.0 * t3 - 15.0 * t4 + 6.0 * t5;
  const double h4 = -4.0 * t3 + 7.0 * t4 - 3.0 * t5;
  const double h5 = 0.5 * (t3 - 2.0 * t4 + t5);
  return p0 * h0 + d0 * h1 + a0 * h2 + p1 * h3 + d1 * h4 + a1 * h5;
}

int sign_of(double value) { return value > 0.0 ? 1 : (value < 0.0 ? -1 : 0); }

template <class Stepper>
class RungeKuttaIntegrator final : public Integrator {
  using Controlled = odeint::controlled_runge_kutta<Stepper, ErrorChecker, StepAdjuster>;
  static constexpr bool kFsal = RungeKuttaTraits<Stepper>::first_same_as_last;
  enum class Outcome { none, event, redo };
  // Interior points per step at which the gap functions are sampled for a pair of crossings
  // (a brief contact) inside one step. dopri5's samples are continuous-extension states (O(n)
  // each) on steps that are short anyway; rkf78's are quintic Hermite guesses (O(1) per
  // spring) on steps several times longer, so it takes many.
  static constexpr int kInteriorSamples = kFsal ? 3 : 15;

 public:
  RungeKuttaIntegrator(const GapStructure& structure, const ReferenceOptions& options)
      : options_(options),
        rhs_(structure),
        // Error per component relative to atol + rtol |y_i| (odeint's default also adds
        // rtol dt |y'_i|, which loosens the control in fast phases of the motion). The step
        // limit is applied here rather than through odeint's step adjuster, whose try_step
        // refuses (and reports as a failure) any dt above the limit.
        controlled_(ErrorChecker(options.absolute_tolerance, options.relative_tolerance),
                    StepAdjuster(0.0), Stepper()),
        locate_(options.locate_kinks && rhs_.spring_count() > 0) {
    const Index n = rhs_.dofs();
    const Index m = rhs_.spring_count();
    for (Vector* v : {&y_, &dydt_, &y_new_, &dydt_new_, &y_tmp_, &y_bracket_}) v->setZero(2 * n);
    for (Vector* v : {&g_start_, &threshold_, &g_a_, &g_b_, &g_c_, &g_end_}) v->setZero(m);
    for (Vector* v : {&rate_start_, &accel_start_, &rate_end_, &accel_end_}) v->setZero(m);
    for (std::vector<int>* v : {&mode_, &armed_, &scan_armed_, &candidate_, &flip_, &event_side_}) {
      v->assign(static_cast<std::size_t>(m), 0);
    }
    rhs_.freeze_modes(locate_ ? mode_.data() : nullptr);
    set_state(0.0, Vector::Zero(n), Vector::Zero(n));
  }
  RungeKuttaIntegrator(const RungeKuttaIntegrator&) = delete;
  RungeKuttaIntegrator& operator=(const RungeKuttaIntegrator&) = delete;

  Method method() const override {
    return options_.method == RungeKuttaMethod::dopri5 ? Method::dopri5 : Method::rkf78;
  }
  std::string name() const override {
    return fmt::format("{}{} (rtol {:g})", RungeKuttaTraits<Stepper>::name,
                       options_.locate_kinks ? " kink-located" : "", options_.relative_tolerance);
  }

  Index dofs() const override { return rhs_.dofs(); }

  void set_state(double t, const Vector& x, const Vector& v) override {
    const Index n = dofs();
    check_initial_state(t, x, v, n);
    t_ = t;
    y_.head(n) = x;
    y_.tail(n) = v;
    x_ = x;
    v_ = v;
    derivative_valid_ = false;
    dt_ = options_.initial_step;
    if (locate_) {
      std::fill(event_side_.begin(), event_side_.end(), 0);
      prepare_step_start();
    }
  }

  double time() const override { return t_; }
  const Vector& position() const override { return x_; }
  const Vector& velocity() const override { return v_; }

  IntegratorStats stats() const override {
    IntegratorStats s = stats_;
    s.rhs_evaluations = rhs_.evaluations();
    return s;
  }

  void advance_to(double t_end, const StepObserver& observer) override {
    if (!std::isfinite(t_end) || t_end < t_) {
      throw InputError(fmt::format("{}: advance_to(t_end = {}) must be finite and not before the "
                                   "current time {}",
                                   name(), t_end, t_));
    }
    // x_ and v_ follow y_ only when someone looks: before the observer and on leaving (also by
    // an exception, so that position() is the last state that passed the checks).
    struct Publish {
      RungeKuttaIntegrator* self;
      ~Publish() { self->publish(); }
    } publish_on_exit{this};
    long attempts = 0;
    int consecutive_rejections = 0;
    int redos = 0;
    while (t_ < t_end) {
      if (++attempts > kMaxAttemptsPerAdvance) {
        throw DivergenceError(fmt::format(
            "{}: gave up after {} step attempts at t = {:.17g}, short of t_end = {} (step size "
            "{:g}); the tolerances are too tight for this motion",
            name(), kMaxAttemptsPerAdvance, t_, t_end, dt_));
      }
      if (!derivative_valid_) {
        rhs_.evaluate(y_, dydt_, t_);
        derivative_valid_ = true;
      }
      const double remaining = t_end - t_;
      double dt = dt_;
      if (options_.max_step > 0.0) dt = std::min(dt, options_.max_step);
      // Take the rest of the interval when it is at most 1% longer than the planned step, rather
      // than leaving a sliver for a final tiny step; the error control still judges the step.
      bool last = false;
      if (dt * 1.01 >= remaining &&
          (options_.max_step == 0.0 || remaining <= options_.max_step)) {
        dt = remaining;
        last = true;
      }

      double t_try = t_;
      double dt_next = dt;
      odeint::controlled_step_result result;
      if constexpr (kFsal) {
        result = controlled_.try_step(SystemRef{&rhs_}, y_, dydt_, t_try, y_new_, dydt_new_,
                                      dt_next);
      } else {
        result = controlled_.try_step(SystemRef{&rhs_}, y_, dydt_, t_try, y_new_, dt_next);
      }

      if (result == odeint::fail) {
        ++stats_.rejected_steps;
        dt_ = dt_next;
        if (!std::isfinite(dt_) || !(t_ + dt_ > t_)) {
          throw DivergenceError(fmt::format(
              "{}: step size underflow at t = {:.17g}: the step size {:g} no longer advances t "
              "(the motion is too violent for rtol = {:g}, atol = {:g})",
              name(), t_, dt_, options_.relative_tolerance, options_.absolute_tolerance));
        }
        if (++consecutive_rejections > kMaxConsecutiveRejections) {
          throw DivergenceError(fmt::format(
              "{}: {} consecutive rejected steps at t = {:.17g} (last step size {:g})", name(),
              kMaxConsecutiveRejections, t_, dt_));
        }
        continue;
      }
      consecutive_rejections = 0;
      if (!(t_try > t_)) {  // only a max_step below the resolution of t gets here
        throw DivergenceError(fmt::format(
            "{}: step size underflow at t = {:.17g}: the step size {:g} does not advance t", name(),
            t_, dt));
      }
      double t_new = last ? t_end : t_try;
      check_state(y_new_, t_new);

      // rkf78 is not first-same-as-last: the next step's first stage (and the Hermite guesses).
      if constexpr (!kFsal) rhs_.evaluate(y_new_, dydt_new_, t_new);
      if (locate_) {
        const Outcome outcome = locate_kink(t_new, redos < kMaxRedos);
        if (outcome == Outcome::redo) {
          // A spring that started on its kink left it on the side its mode did not predict: the
          // step integrated the wrong piece. Flip those modes and take the step again.
          ++redos;
          derivative_valid_ = false;
          dt_ = dt;
          continue;
        }
        if (outcome == Outcome::event) {
          check_state(y_new_, t_new);
          derivative_valid_ = false;  // the modes change at the kink
          last = false;
        }
      }
      redos = 0;
      // A step shortened to land on t_end says little about the step the motion allows.
      dt_ = last ? std::max(dt_next, dt_) : dt_next;
      if (last || t_new >= t_end) t_new = t_end;

      t_ = t_new;
      y_.swap(y_new_);
      dydt_.swap(dydt_new_);
      ++stats_.steps;
      if (locate_) prepare_step_start();
      if (observer) {
        publish();
        observer(t_, x_, v_);
      }
    }
  }

 private:
  // A step is taken again at most this often because a spring left its kink on the unexpected
  // side; beyond it the step is kept (only possible for a spring that hovers at its kink).
  static constexpr int kMaxRedos = 4;

  void publish() {
    const Index n = dofs();
    x_ = y_.head(n);
    v_ = y_.tail(n);
  }

  void check_state(const Vector& y, double t) const {
    const Index n = dofs();
    if (!y.allFinite()) {
      for (Index i = 0; i < 2 * n; ++i) {
        if (!std::isfinite(y[i])) {
          throw DivergenceError(fmt::format(
              "{}: the state is not finite at t = {:.17g}: {}[{}] = {}", name(), t,
              i < n ? "x" : "x'", i % n, y[i]));
        }
      }
    }
    const double x_max = y.head(n).cwiseAbs().maxCoeff();
    const double v_max = y.tail(n).cwiseAbs().maxCoeff();
    if (x_max > options_.divergence_bound || v_max > options_.divergence_bound) {
      throw DivergenceError(fmt::format(
          "{}: the motion left divergence_bound = {:g} at t = {:.17g}: max |x| = {:g}, max |x'| = "
          "{:g}",
          name(), options_.divergence_bound, t, x_max, v_max));
    }
  }

  // Kink location integrates each step with the active set frozen (GapRhs::freeze_modes): the
  // right-hand side is then one linear piece, smooth across the kinks, so the Runge-Kutta stages
  // never see a kink, not even the last stages of a step that ends on one (with the true
  // max(0, g) those stages sit within their own error of the kink and pick up a spurious force).
  // Until the first sign change of a g_j against its mode the frozen and the true right-hand
  // sides agree; the crossing is located on the frozen piece and the step redone to end there.
  //
  // At the start of a step each spring gets a mode (+1: acting, -1: slack) and is "armed" when
  // its gap is beyond the threshold on the mode's side. A spring within the threshold of its
  // kink is not armed: its sign is not trusted, its mode is a prediction (the side it moves to,
  // or after a located crossing the side it crossed into), and it becomes armed once it is
  // clearly on that side. Only armed springs raise events, so a just-located crossing is never
  // found again; an unarmed spring that ends clearly on the other side was mispredicted and the
  // step is taken again with its mode flipped.
  void prepare_step_start() {
    const Index n = dofs();
    const Index m = rhs_.spring_count();
    rhs_.gaps(y_, g_start_);
    rhs_.gap_scales(y_, threshold_);
    for (Index j = 0; j < m; ++j) {
      threshold_[j] = kOnKinkFactor * (options_.absolute_tolerance +
                                       options_.relative_tolerance * threshold_[j]);
    }
    bool predict = false;
    for (Index j = 0; j < m; ++j) {
      predict = predict || (event_side_[static_cast<std::size_t>(j)] == 0 &&
                            std::abs(g_start_[j]) <= threshold_[j]);
    }
    bool true_derivative = false;
    if (predict) {
      if (!derivative_valid_) {
        // The acceleration for the prediction, from the true right-hand side.
        rhs_.freeze_modes(nullptr);
        rhs_.evaluate(y_, dydt_, t_);
        rhs_.freeze_modes(mode_.data());
        true_derivative = true;
      }
      rhs_.gap_directional(y_, n, rate_start_);
      rhs_.gap_directional(dydt_, n, accel_start_);
    }
    const double h = options_.max_step > 0.0 ? std::min(dt_, options_.max_step) : dt_;
    bool changed = false;
    for (Index j = 0; j < m; ++j) {
      const auto k = static_cast<std::size_t>(j);
      const double g = g_start_[j];
      int mode = 0;
      if (event_side_[k] != 0) {
        mode = event_side_[k];
        armed_[k] = mode * g > threshold_[j];
      } else if (std::abs(g) > threshold_[j]) {
        mode = sign_of(g);
        armed_[k] = 1;
      } else {
        const double predicted = g + h * rate_start_[j] + 0.5 * h * h * accel_start_[j];
        mode = predicted > 0.0 ? 1 : -1;
        armed_[k] = 0;
      }
      changed = changed || mode != mode_[k];
      mode_[k] = mode;
      event_side_[k] = 0;
    }
    // dydt_ holds the right-hand side of the previous piece (or the true one): recompute it.
    if (changed || true_derivative) derivative_valid_ = false;
  }

  // After an accepted step from (t_, y_) to (t_new, y_new_) on the frozen piece: looks for the
  // earliest crossing inside the step. On an event, replaces t_new and y_new_ by the state at
  // the crossing.
  Outcome locate_kink(double& t_new, bool allow_redo) {
    const Index m = rhs_.spring_count();
    const double t0 = t_;
    const double t1 = t_new;
    const double h = t1 - t0;
    t_new_of_step_ = t1;
    scan_armed_ = armed_;
    g_a_ = g_start_;
    rhs_.gaps(y_new_, g_end_);
    if constexpr (!kFsal) {
      // Value, rate and acceleration of every gap at both ends for the Hermite guesses.
      const Index n = dofs();
      rhs_.gap_directional(y_, n, rate_start_);
      rhs_.gap_directional(dydt_, n, accel_start_);
      rhs_.gap_directional(y_new_, n, rate_end_);
      rhs_.gap_directional(dydt_new_, n, accel_end_);
    }
    double previous = t0;
    for (int i = 1; i <= kInteriorSamples + 1; ++i) {
      const bool at_end = i == kInteriorSamples + 1;
      const double theta = static_cast<double>(i) / (kInteriorSamples + 1);
      const double ts = at_end ? t1 : t0 + theta * h;
      bool confirmed = true;  // g_c_ holds values of the method, not a Hermite guess
      if (at_end) {
        g_c_ = g_end_;
      } else if constexpr (kFsal) {
        dense_gaps(ts, g_c_);
      } else {
        for (Index j = 0; j < m; ++j) {
          g_c_[j] = quintic_hermite(theta, g_start_[j], h * rate_start_[j],
                                    h * h * accel_start_[j], g_end_[j], h * rate_end_[j],
                                    h * h * accel_end_[j]);
        }
        confirmed = false;
      }
      Outcome outcome = classify(allow_redo);
      if constexpr (!kFsal) {
        if (outcome != Outcome::none && !confirmed) {
          step_gaps(ts, g_c_);
          y_bracket_.swap(y_tmp_);
          outcome = classify(allow_redo);
        }
      }
      if (outcome == Outcome::redo) {
        for (std::size_t k = 0; k < flip_.size(); ++k) {
          if (flip_[k] != 0) mode_[k] = -mode_[k];
        }
        return Outcome::redo;
      }
      if (outcome == Outcome::event) {
        g_b_ = g_c_;
        const double t_star = find_crossing(previous, ts);
        land(t_star, t1, t_new);
        return Outcome::event;
      }
      for (Index j = 0; j < m; ++j) {
        const auto k = static_cast<std::size_t>(j);
        if (scan_armed_[k] == 0 && mode_[k] * g_c_[j] > threshold_[j]) scan_armed_[k] = 1;
      }
      g_a_ = g_c_;
      previous = ts;
    }
    return Outcome::none;
  }

  // Compares the sample in g_c_ with the springs' modes: an armed spring on the other side of
  // its kink is an event candidate; an unarmed one clearly on the other side was mispredicted.
  Outcome classify(bool allow_redo) {
    bool event = false;
    bool redo = false;
    for (std::size_t k = 0; k < candidate_.size(); ++k) {
      const auto j = static_cast<Index>(k);
      const double e = mode_[k] * g_c_[j];
      candidate_[k] = scan_armed_[k] != 0 && e < 0.0;
      flip_[k] = allow_redo && scan_armed_[k] == 0 && e < -threshold_[j];
      event = event || candidate_[k] != 0;
      redo = redo || flip_[k] != 0;
    }
    return redo ? Outcome::redo : (event ? Outcome::event : Outcome::none);
  }

  bool crossed(const Vector& g) const {
    for (std::size_t k = 0; k < candidate_.size(); ++k) {
      if (candidate_[k] != 0 && mode_[k] * g[static_cast<Index>(k)] < 0.0) return true;
    }
    return false;
  }

  // The earliest crossing in (a, b] of the candidate springs, with g_a_ and g_b_ holding the
  // gaps at a (no candidate crossed) and b (some candidate crossed). Returns the final b: just
  // past the crossing, with every candidate that crossed there within half the threshold of its
  // kink.
  double find_crossing(double a, double b) {
    double weight_a = 1.0;
    double weight_b = 1.0;
    int last_move = 0;  // +1: b moved, -1: a moved
    double reference_width = b - a;
    int without_halving = 0;
    for (int iteration = 0; iteration < kMaxRootIterations; ++iteration) {
      bool converged = true;
      double c = b;
      for (std::size_t k = 0; k < candidate_.size(); ++k) {
        const auto j = static_cast<Index>(k);
        if (candidate_[k] == 0) continue;
        const double fb = mode_[k] * g_b_[j];
        if (fb >= 0.0) continue;
        if (-fb > 0.5 * threshold_[j]) converged = false;
        // Weighted regula falsi on this spring; the earliest estimate wins.
        const double fa = std::max(0.0, mode_[k] * g_a_[j]);
        const double estimate = a + (b - a) * (weight_a * fa) / (weight_a * fa - weight_b * fb);
        c = std::min(c, estimate);
      }
      if (converged) break;
      if (b - a <= 4.0 * std::numeric_limits<double>::epsilon() *
                       std::max(std::abs(a), std::abs(b))) {
        break;
      }
      // Bisection when the secant stalls (no halving of the bracket in three iterations) or
      // falls outside the open bracket.
      if (without_halving >= 3 || !(c > a && c < b)) c = 0.5 * (a + b);
      if (!(c > a && c < b)) break;
      evaluate_gaps(c, g_c_);
      if (crossed(g_c_)) {
        b = c;
        g_b_.swap(g_c_);
        if constexpr (!kFsal) y_bracket_.swap(y_tmp_);
        weight_a = last_move == 1 ? 0.5 * weight_a : 1.0;  // Illinois: a retained twice
        weight_b = 1.0;
        last_move = 1;
      } else {
        a = c;
        g_a_.swap(g_c_);
        weight_b = last_move == -1 ? 0.5 * weight_b : 1.0;
        weight_a = 1.0;
        last_move = -1;
      }
      if (b - a <= 0.5 * reference_width) {
        reference_width = b - a;
        without_halving = 0;
      } else {
        ++without_halving;
      }
    }
    return b;
  }

  // Ends the step at the located crossing t_star (<= t1) and records the springs that crossed.
  void land(double t_star, double t1, double& t_new) {
    for (std::size_t k = 0; k < candidate_.size(); ++k) {
      if (candidate_[k] != 0 && mode_[k] * g_b_[static_cast<Index>(k)] < 0.0) {
        event_side_[k] = -mode_[k];
        ++stats_.kink_events;
      }
    }
    if (t_star >= t1) return;  // the step already ends there
    if constexpr (kFsal) {
      // Redo the step from (t_, y_) so that it ends exactly on the kink.
      controlled_.stepper().do_step(SystemRef{&rhs_}, y_, dydt_, t_, y_new_, dydt_new_,
                                    t_star - t_);
    } else {
      // The one-step map's state at t_star, computed by the search. The derivative there
      // belongs to the next piece and is recomputed after the modes change.
      y_new_.swap(y_bracket_);
    }
    t_new = t_star;
  }

  // Gaps at time t inside the current step: on dopri5's continuous extension, or (rkf78) at the
  // end of one step of the method from (t_, y_) to t.
  void evaluate_gaps(double t, Vector& g) {
    if constexpr (kFsal) {
      dense_gaps(t, g);
    } else {
      step_gaps(t, g);
    }
  }

  void dense_gaps(double t, Vector& g) {
    // Uses the stages of the stepper's last do_step, which is the step being examined: nothing
    // may step between the accepted step and the end of the search.
    controlled_.stepper().calc_state(t, y_tmp_, y_, dydt_, t_, y_new_, dydt_new_, t_new_of_step_);
    rhs_.gaps(y_tmp_, g);
  }

  void step_gaps(double t, Vector& g) {
    controlled_.stepper().do_step(SystemRef{&rhs_}, y_, dydt_, t_, y_tmp_, t - t_);
    rhs_.gaps(y_tmp_, g);
  }

  ReferenceOptions options_;
  GapRhs rhs_;
  Controlled controlled_;
  bool locate_ = false;
  double t_ = 0.0;
  double dt_ = 0.0;
  double t_new_of_step_ = 0.0;
  Vector y_, dydt_, y_new_, dydt_new_, y_tmp_, y_bracket_;
  bool derivative_valid_ = false;  // dydt_ is the current piece's right-hand side at (t_, y_)
  Vector x_, v_;
  IntegratorStats stats_;
  // Kink location, one entry per spring.
  Vector g_start_, threshold_, g_a_, g_b_, g_c_, g_end_;
  Vector rate_start_, accel_start_, rate_end_, accel_end_;
  std::vector<int> mode_, armed_, scan_armed_, candidate_, flip_, event_side_;
};

}  // namespace

bool ReferenceOptions::is_valid(std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  if (method != RungeKuttaMethod::dopri5 && method != RungeKuttaMethod::rkf78) {
    *why = fmt::format("method = {} is not a known Runge-Kutta method", static_cast<int>(method));
    return false;
  }
  if (!std::isfinite(relative_tolerance) || relative_tolerance <= 0.0) {
    *why = fmt::format("relative_tolerance = {} must be positive and finite", relative_tolerance);
    return false;
  }
  if (!std::isfinite(absolute_tolerance) || absolute_tolerance <= 0.0) {
    *why = fmt::format("absolute_tolerance = {} must be positive and finite", absolute_tolerance);
    return false;
  }
  if (!std::isfinite(max_step) || max_step < 0.0) {
    *why = fmt::format("max_step = {} must be finite and non-negative (0: no limit)", max_step);
    return false;
  }
  if (!std::isfinite(initial_step) || initial_step <= 0.0) {
    *why = fmt::format("initial_step = {} must be positive and finite", initial_step);
    return false;
  }
  if (std::isnan(divergence_bound) || divergence_bound <= 0.0) {
    *why = fmt::format("divergence_bound = {} must be positive", divergence_bound);
    return false;
  }
  return true;
}

std::unique_ptr<Integrator> make_reference_integrator(const GapStructure& structure,
                                                      const ReferenceOptions& options) {
  structure.validate();
  std::string why;
  if (!options.is_valid(&why)) throw InputError("invalid reference integrator options: " + why);
  if (options.method == RungeKuttaMethod::dopri5) {
    return std::make_unique<RungeKuttaIntegrator<Dopri5>>(structure, options);
  }
  return std::make_unique<RungeKuttaIntegrator<Fehlberg78>>(structure, options);
}

RungeKuttaMethod parse_runge_kutta_method(const std::string& name) {
  if (name == "dopri5") return RungeKuttaMethod::dopri5;
  if (name == "rkf78") return RungeKuttaMethod::rkf78;
  throw InputError(fmt::format("method = \"{}\": the reference methods are dopri5 and rkf78", name));
}

}  // namespace pwl
