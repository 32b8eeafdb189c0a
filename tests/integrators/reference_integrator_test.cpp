// The reference integrators against motions known in closed form: a forced damped linear
// oscillator, and a gap oscillator whose motion is piecewise harmonic with known half-periods.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "test_structures.hpp"

namespace {

using pwl::GapStructure;
using pwl::Matrix;
using pwl::ReferenceOptions;
using pwl::RungeKuttaMethod;
using pwl::Vector;

constexpr RungeKuttaMethod kMethods[] = {RungeKuttaMethod::dopri5, RungeKuttaMethod::rkf78};

ReferenceOptions options_for(RungeKuttaMethod method, bool locate, double tolerance) {
  ReferenceOptions o;
  o.method = method;
  o.locate_kinks = locate;
  o.relative_tolerance = tolerance;
  o.absolute_tolerance = tolerance;
  return o;
}

Vector scalar(double value) { return Vector::Constant(1, value); }

// A unit mass on a spring and a damper (test_structures.hpp).
GapStructure single_mass(double damping, double stiffness) {
  return pwl::test::single_mass(1.0, damping, stiffness);
}

// x'' + 2 ζ ω x' + ω² x = A sin(Ω t), x(0) = x0, x'(0) = v0, ζ < 1.
struct ForcedOscillator {
  double omega = 1.3, zeta = 0.05, big_omega = 0.7, amplitude = 0.8, x0 = 0.3, v0 = -0.2;

  GapStructure structure() const {
    GapStructure s = single_mass(2.0 * zeta * omega, omega * omega);
    s.loads.push_back({0, amplitude, big_omega, 0.0});
    return s;
  }
  // Particular solution B sin Ωt + D cos Ωt from the complex amplitude A / (ω² - Ω² + 2iζωΩ);
  // the homogeneous part e^{-ζωt} (c1 cos ω_d t + c2 sin ω_d t) matches the initial state.
  void at(double t, double& x, double& v) const {
    const double detuning = omega * omega - big_omega * big_omega;
    const double friction = 2.0 * zeta * omega * big_omega;
    const double denominator = detuning * detuning + friction * friction;
    const double b = amplitude * detuning / denominator;
    const double d = -amplitude * friction / denominator;
    const double wd = omega * std::sqrt(1.0 - zeta * zeta);
    const double c1 = x0 - d;
    const double c2 = (v0 - b * big_omega + zeta * omega * c1) / wd;
    const double decay = std::exp(-zeta * omega * t);
    const double ch = c1 * std::cos(wd * t) + c2 * std::sin(wd * t);
    const double ch_rate = -c1 * wd * std::sin(wd * t) + c2 * wd * std::cos(wd * t);
    x = decay * ch + b * std::sin(big_omega * t) + d * std::cos(big_omega * t);
    v = decay * (ch_rate - zeta * omega * ch) + b * big_omega * std::cos(big_omega * t) -
        d * big_omega * std::sin(big_omega * t);
  }
};

// x'' + x + α max(0, x) = 0 from x = -A, x' = 0: a quarter period π/2 on the slack side, half a
// period π/ω_c on the contact side (ω_c = sqrt(1 + α), amplitude A/ω_c by energy), another
// quarter π/2 back to -A. Period π + π/ω_c.
struct GapOscillator {
  double alpha = 2.0, amplitude = 1.0;

