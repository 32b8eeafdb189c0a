// Grazing bifurcations located by continuation, against the exact solver's contact events and a
// closed form. On the gap oscillator x'' + 0.1 x' + x + 3 max(0, x − 1.5) = 0.5 sin θt the
// period-1 branch from θ = 0.8 to 2 is the linear harmonic response wherever it does not touch,
// so it grazes where that response's amplitude q / √((1 − θ²)² + (0.1 θ)²) equals the gap 1.5:
// once below resonance and once above (on the branch's way back from the hysteresis). That
// equation, solved by bisection on θ here, gives the grazing parameters; and 1e-6 to either side,
// the orbit (Newton on the exact solver) has no contact event in a period on the linear side and
// two on the other.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

// The zero of amplitude(θ) − 1.5 in [a, b], by bisection.
double linear_grazing(double a, double b) {
  const auto f = [](double theta) {
    return 0.5 / std::hypot(1 - theta * theta, 0.1 * theta) - 1.5;
  };
  const double fa = f(a);
  REQUIRE(fa * f(b) < 0);
  for (int i = 0; i < 200 && b - a > 1e-15; ++i) {
    const double m = 0.5 * (a + b);
    ((f(m) > 0) == (fa > 0) ? a : b) = m;
  }
  return 0.5 * (a + b);
}

// The contact events in one period of the orbit at θ, found by Newton from `guess`.
std::size_t events_per_period(double theta, const Vector& guess) {
  const analysis::PointCase point(pwl::test::hardening_oscillator(theta));
  StroboscopicMap map(point, MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  const PeriodicOrbit orbit = find_periodic_orbit(map, guess, options);
  return pwl::test::contact_events(point.structure, orbit.state, 0.0, point.period).size();
}

}  // namespace

TEST_CASE("grazing points of the gap oscillator's orbit branch are located to 1e-8", "[orbits]") {
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 0.8;
  o.end = 2.0;
  const ContinuationResult r =
      continue_periodic_orbit(analysis::PointModel(pwl::test::hardening_oscillator(0.8)), Vector::Zero(2), o);
  std::vector<Bifurcation> grazings;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.type == BifurcationType::grazing) grazings.push_back(b);
  }
  REQUIRE(grazings.size() == 2);
  std::sort(grazings.begin(), grazings.end(),
            [](const Bifurcation& a, const Bifurcation& b) { return a.parameter < b.parameter; });
  const double expected[2] = {linear_grazing(0.8, 1.0), linear_grazing(1.0, 2.0)};
  for (int i = 0; i < 2; ++i) {
    const Bifurcation& g = grazings[i];
    INFO("grazing " << i << " located at " << g.parameter << ", closed form " << expected[i]);
    CHECK(g.spring == 0);
    CHECK(g.at_largest_gap);
    measured("grazing " + std::to_string(i) + ": located - closed form", g.parameter - expected[i]);
    CHECK(std::abs(g.parameter - expected[i]) <= 1e-8);
    CHECK(std::abs(g.test_value) <= 1e-8);
    // Contact below the lower grazing point's parameter is absent, above the upper one too: the
    // linear side is away from resonance.
    const double linear_side = i == 0 ? -1.0 : 1.0;
    CHECK(events_per_period(g.parameter + linear_side * 1e-6, g.state) == 0);
    CHECK(events_per_period(g.parameter - linear_side * 1e-6, g.state) == 2);
  }
}
