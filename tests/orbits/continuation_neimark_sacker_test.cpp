// A Neimark–Sacker point on the paper's 5-DOF chain of figure 5 (α = 5, Δ̃ = 0, ζ = 0.2): its
// period-1 orbit at θ = 2.59 is unstable (two multipliers outside the unit circle) and has a
// complex pair just inside it, which crosses out near θ = 2.6056. Continuation in θ must detect
// that crossing, locate it (checked against a bisection on θ of the modulus of the complex pair
// of orbits found by plain Newton at tolerance 1e-13), and report the pair's multiplier on the
// circle; on either side of it the count of multipliers outside the circle differs by two.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

NondimensionalChain chain_at(double theta) { return pwl::test::paper_case_at("5", theta); }

PeriodicOrbit orbit_at(double theta, const Vector& guess) {
  StroboscopicMap map(analysis::PointCase(chain_at(theta)), MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  return find_periodic_orbit(map, guess, options);
}

// |μ| − 1 of the complex multiplier (Im μ > 0) nearest the unit circle.
double complex_pair_off_circle(const PeriodicOrbit& orbit) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const std::complex<double>& mu : orbit.multipliers.values) {
    if (!(mu.imag() > 1e-6)) continue;
    const double off = std::abs(mu) - 1.0;
    if (std::isnan(best) || std::abs(off) < std::abs(best)) best = off;
  }
  return best;
}

int outside_circle(const PeriodicOrbit& orbit) {
  int count = 0;
  for (const std::complex<double>& mu : orbit.multipliers.values) count += std::abs(mu) > 1.0;
  return count;
}

}  // namespace

TEST_CASE("figure 5's period-1 orbit has a Neimark-Sacker point where continuation says",
          "[orbits]") {
  StroboscopicMap map(analysis::PointCase(chain_at(2.59)), MethodSettings{Method::exact}, 1);
  const PeriodicOrbit start = find_periodic_orbit(map, map.advance(Vector::Zero(10), 200));
  REQUIRE(outside_circle(start) == 2);
  REQUIRE(complex_pair_off_circle(start) < 0);  // a complex pair just inside the circle

  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 2.59;
  o.end = 2.62;
  const ContinuationResult r =
      continue_periodic_orbit(analysis::PointModel(chain_at(2.59)), start.state, o);
  const Bifurcation* ns = nullptr;
  int count = 0;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.type == BifurcationType::neimark_sacker) {
      ns = &b;
      ++count;
    }
  }
  REQUIRE(count == 1);
  INFO("Neimark-Sacker point at theta = " << ns->parameter << ", multiplier " << ns->multiplier);
  CHECK(ns->located);
  CHECK(ns->period == 1);
  measured("Neimark-Sacker: |mu| - 1", std::abs(ns->multiplier) - 1.0);
  CHECK(std::abs(std::abs(ns->multiplier) - 1.0) <= 1e-6);
  CHECK(std::abs(ns->multiplier.imag()) > 0.1);  // a complex pair, not ±1

  // Independently: bisection on θ of |μ| − 1 of the complex pair of Newton's orbits.
  double a = ns->parameter - 2e-3, b = ns->parameter + 2e-3;
  const PeriodicOrbit below = orbit_at(a, ns->state), above = orbit_at(b, ns->state);
  const double fa = complex_pair_off_circle(below);
  REQUIRE(fa * complex_pair_off_circle(above) < 0);
  CHECK(std::abs(outside_circle(below) - outside_circle(above)) == 2);
  while (b - a > 1e-12) {
    const double m = 0.5 * (a + b);
    ((complex_pair_off_circle(orbit_at(m, ns->state)) > 0) == (fa > 0) ? a : b) = m;
  }
  measured("Neimark-Sacker: located - bisection", ns->parameter - 0.5 * (a + b));
  CHECK(std::abs(ns->parameter - 0.5 * (a + b)) <= 1e-10);  // the location tolerance
}
