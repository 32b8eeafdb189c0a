// Transient chaos in the study pipeline (PointResult::chaotic_transient): a motion that wanders
// chaotically for thousands of periods and then settles on a periodic orbit is reported as the
// orbit, with the length of its chaotic transient; a long transient that is not chaotic (a slow
// spiral onto the orbit) and a short settling are not reported.
//
// The cases, from rest by the exact event-driven solver: the paper's 5-DOF chain (figure 5: ζ = 0.2,
// Δ̃ = 0) at α = 9, θ = 1.72, and one gap oscillator (α = 20, ζ = 0.05, Δ̃ = 0.5, Q = 1, θ = 2.2).
// Their truth, independent of the pipeline's search: Newton on the exact stroboscopic map finds
// the stable period-k orbit the motion ends on; λ1 by two nearby trajectories of the exact map
// over the first 300 periods is clearly positive; and the recorded motion stays far from that
// orbit, with no period, for a thousand periods first. How long a chaotic transient lasts depends
// on the start and on the integrator (a change of 1e-9 in the initial state moves it by a factor
// of up to 10), so the tests bound it loosely.
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "orbit_cases.hpp"
#include "study_cases.hpp"
#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/period_detection.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

PointCase chain(double alpha, double theta) { return PointCase(pwl::test::figure5_cell(alpha, theta)); }

using pwl::test::exact_record;

double distance_to_orbit(const Vector& y, const std::vector<Vector>& orbit) {
  double d = std::numeric_limits<double>::infinity();
  for (const Vector& p : orbit) d = std::min(d, (y - p).lpNorm<Eigen::Infinity>());
  return d;
}

// Evaluates `point` from rest by the exact solver (500 + 3000 periods) and checks its verdict
// (period-k after a chaotic transient of `least` to `most` periods) against the truth.
void check_chaotic_transient(const PointCase& point, int k, int least, int most) {
  const Vector rest = Vector::Zero(2 * point.structure.dofs());
  pwl::test::StateRecorder recorder;
  const PointResult r = evaluate_point(point, rest, exact_record(500, 3000), &recorder);
  REQUIRE(r.regime == fmt::format("period-{}", k));
  pwl::test::measured("chaotic transient (periods)", r.chaotic_transient);
  CHECK(r.chaotic_transient > least);
  CHECK(r.chaotic_transient < most);

  // Truth 1: Newton on the exact map from the last state finds a stable period-k orbit, and the
  // motion is on it.
  orbits::StroboscopicMap exact(point, MethodSettings{Method::exact}, 1);
  orbits::ShootingOptions o;
  o.period = k;
  const orbits::PeriodicOrbit orbit = orbits::find_periodic_orbit(exact, r.final_state, o);
  CHECK(orbit.period == k);
  CHECK(orbit.stable());
  std::vector<Vector> cycle{orbit.state};
  for (int j = 1; j < k; ++j) cycle.push_back(exact.advance(cycle.back(), 1));
  CHECK(distance_to_orbit(r.final_state, cycle) < 1e-8 * std::max(1.0, orbit.state.norm()));

  // Truth 2: the start is chaotic. λ1 by two nearby trajectories of the exact map from rest over
  // periods 50..300 (short enough that rounding, amplified about e^20, keeps the re-run on the
  // pipeline's own motion).
  TwoTrajectoryOptions l;
  l.transient = 50;
  l.iterations = 250;
  l.blocks = 5;
  l.separation = 1e-7;
  const StateMap map = [&](const Vector& y) { return exact.advance(y, 1); };
  const LyapunovResult early = largest_lyapunov_two_trajectories(map, rest, l);
  pwl::test::measured("exact λ1 over periods 50..300", early.largest());
  CHECK(early.largest() - early.error[0] > 0.02);

  // Truth 3: the recorded motion (periods 501 on) stays far from the orbit, with no period, for
  // its first 1000 periods.
  REQUIRE(recorder.states.size() == 3000);
  const std::vector<Vector> wandering(recorder.states.begin(), recorder.states.begin() + 1000);
  std::vector<double> distances;
  for (const Vector& y : wandering) distances.push_back(distance_to_orbit(y, cycle));
  std::sort(distances.begin(), distances.end());
  double size = 0.0;
  for (const Vector& p : cycle) size = std::max(size, p.lpNorm<Eigen::Infinity>());
  pwl::test::measured("closest approach to the orbit over periods 501..1500, of its size",
                      distances.front() / size);
  pwl::test::measured("median distance from the orbit over periods 501..1500, of its size",
                      distances[distances.size() / 2] / size);
  CHECK(distances.front() > 1e-4 * size);
  CHECK(distances[distances.size() / 2] > 1e-2 * size);
  CHECK(detect_period(wandering).period == 0);
}

}  // namespace

TEST_CASE("transient chaos that ends on a period-7 orbit of the chain is reported with its length",
          "[sweep_point][transient]") {
  // Measured: 2494 periods of transient chaos.
  check_chaotic_transient(chain(9.0, 1.72), 7, 1500, 3400);
}

TEST_CASE("transient chaos of one gap oscillator, ending on a period-8 orbit through the contact",
          "[sweep_point][transient]") {
  // x'' + 0.1 x' + x + 20 max(0, x − 0.5) = sin(2.2 t) from rest. Measured: 2018 periods.
  check_chaotic_transient(PointCase(pwl::test::one_mass(20.0, 0.05, 0.5, 1.0, 2.2)), 8, 1500, 3400);
}

TEST_CASE("a short settling and a slow spiral are not transient chaos", "[sweep_point][transient]") {
  // α = 9, θ = 1.7179 by the exact solver: period-6 within about 35 periods.
  const PointResult quick = evaluate_point(chain(9.0, 0.5 + 2.5 * 19 / 39.0), Vector::Zero(10),
                                           exact_record(200, 300));
  CHECK(quick.regime == "period-6");
  CHECK(quick.chaotic_transient == 0);

  // x'' + 0.001 x' + x + 1.5 max(0, x − 0.6) = 0.3 sin(0.8 t) spirals onto its period-1 orbit for
  // thousands of periods (point_refinement_test.cpp): long, but its λ1 is negative all along.
  pwl::test::GapOscillator g;
  g.zeta = 0.0005;
  g.q = 0.3;
  g.theta = 0.8;
  PointSettings s;
  s.transient_periods = 6000;
  s.recorded_periods = 200;
  const PointResult spiral = evaluate_point(g.point_case(), Vector::Zero(2), s);
  CHECK(spiral.regime == "period-1");
  CHECK(spiral.chaotic_transient == 0);
}