  double contact_frequency() const { return std::sqrt(1.0 + alpha); }
  double period() const { return M_PI + M_PI / contact_frequency(); }
  GapStructure structure() const {
    GapStructure s = single_mass(0.0, 1.0);
    s.springs.push_back({0, -1, 1.0, alpha, 0.0});
    return s;
  }
  void at(double t, double& x, double& v) const {
    const double wc = contact_frequency();
    const double tau = std::fmod(t, period());
    if (tau < M_PI / 2) {
      x = -amplitude * std::cos(tau);
      v = amplitude * std::sin(tau);
    } else if (tau < M_PI / 2 + M_PI / wc) {
      const double s = tau - M_PI / 2;
      x = amplitude / wc * std::sin(wc * s);
      v = amplitude * std::cos(wc * s);
    } else {
      const double s = tau - M_PI / 2 - M_PI / wc;
      x = -amplitude * std::sin(s);
      v = -amplitude * std::cos(s);
    }
  }
  // The kinks in (0, t_end]: contact begins at π/2 + kT and ends at π/2 + π/ω_c + kT.
  std::vector<double> crossings(double t_end) const {
    std::vector<double> times;
    for (int k = 0; k * period() <= t_end; ++k) {
      for (double offset : {M_PI / 2, M_PI / 2 + M_PI / contact_frequency()}) {
        const double t = k * period() + offset;
        if (t <= t_end) times.push_back(t);
      }
    }
    return times;
  }
  double energy(double x, double v) const {
    const double contact = std::max(0.0, x);
    return 0.5 * v * v + 0.5 * x * x + 0.5 * alpha * contact * contact;
  }
};

// Largest error in x and x' against the gap oscillator at `checkpoints` equally spaced times up to
// t_end.
double gap_oscillator_error(const GapOscillator& exact, pwl::Integrator& integrator, double t_end,
                            int checkpoints) {
  integrator.set_state(0.0, scalar(-exact.amplitude), scalar(0.0));
  double worst = 0.0;
  for (int k = 1; k <= checkpoints; ++k) {
    const double t = t_end * k / checkpoints;
    integrator.advance_to(t);
    double x = 0.0, v = 0.0;
    exact.at(t, x, v);
    worst = std::max({worst, std::abs(integrator.position()[0] - x),
                      std::abs(integrator.velocity()[0] - v)});
  }
  return worst;
}

}  // namespace

TEST_CASE("reference integrators reproduce a forced damped oscillator in closed form",
          "[reference]") {
  const ForcedOscillator exact;
  GapStructure with_spring = exact.structure();
  // A gap far beyond the motion (|x| stays below 1.5): the spring never acts.
  with_spring.springs.push_back({0, -1, 1.0, 7.0, 5.0});
  const double times[] = {0.5, 3.7, 12.0, 31.4, 50.0};
  for (const GapStructure& structure : {exact.structure(), with_spring}) {
    for (RungeKuttaMethod method : kMethods) {
      for (bool locate : {false, true}) {
        auto integrator = pwl::make_reference_integrator(structure, options_for(method, locate,
                                                                                1e-12));
        CAPTURE(integrator->name(), structure.spring_count());
        integrator->set_state(0.0, scalar(exact.x0), scalar(exact.v0));
        double largest = 0.0;
        long observed = 0;  // steps the observer was told about
        for (double t : times) {
          integrator->advance_to(t, [&](double, const Vector& x, const Vector&) {
            largest = std::max(largest, std::abs(x[0]));
            ++observed;
          });
          CAPTURE(t);
          REQUIRE(integrator->time() == t);
          double x = 0.0, v = 0.0;
          exact.at(t, x, v);
          CHECK(std::abs(integrator->position()[0] - x) < 1e-9);
          CHECK(std::abs(integrator->velocity()[0] - v) < 1e-9);
        }
        REQUIRE(largest < 1.5);
        const pwl::IntegratorStats stats = integrator->stats();
        CHECK(stats.kink_events == 0);
        // Every accepted step is reported to the observer once; a 5(4) or 7(8) pair takes at
        // least 6 right-hand sides per step (FSAL dopri5: 6, rkf78: 13).
        CHECK(stats.steps == observed);
        CHECK(stats.steps >= 5);
        CHECK(stats.rhs_evaluations >= 6 * stats.steps);
      }
    }
  }
}

