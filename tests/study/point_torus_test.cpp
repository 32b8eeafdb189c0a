// A torus and an orbit locked on one, told apart by the study pipeline: the torus test (weighted
// Birkhoff averages, PointResult::torus_digits) says the points lie on a smooth closed curve in
// both cases; the rotation number says whether the curve carries an irrational rotation (a torus:
// quasi-periodic) or a fraction p/q whose period-q orbit Newton finds (period-q, beyond the period
// search's 64).
//
// The cases: the paper's 5-DOF chain (figure 5: ζ = 0.2, Δ̃ = 0) at α = 5 by the exact event-driven
// solver, 4000 points after 500 periods. At θ = 1.8 a torus; at θ = 1.81 an orbit of period 73
// locked on one (rotation 22/73). The truth, independent of the verdict: for the torus, its
// points 10000 periods later lie on the same curve (the same extent, the same rotation: not a
// transient) and λ1 by two nearby trajectories of the exact map is zero; for the locked orbit,
// Newton on the exact map at period 73 from the motion's last state, stable, the motion on it.
#include <catch2/catch.hpp>
#include <cmath>

#include "orbit_cases.hpp"
#include "study_cases.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

PointCase chain(double theta) { return PointCase(pwl::test::figure5_cell(5.0, theta)); }

PointSettings exact_record() {
  PointSettings s;
  s.transient_periods = 500;
  s.recorded_periods = 4000;
  s.refine_max_period = 150;
  s.method = MethodSettings{Method::exact};
  s.lyapunov_estimate = LyapunovEstimate::two_trajectories;
  return s;
}

}  // namespace

TEST_CASE("a torus is quasi-periodic: its points stay on one smooth curve", "[sweep_point][torus][release-only]") {
  const PointCase point = chain(1.8);
  pwl::test::StateRecorder recorder;
  const PointResult r = evaluate_point(point, Vector::Zero(10), exact_record(), &recorder);
  CHECK(r.regime == "quasi-periodic");
  pwl::test::measured("torus: digits", r.torus_digits);
  CHECK(r.torus_digits >= 5.0);
  REQUIRE(std::isfinite(r.rotation));

  // Truth: 10000 periods later the points lie on the same curve, with the same rotation number.
  orbits::StroboscopicMap exact(point, MethodSettings{Method::exact}, 1);
  Vector y = exact.advance(r.final_state, 10000);
  std::vector<Vector> later{y};
  for (int i = 1; i < 4000; ++i) later.push_back(y = exact.advance(y, 1));
  const WeightedBirkhoffResult again = weighted_birkhoff_test(pwl::test::as_rows(later));
  pwl::test::measured("torus: rotation 10000 periods later minus the record's",
                      again.rotation_number - r.rotation);
  CHECK(std::abs(again.rotation_number - r.rotation) < 1e-5);
  const Matrix before = pwl::test::as_rows(recorder.states), after = pwl::test::as_rows(later);
  const Vector extent_before = before.colwise().maxCoeff() - before.colwise().minCoeff();
  const Vector extent_after = after.colwise().maxCoeff() - after.colwise().minCoeff();
  CHECK((extent_after - extent_before).lpNorm<Eigen::Infinity>() <
        1e-3 * extent_before.lpNorm<Eigen::Infinity>());
  // And λ1 (two nearby trajectories of the exact map, the pipeline's estimate) is zero.
  CHECK(std::abs(r.lambda1) + r.lambda1_error < 0.005);
}

TEST_CASE("an orbit locked on a torus is its period, found from the rotation number",
          "[sweep_point][torus]") {
  const PointCase point = chain(1.81);
  const PointResult r = evaluate_point(point, Vector::Zero(10), exact_record());
  REQUIRE(r.regime == "period-73");
  CHECK(r.settle_periods == 0.0);
  pwl::test::measured("locked: torus digits", r.torus_digits);
  CHECK(r.torus_digits >= 5.0);
  CHECK(std::abs(73.0 * r.rotation - 22.0) < 1e-6);

  // Truth: Newton on the exact map at period 73, stable, the motion on it.
  orbits::StroboscopicMap exact(point, MethodSettings{Method::exact}, 1);
  orbits::ShootingOptions o;
  o.period = 73;
  const orbits::PeriodicOrbit orbit = orbits::find_periodic_orbit(exact, r.final_state, o);
  CHECK(orbit.period == 73);
  CHECK(orbit.stable());
  double nearest = std::numeric_limits<double>::infinity();
  Vector p = orbit.state;
  for (int j = 0; j < 73; ++j) {
    nearest = std::min(nearest, (r.final_state - p).lpNorm<Eigen::Infinity>());
    p = exact.advance(p, 1);
  }
  CHECK(nearest < 1e-7);
}
