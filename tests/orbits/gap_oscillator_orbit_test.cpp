// The period-1 orbit of the single gap oscillator
//
//     x'' + 2ζ x' + x + α max(0, x − Δ) = q sin(θ t)
//
// with one contact interval per period, in closed form piece by piece: while free the motion is
// the underdamped free mode plus the harmonic response, while in contact the stiffer mode plus its
// harmonic response and the static preload αΔ/(1 + α). The unknowns are the times t_in, t_out at
// which x crosses Δ and the speeds v_in, v_out there; the four matching equations (each piece
// started at its crossing ends at the next crossing, at x = Δ, with the speed it started the
// other with) are solved here by Newton with a finite-difference Jacobian. The orbit, its contact
// times and its monodromy (the product of the two pieces' 2x2 transition matrices) are then
// compared with find_periodic_orbit on the exact solver, and the PIM's orbit with its O(η²)
// convergence to it.
#include <Eigen/LU>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>

#include "orbit_cases.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "test_series.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::GapOscillator;
using pwl::test::measured;

namespace {

// One linear piece: u'' + 2ζ u' + ω0² u = c0 + q sin(θ t).
struct Piece {
  double zeta, omega0_sq, c0, q, theta;

  double omega_d() const { return std::sqrt(omega0_sq - zeta * zeta); }
  // The particular solution and its derivative at t.
  std::array<double, 2> particular(double t) const {
    const std::complex<double> X =
        q / std::complex<double>(omega0_sq - theta * theta, 2 * zeta * theta);
    const std::complex<double> e = std::polar(1.0, theta * t);
    return {c0 / omega0_sq + (X * e).imag(), (std::complex<double>(0, theta) * X * e).imag()};
  }
  // The transition matrix of the homogeneous motion over τ.
  Eigen::Matrix2d transition(double tau) const {
    const double wd = omega_d(), c = std::cos(wd * tau), s = std::sin(wd * tau);
    Eigen::Matrix2d P;
    P << c + zeta / wd * s, s / wd, -omega0_sq / wd * s, c - zeta / wd * s;
    return std::exp(-zeta * tau) * P;
  }
  // The state at t1 from (x, v) at t0.
  Eigen::Vector2d flow(double t0, const Eigen::Vector2d& y, double t1) const {
    const auto p0 = particular(t0), p1 = particular(t1);
    const Eigen::Vector2d u = transition(t1 - t0) * Eigen::Vector2d(y(0) - p0[0], y(1) - p0[1]);
    return {u(0) + p1[0], u(1) + p1[1]};
  }
};

struct ClosedFormOrbit {
  double t_in = 0, t_out = 0, v_in = 0, v_out = 0;  // 0 <= t_in < T, t_in < t_out < t_in + T
  Vector state;                                     // at t = 0
  Matrix monodromy;                                 // over [0, T]
  double residual = 0;                              // of the matching equations
  double max_x = 0, min_x = 0;                      // over the orbit (x' = 0 in contact, free)
};

// The extreme of x on a piece started at (Δ, v0) at t0, where x' changes sign in (t0, t1): by
// bisection on x'.
double piece_extreme(const Piece& piece, double t0, double v0, double t1, double gap) {
  const auto speed = [&](double t) { return piece.flow(t0, {gap, v0}, t)(1); };
  double a = t0, b = t1;
  const double sa = speed(a + 1e-9 * (b - a));
  REQUIRE(sa * speed(b - 1e-9 * (b - a)) < 0);
  for (int i = 0; i < 200 && b - a > 1e-15 * std::max(1.0, std::abs(b)); ++i) {
    const double m = 0.5 * (a + b);
    ((speed(m) > 0) == (sa > 0) ? a : b) = m;
  }
  return piece.flow(t0, {gap, v0}, 0.5 * (a + b))(0);
}

ClosedFormOrbit closed_form_orbit(const GapOscillator& g, std::array<double, 4> z) {
  const Piece free{g.zeta, 1.0, 0.0, g.q, g.theta};
  const Piece contact{g.zeta, 1.0 + g.alpha, g.alpha * g.gap, g.q, g.theta};
  const double T = g.period(), D = g.gap;
  // z = (t_in, t_out, v_in, v_out)
  const auto equations = [&](const std::array<double, 4>& u) {
    const Eigen::Vector2d a = contact.flow(u[0], {D, u[2]}, u[1]);
    const Eigen::Vector2d b = free.flow(u[1], {D, u[3]}, u[0] + T);
    return Eigen::Vector4d(a(0) - D, a(1) - u[3], b(0) - D, b(1) - u[2]);
  };
  Eigen::Vector4d F = equations(z);
  for (int it = 0; it < 50 && F.lpNorm<Eigen::Infinity>() > 1e-15; ++it) {
    Eigen::Matrix4d J;
    for (int k = 0; k < 4; ++k) {
      const double h = 1e-7 * std::max(1.0, std::abs(z[k]));
      auto zp = z, zm = z;
      zp[k] += h;
      zm[k] -= h;
      J.col(k) = (equations(zp) - equations(zm)) / (2 * h);
    }
    const Eigen::Vector4d d = J.partialPivLu().solve(-F);
    // Damped: halve until the residual decreases.
    double lambda = 1;
    for (; lambda > 1e-3; lambda /= 2) {
      auto trial = z;
      for (int k = 0; k < 4; ++k) trial[k] += lambda * d(k);
      const Eigen::Vector4d Ft = equations(trial);
      if (Ft.lpNorm<Eigen::Infinity>() < F.lpNorm<Eigen::Infinity>()) {
        z = trial;
        F = Ft;
        break;
      }
    }
    if (lambda <= 1e-3) break;
  }
  ClosedFormOrbit o;
  o.residual = F.lpNorm<Eigen::Infinity>();
  // Normalise t_in into [0, T).
  const double shift = T * std::floor(z[0] / T);
  o.t_in = z[0] - shift;
  o.t_out = z[1] - shift;
  o.v_in = z[2];
  o.v_out = z[3];
  Eigen::Vector2d y0;
  Eigen::Matrix2d M;
  if (o.t_out < T) {
    // t = 0 is in the free piece that starts at t_out − T.
    y0 = free.flow(o.t_out - T, {D, o.v_out}, 0.0);
    M = free.transition(T - o.t_out) * contact.transition(o.t_out - o.t_in) *
        free.transition(o.t_in);
  } else {
    // t = 0 (= T) is inside the contact that starts at t_in.
    y0 = contact.flow(o.t_in, {D, o.v_in}, T);
    M = contact.transition(T - o.t_in) * free.transition(o.t_in - (o.t_out - T)) *
        contact.transition(o.t_out - T);
  }
  o.state = Vector(2);
  o.state << y0(0), y0(1);
  o.max_x = piece_extreme(contact, o.t_in, o.v_in, o.t_out, D);
  o.min_x = piece_extreme(free, o.t_out, o.v_out, o.t_in + T, D);
  o.monodromy = M;
  return o;
}

// A seed for the matching equations from the linear response x = A sin(θt + φ) alone (no orbit
// computed by the library): its crossings of Δ and its speeds there.
std::array<double, 4> linear_seed(const GapOscillator& g) {
  const std::complex<double> X =
      g.q / std::complex<double>(1 - g.theta * g.theta, 2 * g.zeta * g.theta);
  const double A = std::abs(X), phi = std::arg(X);
  REQUIRE(A > g.gap);
  const double s = std::asin(g.gap / A);  // θ t + φ = s (rising), π − s (falling)
  const double t_in = (s - phi) / g.theta, t_out = (M_PI - s - phi) / g.theta;
  const double v = A * g.theta * std::cos(s);
  return {t_in, t_out, v, -v};
}

GapOscillator the_oscillator() {
  GapOscillator g;
  g.zeta = 0.05;
  g.alpha = 1.5;
  g.gap = 0.6;
  g.q = 0.3;
  g.theta = 0.8;
  return g;
}

}  // namespace