TEST_CASE("kink-located integrators reproduce the gap oscillator and stop on every kink",
          "[reference]") {
  const GapOscillator exact;
  const double t_end = 10.3 * exact.period();
  const std::vector<double> kinks = exact.crossings(t_end);
  REQUIRE(kinks.size() == 20);
  for (RungeKuttaMethod method : kMethods) {
    auto integrator =
        pwl::make_reference_integrator(exact.structure(), options_for(method, true, 1e-12));
    CAPTURE(integrator->name());
    integrator->set_state(0.0, scalar(-exact.amplitude), scalar(0.0));
    std::vector<double> step_times, step_positions;
    const auto record = [&](double t, const Vector& x, const Vector&) {
      step_times.push_back(t);
      step_positions.push_back(x[0]);
    };
    for (int k = 1; k <= 10; ++k) {
      const double t = t_end * k / 10;
      integrator->advance_to(t, record);
      double x = 0.0, v = 0.0;
      exact.at(t, x, v);
      CAPTURE(t);
      CHECK(std::abs(integrator->position()[0] - x) < 1e-9);
      CHECK(std::abs(integrator->velocity()[0] - v) < 1e-9);
    }
    // Exactly one located event per kink: none missed, none found twice.
    CHECK(integrator->stats().kink_events == static_cast<long>(kinks.size()));
    CHECK(integrator->stats().steps == static_cast<long>(step_times.size()));
    // Some step ends on each kink, at the kink.
    for (double kink : kinks) {
      const auto nearest = std::min_element(step_times.begin(), step_times.end(),
                                            [&](double a, double b) {
                                              return std::abs(a - kink) < std::abs(b - kink);
                                            });
      CAPTURE(kink, *nearest);
      CHECK(std::abs(*nearest - kink) < 1e-9);
      CHECK(std::abs(step_positions[static_cast<std::size_t>(nearest - step_times.begin())]) <
            1e-9);
    }
  }
}

TEST_CASE("kink location handles a spring between two masses acting in the negative direction",
          "[reference]") {
  // Two unit masses, each on a unit spring to the ground, and a gap spring of stiffness α on
  // mass 1 against mass 0 with direction -1: g = x0 - x1. The relative motion r = x0 - x1 obeys
  // r'' + r + 2α max(0, r) = 0 (a gap oscillator with stiffness 2α) and x0 + x1 stays 0.
  const double alpha = 1.5;
  GapOscillator relative;
  relative.alpha = 2.0 * alpha;
  GapStructure s;
  s.mass = pwl::to_sparse(Matrix::Identity(2, 2));
  s.damping.resize(2, 2);
  s.stiffness = pwl::to_sparse(Matrix::Identity(2, 2));
  s.springs.push_back({1, 0, -1.0, alpha, 0.0});
  const double t_end = 5.6 * relative.period();
  for (RungeKuttaMethod method : kMethods) {
    auto integrator = pwl::make_reference_integrator(s, options_for(method, true, 1e-12));
    CAPTURE(integrator->name());
    Vector x0(2);
    x0 << -0.5, 0.5;
    integrator->set_state(0.0, x0, Vector::Zero(2));
    integrator->advance_to(t_end);
    double r = 0.0, rate = 0.0;
    relative.at(t_end, r, rate);
    const Vector& x = integrator->position();
    const Vector& v = integrator->velocity();
    CHECK(std::abs(x[0] - x[1] - r) < 1e-9);
    CHECK(std::abs(v[0] - v[1] - rate) < 1e-9);
    CHECK(std::abs(x[0] + x[1]) < 1e-9);
    CHECK(integrator->stats().kink_events == static_cast<long>(relative.crossings(t_end).size()));
  }
}

