// An orbit's minimal period (at_minimal_period, periodic_orbit.hpp). A period-k request can
// converge on an orbit of a shorter period: Newton on φ_{kT}(y) = y has every orbit of period m | k
// among its solutions. The case that calls for the check: a lightly damped structure whose
// complex pair of multipliers turns about p/k of a circle a period, so that the motion spirals
// onto the period-1 orbit and returns near itself every k periods.
//
//  - One mass with its gap never reached: the period-1 orbit is the harmonic response in closed
//    form, its multipliers exp(λT). Forced at θ = 3.5 ω_d the pair turns 2/7 of a circle a
//    period, so M^7 − I is far from singular and Newton at period 7 lands on the period-1 orbit:
//    minimal period 1, the state and the multipliers those of the closed form.
//  - Figure 4a's chain at θ = 1.1 has a genuine stable period-2 orbit and the unstable period-1
//    orbit it was born from: a period-2 request on the period-1 orbit reduces to 1, the period-2
//    orbit stays period 2, and a period-4 request on it reduces to 2 (not to 1).
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

TEST_CASE("a period-7 request on a slow spiral finds the period-1 orbit, minimal period 1",
          "[orbits]") {
  // m = 1, k = 4, c = 0.04: ω_n = 2, ζ = 0.01, ω_d = ω_n sqrt(1 − ζ²).
  GapStructure s = pwl::test::single_mass(1.0, 0.04, 4.0);
  const double wd = 2.0 * std::sqrt(1.0 - 0.01 * 0.01);
  const double omega = 3.5 * wd;
  s.loads.push_back({0, 0.5, omega, 0.0});
  s.springs.push_back({0, -1, 1.0, 10.0, 100.0});  // a stop 100 away: never reached
  const double T = 2 * M_PI / omega;
  StroboscopicMap map(analysis::PointCase(s, T), MethodSettings{Method::exact}, 1);

  const Vector expected = pwl::test::harmonic_response(s, omega);
  // The multipliers per period: exp(λT), λ = −ζω_n ± iω_d; |μ| = exp(−0.02 T) = 0.9964.
  const double modulus = std::exp(-0.02 * T);
  ShootingOptions options;
  options.period = 7;
  options.tolerance = 1e-12;
  const PeriodicOrbit seven = find_periodic_orbit(map, expected + Vector::Constant(2, 0.2), options);
  REQUIRE(seven.period == 7);
  // At period 7 the pair has turned twice round: μ^7 real and positive, |μ|^7.
  CHECK(seven.multipliers.largest_modulus() == Approx(std::pow(modulus, 7)).epsilon(1e-10));

  const PeriodicOrbit minimal = at_minimal_period(map, seven, options);
  CHECK(minimal.period == 1);
  const double error = (minimal.state - expected).lpNorm<Eigen::Infinity>();
  measured("minimal period: period-1 state against the harmonic response", error);
  CHECK(error <= 1e-11);
  REQUIRE(minimal.multipliers.values.size() == 2);
  for (const auto& mu : minimal.multipliers.values) {
    CHECK(std::abs(mu) == Approx(modulus).epsilon(1e-11));
    // 2/7 of a circle a period: arg μ = ±4π/7.
    CHECK(std::abs(std::arg(mu)) == Approx(4 * M_PI / 7).epsilon(1e-10));
  }

  // Period 6 (divisors 1, 2, 3): the same orbit, minimal period 1.
  options.period = 6;
  const PeriodicOrbit six = find_periodic_orbit(map, expected + Vector::Constant(2, 0.2), options);
  CHECK(at_minimal_period(map, six, options).period == 1);
}

TEST_CASE("a genuine period-2 orbit keeps its period; period 4 on it reduces to 2, not 1",
          "[orbits]") {
  StroboscopicMap map(analysis::PointCase(pwl::test::paper_case_at("4a", 1.1)),
                      MethodSettings{Method::exact}, 1);
  const auto points = pwl::test::poincare_points(map, Vector::Zero(10), 300, 2);
  REQUIRE((points[1] - points[0]).norm() > 0.1);  // the period-2 attractor

  ShootingOptions options;
  options.tolerance = 1e-12;
  // The unstable period-1 orbit between the attractor's two points, asked at period 2.
  options.period = 2;
  const PeriodicOrbit one_as_two = find_periodic_orbit(map, 0.5 * (points[0] + points[1]), options);
  const PeriodicOrbit one = at_minimal_period(map, one_as_two, options);
  CHECK(one.period == 1);
  CHECK(one.multipliers.values[0].real() < -1);  // the multiplier that doubled the period

  // The attractor itself: period 2, minimal.
  const PeriodicOrbit two = find_periodic_orbit(map, points[0], options);
  CHECK(at_minimal_period(map, two, options).period == 2);
  CHECK(two.stable());

  // Asked at period 4 from the same point: the period-2 orbit taken twice, reduced to 2.
  options.period = 4;
  const PeriodicOrbit four = find_periodic_orbit(map, points[0], options);
  const PeriodicOrbit reduced = at_minimal_period(map, four, options);
  CHECK(reduced.period == 2);
  const double distance = std::min((reduced.state - two.state).lpNorm<Eigen::Infinity>(),
                                   (map.advance(reduced.state, 1) - two.state).lpNorm<Eigen::Infinity>());
  measured("minimal period: period-4 request against the period-2 orbit", distance);
  CHECK(distance <= 1e-10);
  // Its multipliers at period 2 are those of the period-2 orbit.
  CHECK(reduced.multipliers.largest_modulus() ==
        Approx(two.multipliers.largest_modulus()).epsilon(1e-8));
}