TEST_CASE("the gap oscillator's period-1 orbit matches its closed form piece by piece",
          "[orbits]") {
  const GapOscillator g = the_oscillator();
  const ClosedFormOrbit cf = closed_form_orbit(g, linear_seed(g));
  REQUIRE(cf.residual <= 1e-13);
  REQUIRE(cf.v_in > 0);
  REQUIRE(cf.v_out < 0);
  const double T = g.period();

  StroboscopicMap map(g.point_case(), MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  const PeriodicOrbit orbit = find_periodic_orbit(map, Vector::Zero(2), options);
  INFO("closed form " << cf.state.transpose() << ", shooting " << orbit.state.transpose());
  const double state_error = (orbit.state - cf.state).lpNorm<Eigen::Infinity>();
  measured("gap oscillator orbit vs closed form", state_error);
  CHECK(state_error <= 1e-9);

  // The exact solver's contact times along the orbit: one contact interval, at t_in and t_out.
  const auto events = pwl::test::contact_events(g.structure(), orbit.state, 0.0, T);
  REQUIRE(events.size() == 2);
  double t_in = -1, t_out = -1;
  for (const auto& e : events) (e.touching ? t_in : t_out) = e.t;
  REQUIRE(t_in >= 0);
  REQUIRE(t_out >= 0);
  if (t_out < t_in) t_out += T;  // the contact spans t = T
  INFO("t_in " << t_in << " vs " << cf.t_in << ", t_out " << t_out << " vs " << cf.t_out);
  const double time_error = std::max(std::abs(t_in - cf.t_in), std::abs(t_out - cf.t_out));
  measured("gap oscillator contact times", time_error);
  CHECK(time_error <= 1e-9);

  const double monodromy_error = (orbit.monodromy - cf.monodromy).lpNorm<Eigen::Infinity>();
  INFO("monodromy\n" << orbit.monodromy << "\nclosed form\n" << cf.monodromy);
  measured("gap oscillator monodromy", monodromy_error);
  CHECK(monodromy_error <= 1e-9);
  // det M = exp(−2ζ T) (trace of the state matrix is −2ζ in both pieces).
  CHECK(orbit.monodromy.determinant() == Approx(std::exp(-2 * g.zeta * T)).epsilon(1e-12));
}

TEST_CASE(
    "the PIM's orbit of the gap oscillator is within its second-order error of the closed form",
    "[orbits]") {
  const GapOscillator g = the_oscillator();
  const ClosedFormOrbit cf = closed_form_orbit(g, linear_seed(g));
  REQUIRE(cf.residual <= 1e-13);
  // The constant of the PIM's error depends on where the two kinks fall inside their steps (their
  // contributions have opposite signs and partly cancel), so pairwise ratios scatter between 1 and
  // 8; the error times (T/η)² stays below about 1.2 from 100 to 6400 steps, and the
  // least-squares slope over five halvings is 2 (1.99).
  std::vector<double> steps_list, errors;
  for (int steps : {100, 200, 400, 800, 1600, 3200}) {
    StroboscopicMap map(g.point_case(), MethodSettings{Method::pim}, steps);
    const PeriodicOrbit orbit = find_periodic_orbit(map, Vector::Zero(2));
    const double error = (orbit.state - cf.state).lpNorm<Eigen::Infinity>();
    measured("PIM orbit error at T/" + std::to_string(steps), error);
    INFO("steps " << steps << ", error " << error);
    CHECK(error * steps * steps <= 1.5);
    steps_list.push_back(g.period() / steps);
    errors.push_back(error);
  }
  const double order = pwl::test::fitted_order(steps_list, errors);
  measured("PIM orbit fitted order", order);
  CHECK(order > 1.8);
  CHECK(order < 2.5);
  CHECK(errors.back() < 1e-7);
}

TEST_CASE("the switching PIM's orbit of the gap oscillator converges at high order", "[orbits]") {
  // Its order is d + 3 = 5 with the default force degree: the error drops by about 2^5 per
  // halving of η, to rounding by T/400.
  const GapOscillator g = the_oscillator();
  const ClosedFormOrbit cf = closed_form_orbit(g, linear_seed(g));
  REQUIRE(cf.residual <= 1e-13);
  std::vector<double> errors;
  for (int steps : {100, 200, 400}) {
    StroboscopicMap map(g.point_case(), MethodSettings{Method::pim_switching}, steps);
    ShootingOptions options;
    options.tolerance = 1e-13;
    const PeriodicOrbit orbit = find_periodic_orbit(map, Vector::Zero(2), options);
    errors.push_back((orbit.state - cf.state).lpNorm<Eigen::Infinity>());
    measured("switching PIM orbit error at T/" + std::to_string(steps), errors.back());
  }
  INFO("errors " << errors[0] << " " << errors[1] << " " << errors[2]);
  CHECK(errors[0] < 1e-9);
  CHECK(errors[0] / errors[1] > 16);
  CHECK(errors[2] < 1e-12);
}

TEST_CASE("the gap oscillator's orbit profile has the closed form's extremes", "[orbits]") {
  // The largest x lies inside the contact, the smallest in the free flight: each where the closed
  // form's x' vanishes. The exact solver's gap extremes are refined on the motion (to rounding);
  // its displacement extremes and the PIM's come from cubic Hermite interpolation of the samples,
  // O(h⁴).
  const GapOscillator g = the_oscillator();
  const ClosedFormOrbit cf = closed_form_orbit(g, linear_seed(g));
  REQUIRE(cf.residual <= 1e-13);
  ShootingOptions options;
  options.tolerance = 1e-13;
  {
    StroboscopicMap map(g.point_case(), MethodSettings{Method::exact}, 1);
    const PeriodicOrbit orbit = find_periodic_orbit(map, Vector::Zero(2), options);
    const OrbitProfile p = orbit_profile(map, orbit.state, 1, 256);
    INFO("max x " << p.max_position(0) << " vs " << cf.max_x << ", min x " << p.min_position(0)
                  << " vs " << cf.min_x);
    measured("exact profile: max gap error", p.max_gap(0) - (cf.max_x - g.gap));
    measured("exact profile: min gap error", p.min_gap(0) - (cf.min_x - g.gap));
    measured("exact profile: max x error", p.max_position(0) - cf.max_x);
    CHECK(std::abs(p.max_gap(0) - (cf.max_x - g.gap)) <= 1e-12);
    CHECK(std::abs(p.min_gap(0) - (cf.min_x - g.gap)) <= 1e-12);
    CHECK(std::abs(p.max_position(0) - cf.max_x) <= 1e-8);
    CHECK(std::abs(p.min_position(0) - cf.min_x) <= 1e-8);
    CHECK(p.amplitude(0) == Approx(std::max(cf.max_x, -cf.min_x)).epsilon(1e-8));
  }
  {
    StroboscopicMap map(g.point_case(), MethodSettings{Method::pim_switching}, 400);
    const PeriodicOrbit orbit = find_periodic_orbit(map, Vector::Zero(2), options);
    const OrbitProfile p = orbit_profile(map, orbit.state, 1);
    measured("switching PIM profile (T/400): max gap error", p.max_gap(0) - (cf.max_x - g.gap));
    CHECK(std::abs(p.max_gap(0) - (cf.max_x - g.gap)) <= 1e-8);
    CHECK(std::abs(p.min_gap(0) - (cf.min_x - g.gap)) <= 1e-8);
  }
}