TEST_CASE("kink location finds brief contacts that begin and end within one step",
          "[reference]") {
  // Free vibration x = -cos t against a spring whose gap Δ = 1 - 1e-3 is barely reached: each
  // contact lasts 2φ/ω_c ≈ 0.089, shorter than the steps at loose tolerance (up to 0.3 for dopri5
  // and 0.95 for rkf78 at 1e-6), so the gap is open at both ends of the step that contains it.
  // In contact x'' + (1 + α) x = α Δ; entering at t1 = arccos(-Δ) with speed sqrt(1 - Δ²), the
  // motion about x_eq = α Δ / (1 + α) is symmetric, so it leaves after 2φ/ω_c with
  // tan φ = (sqrt(1 - Δ²)/ω_c) / (Δ - x_eq), and returns to x = -1, x' = 0 after
  // T = 2 t1 + 2φ/ω_c.
  const double alpha = 2.0, gap = 1.0 - 1e-3;
  GapStructure s = single_mass(0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, alpha, gap});
  const double wc = std::sqrt(1.0 + alpha);
  const double phi = std::atan2(std::sqrt(1.0 - gap * gap) / wc, gap - alpha * gap / (1.0 + alpha));
  const double period = 2.0 * std::acos(-gap) + 2.0 * phi / wc;
  const int periods = 50;
  for (RungeKuttaMethod method : kMethods) {
    for (double tolerance : {1e-6, 1e-10}) {
      auto integrator =
          pwl::make_reference_integrator(s, options_for(method, true, tolerance));
      CAPTURE(integrator->name());
      integrator->set_state(0.0, scalar(-1.0), scalar(0.0));
      integrator->advance_to(periods * period);
      CHECK(integrator->stats().kink_events == 2 * periods);
      if (tolerance == 1e-10) {
        CHECK(std::abs(integrator->position()[0] + 1.0) < 1e-7);
        CHECK(std::abs(integrator->velocity()[0]) < 1e-7);
      }
    }
  }
}

TEST_CASE("a motion that starts on a kink leaves it on the right piece", "[reference]") {
  // x'' + x + 3 max(0, x) = sin t from rest at x = 0 (g = g' = g'' = 0: the side it leaves to is
  // decided by g''' = 1). It stays in contact for t in (0, π), where x'' + 4 x = sin t gives
  // x = sin t (1 - cos t) / 3, x' = (cos t - cos 2t) / 3. A long first trial step makes an error
  // in the choice of piece visible (slack instead of contact over a step h costs ~ h^5/40).
  GapStructure s = single_mass(0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, 3.0, 0.0});
  s.loads.push_back({0, 1.0, 1.0, 0.0});
  for (RungeKuttaMethod method : kMethods) {
    for (bool locate : {false, true}) {
      ReferenceOptions o = options_for(method, locate, 1e-12);
      o.initial_step = 1.0;
      auto integrator = pwl::make_reference_integrator(s, o);
      CAPTURE(integrator->name());
      for (double t : {0.4, 1.5, 3.0}) {
        integrator->advance_to(t);
        CHECK(std::abs(integrator->position()[0] - std::sin(t) * (1.0 - std::cos(t)) / 3.0) <
              1e-10);
        CHECK(std::abs(integrator->velocity()[0] - (std::cos(t) - std::cos(2.0 * t)) / 3.0) <
              1e-10);
      }
      CHECK(integrator->stats().kink_events == 0);  // leaving the kink at t = 0 is no crossing
    }
  }
}

TEST_CASE("plain integration across the kinks is less accurate than kink location",
          "[reference]") {
  // Measured at tolerance 1e-12 over 100 periods (largest error at 100 checkpoints): dopri5
  // plain 5.2e-9 against 2.5e-10 kink-located; rkf78 plain 2.9e-4 (its long steps straddle the
  // kinks and its error estimate misjudges them) against 1.1e-10.
  const GapOscillator exact;
  const double t_end = 100.0 * exact.period();
  for (RungeKuttaMethod method : kMethods) {
    auto plain = pwl::make_reference_integrator(exact.structure(),
                                                options_for(method, false, 1e-12));
    auto located = pwl::make_reference_integrator(exact.structure(),
                                                  options_for(method, true, 1e-12));
    const double plain_error = gap_oscillator_error(exact, *plain, t_end, 100);
    const double located_error = gap_oscillator_error(exact, *located, t_end, 100);
    CAPTURE(plain->name(), plain_error, located_error);
    CHECK(located_error < 1e-9);
    CHECK(plain->stats().kink_events == 0);
    if (method == RungeKuttaMethod::dopri5) {
      CHECK(plain_error > 4.0 * located_error);
    } else {
      CHECK(plain_error > 1e3 * located_error);
    }
  }
}

