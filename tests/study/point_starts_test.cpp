// Coexisting attractors counted per point (PointSettings::starts): the hardening gap oscillator
// has two stable period-1 orbits inside the hysteresis of its resonance (θ = 1.2: the linear
// steady state in closed form and a contacting orbit, both confirmed by Newton on the exact map)
// and one outside it (θ = 0.6 and 2.0); the undamped resonance has only the attractor at infinity.
#include <catch2/catch.hpp>
#include <complex>

#include "orbit_cases.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

PointSettings with_starts(int starts) {
  PointSettings s;
  s.transient_periods = 300;
  s.recorded_periods = 100;
  s.starts = starts;
  return s;
}

}  // namespace

TEST_CASE("two attractors inside the hysteresis of the hardening oscillator, one outside",
          "[sweep_point][starts]") {
  const Vector rest = Vector::Zero(2);
  const PointCase inside(pwl::test::hardening_oscillator(1.2));
  const PointResult counted = evaluate_point(inside, rest, with_starts(8));
  CHECK(counted.attractors == 2);
  // The point's own columns are those of its own start.
  const PointResult alone = evaluate_point(inside, rest, with_starts(1));
  CHECK(alone.attractors == 0);
  CHECK(counted.regime == alone.regime);
  CHECK(counted.lambda1 == alone.lambda1);
  CHECK(counted.final_state == alone.final_state);
  // Reproducible: the same starts every time.
  CHECK(indicator_cells(evaluate_point(inside, rest, with_starts(8))) == indicator_cells(counted));

  // The truth at θ = 1.2: two stable period-1 orbits of the exact map, the linear steady state
  // (closed form, x = Im(Q e^{iθt} / (1 − θ² + i ζ θ))) and one beyond the gap.
  orbits::StroboscopicMap exact(inside, MethodSettings{Method::exact}, 1);
  const std::complex<double> H = 1.0 / std::complex<double>(1.0 - 1.44, 0.1 * 1.2);
  Vector linear(2);
  linear << 0.5 * H.imag(), 0.5 * 1.2 * H.real();
  Vector contacting_guess(2);
  contacting_guess << -4.66, 0.72;  // the basin test's attractor at t = 0
  const orbits::PeriodicOrbit small = orbits::find_periodic_orbit(exact, linear);
  const orbits::PeriodicOrbit large = orbits::find_periodic_orbit(exact, contacting_guess);
  CHECK(small.stable());
  CHECK(large.stable());
  CHECK((small.state - large.state).norm() > 1.0);

  for (double theta : {0.6, 2.0}) {
    INFO("θ = " << theta);
    const PointResult one =
        evaluate_point(PointCase(pwl::test::hardening_oscillator(theta)), rest, with_starts(8));
    CHECK(one.regime == "period-1");
    CHECK(one.attractors == 1);
  }
}

TEST_CASE("the undamped resonance reaches only the attractor at infinity", "[sweep_point][starts]") {
  const NondimensionalChain c = pwl::test::undamped_resonance();
  PointSettings s = with_starts(4);
  s.transient_periods = 100;
  s.recorded_periods = 200;
  const PointResult r = evaluate_point(PointCase(c), Vector::Zero(2), s);
  CHECK(r.regime == "unbounded");
  CHECK(r.attractors == 1);
}

TEST_CASE("the number of starts is checked and described", "[sweep_point][starts]") {
  PointSettings s;
  std::string why;
  s.starts = 0;
  CHECK_FALSE(s.is_valid(1, &why));
  CHECK(why.find("starts = 0 must be in 1..1000") != std::string::npos);
  s.starts = 1;
  CHECK(s.describe().find("starts") == std::string::npos);
  s.starts = 8;
  CHECK(s.describe().find("starts = 8\n") != std::string::npos);
}