TEST_CASE("kink-located integrators conserve the gap oscillator's energy", "[reference]") {
  const GapOscillator exact;
  const double e0 = exact.energy(-exact.amplitude, 0.0);
  for (RungeKuttaMethod method : kMethods) {
    auto integrator =
        pwl::make_reference_integrator(exact.structure(), options_for(method, true, 1e-12));
    CAPTURE(integrator->name());
    integrator->set_state(0.0, scalar(-exact.amplitude), scalar(0.0));
    double drift = 0.0;
    long observed = 0;
    integrator->advance_to(100.0 * exact.period(), [&](double, const Vector& x, const Vector& v) {
      drift = std::max(drift, std::abs(exact.energy(x[0], v[0]) - e0));
      ++observed;
    });
    CAPTURE(drift);
    CHECK(observed > 1000);
    CHECK(drift < 1e-9);
  }
}

TEST_CASE("kink-located integrators converge in proportion to the tolerance", "[reference]") {
  // A tolerance 100 times smaller gives an error about 100 times smaller (measured ratios
  // 81-94) when no step straddles a kink.
  const GapOscillator exact;
  const double t_end = 10.3 * exact.period();
  for (RungeKuttaMethod method : kMethods) {
    std::vector<double> errors;
    for (double tolerance : {1e-6, 1e-8, 1e-10, 1e-12}) {
      auto integrator = pwl::make_reference_integrator(exact.structure(),
                                                       options_for(method, true, tolerance));
      errors.push_back(gap_oscillator_error(exact, *integrator, t_end, 1));
    }
    for (std::size_t k = 1; k < errors.size(); ++k) {
      const double ratio = errors[k - 1] / errors[k];
      CAPTURE(static_cast<int>(method), k, errors[k - 1], errors[k], ratio);
      CHECK(ratio > 30.0);
      CHECK(ratio < 300.0);
    }
  }
}

TEST_CASE("dopri5 and rkf78 agree on the paper's 5-DOF case 4a", "[reference]") {
  const pwl::NondimensionalChain chain = pwl::paper_five_dof_case("4a");
  const GapStructure structure = pwl::make_chain(chain);
  auto dopri5 = pwl::make_reference_integrator(
      structure, options_for(RungeKuttaMethod::dopri5, true, 1e-12));
  auto rkf78 = pwl::make_reference_integrator(
      structure, options_for(RungeKuttaMethod::rkf78, true, 1e-12));
  double largest = 0.0;
  double difference = 0.0;
  for (int k = 1; k <= 20; ++k) {
    const double t = k * chain.period();
    dopri5->advance_to(t);
    rkf78->advance_to(t);
    largest = std::max(largest, dopri5->position().cwiseAbs().maxCoeff());
    difference = std::max({difference,
                           (dopri5->position() - rkf78->position()).cwiseAbs().maxCoeff(),
                           (dopri5->velocity() - rkf78->velocity()).cwiseAbs().maxCoeff()});
  }
  CAPTURE(difference, largest);
  CHECK(largest > 0.5);  // the masses really move (and the gaps, at 0, are crossed)
  CHECK(difference < 1e-8);
  CHECK(dopri5->stats().kink_events > 20);
  CHECK(dopri5->stats().kink_events == rkf78->stats().kink_events);
}

TEST_CASE("coupled mass matrices are inverted exactly, densely and sparsely", "[reference]") {
  // M = tridiag(1, 4, 1), K = κ M, f = M e_0 sin(Ωt): then x'' + κ x = e_0 sin(Ωt), so from rest
  // x_0 = (sin Ωt - (Ω/√κ) sin √κ t) / (κ - Ω²) and every other mass stays at rest. n = 3 takes
  // the dense Cholesky path, n = 120 the sparse one.
  const double kappa = 2.0, big_omega = 0.9;
  for (int n : {3, 120}) {
    Matrix m = Matrix::Zero(n, n);
    for (int i = 0; i < n; ++i) {
      m(i, i) = 4.0;
      if (i + 1 < n) m(i, i + 1) = m(i + 1, i) = 1.0;
    }
    GapStructure s;
    s.mass = pwl::to_sparse(m);
    s.stiffness = pwl::to_sparse(kappa * m);
    s.damping.resize(n, n);
    s.loads.push_back({0, 4.0, big_omega, 0.0});
    s.loads.push_back({1, 1.0, big_omega, 0.0});
    s.springs.push_back({0, -1, 1.0, 3.0, 10.0});  // never reached
    for (RungeKuttaMethod method : kMethods) {
      auto integrator = pwl::make_reference_integrator(s, options_for(method, false, 1e-12));
      CAPTURE(n, integrator->name());
      for (double t : {2.0, 9.5, 20.0}) {
        integrator->advance_to(t);
        const double root = std::sqrt(kappa);
        const double x0 = (std::sin(big_omega * t) - big_omega / root * std::sin(root * t)) /
                          (kappa - big_omega * big_omega);
        const double v0 = big_omega * (std::cos(big_omega * t) - std::cos(root * t)) /
                          (kappa - big_omega * big_omega);
        CHECK(std::abs(integrator->position()[0] - x0) < 1e-9);
        CHECK(std::abs(integrator->velocity()[0] - v0) < 1e-9);
        CHECK(integrator->position().tail(n - 1).cwiseAbs().maxCoeff() < 1e-9);
      }
    }
  }
}

TEST_CASE("advance_to lands on t_end, respects max_step and reports every step",
          "[reference]") {
  const ForcedOscillator exact;
  for (RungeKuttaMethod method : kMethods) {
    ReferenceOptions o = options_for(method, false, 1e-8);
    o.max_step = 0.05;
    o.initial_step = 1e-4;
    auto integrator = pwl::make_reference_integrator(exact.structure(), o);
    CAPTURE(integrator->name());
    std::vector<double> times{integrator->time()};
    Vector last_x;
    const auto record = [&](double t, const Vector& x, const Vector&) {
      times.push_back(t);
      last_x = x;
    };
    integrator->advance_to(3.3, record);
    integrator->advance_to(3.3, record);  // already there: no step
    integrator->advance_to(7.0 / 3.0 + 5.0, record);
    REQUIRE(integrator->time() == 7.0 / 3.0 + 5.0);
    REQUIRE(times.back() == integrator->time());
    CHECK(last_x == integrator->position());
    CHECK(integrator->stats().steps == static_cast<long>(times.size()) - 1);
    CHECK(integrator->stats().steps >= static_cast<long>((7.0 / 3.0 + 5.0) / 0.05));
    for (std::size_t k = 1; k < times.size(); ++k) {
      CHECK(times[k] > times[k - 1]);
      CHECK(times[k] - times[k - 1] <= 0.05 * (1.0 + 1e-12));
    }
    CHECK(std::any_of(times.begin(), times.end(), [](double t) { return t == 3.3; }));
  }
}

TEST_CASE("reference integrators name themselves after method, variant and tolerance",
          "[reference]") {
  const GapOscillator exact;
  CHECK(pwl::make_reference_integrator(exact.structure(),
                                       options_for(RungeKuttaMethod::dopri5, false, 1e-10))
            ->name() == "dopri5 (rtol 1e-10)");
  CHECK(pwl::make_reference_integrator(exact.structure(),
                                       options_for(RungeKuttaMethod::rkf78, true, 1e-12))
            ->name() == "rkf78 kink-located (rtol 1e-12)");
  CHECK(pwl::parse_runge_kutta_method("dopri5") == RungeKuttaMethod::dopri5);
  CHECK(pwl::parse_runge_kutta_method("rkf78") == RungeKuttaMethod::rkf78);
  CHECK_THROWS_AS(pwl::parse_runge_kutta_method("rk45"), pwl::InputError);
}

TEST_CASE("reference integrators reject invalid options and states", "[reference]") {
  const GapOscillator exact;
  std::string why;
  {
    ReferenceOptions o;
    REQUIRE(o.is_valid(&why));
    o.relative_tolerance = -1e-8;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("relative_tolerance") != std::string::npos);
    CHECK_THROWS_AS(pwl::make_reference_integrator(exact.structure(), o), pwl::InputError);
  }
  {
    ReferenceOptions o;
    o.absolute_tolerance = std::nan("");
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("absolute_tolerance") != std::string::npos);
  }
  {
    ReferenceOptions o;
    o.max_step = -0.1;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("max_step") != std::string::npos);
  }
  {
    ReferenceOptions o;
    o.initial_step = 0.0;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("initial_step") != std::string::npos);
  }
  {
    ReferenceOptions o;
    o.divergence_bound = 0.0;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("divergence_bound") != std::string::npos);
  }
  CHECK_THROWS_AS(pwl::make_reference_integrator(GapStructure{}, ReferenceOptions{}),
                  pwl::InputError);

  for (RungeKuttaMethod method : kMethods) {
    auto integrator =
        pwl::make_reference_integrator(exact.structure(), options_for(method, true, 1e-8));
    CHECK_THROWS_AS(integrator->set_state(0.0, Vector::Zero(2), Vector::Zero(1)),
                    pwl::InputError);
    CHECK_THROWS_AS(integrator->set_state(0.0, scalar(std::nan("")), scalar(0.0)),
                    pwl::InputError);
    CHECK_THROWS_AS(integrator->set_state(0.0, scalar(0.0), scalar(INFINITY)), pwl::InputError);
    CHECK_THROWS_AS(integrator->set_state(std::nan(""), scalar(0.0), scalar(0.0)),
                    pwl::InputError);
    integrator->set_state(1.0, scalar(-1.0), scalar(0.0));
    CHECK_THROWS_AS(integrator->advance_to(0.5), pwl::InputError);
    CHECK_THROWS_AS(integrator->advance_to(INFINITY), pwl::InputError);
  }
}

TEST_CASE("an unbounded motion raises DivergenceError at the divergence bound", "[reference]") {
  // Undamped resonance x'' + x = sin t from rest: x = (sin t - t cos t) / 2 grows like t / 2 and
  // first exceeds 5 near t = 10.
  GapStructure s = single_mass(0.0, 1.0);
  s.loads.push_back({0, 1.0, 1.0, 0.0});
  for (RungeKuttaMethod method : kMethods) {
    for (bool locate : {false, true}) {
      ReferenceOptions o = options_for(method, locate, 1e-10);
      o.divergence_bound = 5.0;
      auto integrator = pwl::make_reference_integrator(s, o);
      CAPTURE(integrator->name());
      try {
        integrator->advance_to(100.0);
        FAIL("no DivergenceError");
      } catch (const pwl::DivergenceError& e) {
        CHECK(std::string(e.what()).find("divergence_bound") != std::string::npos);
      }
      // The integrator keeps the last state inside the bound.
      CHECK(integrator->time() > 8.0);
      CHECK(integrator->time() < 12.0);
      CHECK(std::abs(integrator->position()[0]) <= 5.0);
    }
  }
}
