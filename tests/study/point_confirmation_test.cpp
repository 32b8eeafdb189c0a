// The confirmation by a method whose error cannot move the verdict (confirmation_stage.cpp),
// against Newton on the exact event-driven map and the exact motion integrated out.
//
//  - Figure 5's chain at α = 14, θ = 0.6923: the PIM at T/200 is on a period-2 orbit of its own
//    map (its record repeats to 1e-11 every 2 periods, and Newton on its map finds the orbit at
//    minimal period 2): the step has moved the period doubling. The exact map has no period-2
//    orbit there: Newton on it at period 2 from the same state lands on its stable period-1 orbit,
//    whose multiplier near −1 (|μ| = 0.984) makes the exact motion look period-2 for a while.
//    With the ladder's confirmation the verdict is period-1, decided by the exact solver; the
//    exact motion integrated further settles on period 1 by the record's own search.
//  - α = 10, θ = 1.9 with the PIM at a coarse T/18: the step makes the period-1 orbit stable; on the
//    exact map it is unstable and the motion is a torus, which decides.
//  - A verdict the exact map shares is confirmed by Newton alone (no second motion): figure 4a.
//  - Beyond 20 masses the switching PIM is the accurate method; the exact solver never is.
#include <catch2/catch.hpp>
#include <cmath>
#include <stdexcept>

#include "orbit_cases.hpp"
#include "study_cases.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

PointSettings record(int transient, int recorded, Method method = Method::pim) {
  PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = recorded;
  s.method = MethodSettings{method};
  return s;
}

}  // namespace

TEST_CASE("a period the PIM's step makes is decided by the exact map", "[sweep_point][confirmation]") {
  const PointCase point(pwl::test::figure5_cell(14.0, 0.5 + 2.5 * 3 / 39.0));
  const Vector rest = Vector::Zero(10);
  PointSettings s = record(500, 500);
  const PointResult pim = evaluate_point(point, rest, s);
  REQUIRE(pim.regime == "period-2");
  CHECK(pim.decided_by == "pim");

  // Truth 1: the PIM's map has a period-2 orbit there (minimal period 2), the exact map does not:
  // Newton on it at period 2 from the same state finds its period-1 orbit, stable.
  orbits::ShootingOptions two;
  two.period = 2;
  orbits::StroboscopicMap pim_map(point, s.method_for(point.period), s.steps_per_period);
  const orbits::PeriodicOrbit pim_orbit = orbits::at_minimal_period(
      pim_map, orbits::find_periodic_orbit(pim_map, pim.final_state, two), two);
  CHECK(pim_orbit.period == 2);
  orbits::StroboscopicMap exact_map(point, MethodSettings{Method::exact}, 1);
  const orbits::PeriodicOrbit exact_orbit = orbits::at_minimal_period(
      exact_map, orbits::find_periodic_orbit(exact_map, pim.final_state, two), two);
  CHECK(exact_orbit.period == 1);
  CHECK(exact_orbit.stable());

  // The ladder's confirmation: Newton on the exact map at 2 finds another orbit, so the exact
  // motion from rest decides, and its own Newton check says period-1.
  s.check_periods = true;
  s.confirm = Confirmation::regular;
  const PointResult confirmed = evaluate_point(point, rest, s);
  CHECK(confirmed.regime == "period-1");
  CHECK(confirmed.minimal_period == 1);
  CHECK(confirmed.record_period == 2);
  CHECK(confirmed.decided_by == "exact");
  CHECK(confirmed.confirmed_by == "exact");
  CHECK(confirmed.confirmation == "motion");
  CHECK(confirmed.multiplier == Approx(exact_orbit.multipliers.largest_modulus()).epsilon(1e-8));

  // Truth 2: the exact motion, integrated 300 periods further, repeats every period.
  const PointResult later = evaluate_point(point, rest, record(1300, 200, Method::exact));
  CHECK(later.regime == "period-1");
}

TEST_CASE("a coarse PIM step that makes an unstable orbit stable is decided by the exact map",
          "[sweep_point][confirmation]") {
  // Figure 5's chain at α = 10, θ = 1.9 with the PIM at T/18 (η ω_max = 0.68: warned, accepted):
  // the motion is on a period-1 orbit (|μ| = 0.944 on the PIM's map). The exact map has that orbit
  // but unstable (a complex pair at |μ| = 1.06), and the exact motion is on a torus around it.
  const PointCase point(pwl::test::figure5_cell(10.0, 1.9));
  const Vector rest = Vector::Zero(10);
  PointSettings s = record(500, 500);
  s.steps_per_period = 18;
  const PointResult pim = evaluate_point(point, rest, s);
  REQUIRE(pim.regime == "period-1");

  // Truth: Newton on the exact map from the PIM's state finds the period-1 orbit, unstable.
  orbits::StroboscopicMap exact_map(point, MethodSettings{Method::exact}, 1);
  const orbits::PeriodicOrbit exact_orbit = orbits::find_periodic_orbit(exact_map, pim.final_state);
  CHECK(exact_orbit.period == 1);
  CHECK_FALSE(exact_orbit.stable());
  pwl::test::measured("exact period-1 orbit: largest |mu|", exact_orbit.multipliers.largest_modulus());

  s.check_periods = true;
  s.confirm = Confirmation::regular;
  const PointResult confirmed = evaluate_point(point, rest, s);
  CHECK(confirmed.regime == "quasi-periodic");
  CHECK(confirmed.decided_by == "exact");
  CHECK(confirmed.confirmation == "motion");
  // And the exact motion from rest, recorded alone: no period, and the same verdict.
  const PointResult exact = evaluate_point(point, rest, record(1000, 1000, Method::exact));
  CHECK(exact.period == 0);
  CHECK(exact.regime == "quasi-periodic");
}

TEST_CASE("a verdict the exact map shares is confirmed by Newton alone",
          "[sweep_point][confirmation]") {
  const PointCase point(paper_five_dof_case("4a"));
  PointSettings s = record(300, 100);
  s.check_periods = true;
  s.confirm = Confirmation::regular;
  const PointResult r = evaluate_point(point, Vector::Zero(10), s);
  CHECK(r.regime == "period-2");
  CHECK(r.confirmation == "newton");
  CHECK(r.decided_by == "exact");
  // The record stays the PIM's: its λ1 and final state are those of the plain record.
  const PointResult plain = evaluate_point(point, Vector::Zero(10), record(300, 100));
  CHECK(r.lambda1 == plain.lambda1);
  CHECK(r.final_state == plain.final_state);
  // The exact orbit's multiplier, not the PIM's: Newton on the exact map at 2 from that state.
  orbits::StroboscopicMap exact_map(point, MethodSettings{Method::exact}, 1);
  orbits::ShootingOptions two;
  two.period = 2;
  const orbits::PeriodicOrbit exact = orbits::find_periodic_orbit(exact_map, r.final_state, two);
  CHECK(r.multiplier == Approx(exact.multipliers.largest_modulus()).epsilon(1e-8));
}

TEST_CASE("the accurate method is the exact solver up to 20 masses, the switching PIM beyond",
          "[sweep_point][confirmation]") {
  // A 21-mass chain (α = 2, ζ = 0.5, θ = 0.3), its last mass forced: its PIM verdict, period-2, is
  // checked by Newton on the switching PIM's map (the exact solver takes at most 20 masses for
  // this; Newton–Krylov would too beyond 400 state components).
  NondimensionalChain large = paper_five_dof_case("4a");
  large.masses = 21;
  large.amplitude = std::vector<double>(21, 0.0);
  large.amplitude.back() = 1.0;
  large.theta = 0.3;
  large.zeta = 0.5;
  PointSettings s = record(100, 200);
  s.confirm = Confirmation::regular;
  s.check_periods = true;
  const PointResult r = evaluate_point(PointCase(large), Vector::Zero(42), s);
  REQUIRE(r.regime == "period-2");
  CHECK(r.confirmed_by == "pim-switching");
  CHECK(r.decided_by == "pim-switching");
  CHECK(r.confirmation == "newton");
  // No accurate method for the exact solver itself: its verdict is its own.
  const PointResult exact =
      evaluate_point(PointCase(paper_five_dof_case("4a")), Vector::Zero(10),
                     [] {
                       PointSettings e = record(300, 100, Method::exact);
                       e.confirm = Confirmation::all;
                       return e;
                     }());
  CHECK(exact.confirmed_by.empty());
  CHECK(exact.decided_by == "exact");
}

TEST_CASE("a confirming run and the Newton stages pass the caller's checkpoints on",
          "[sweep_point][confirmation]") {
  // The case above whose exact motion decides: the PIM's record (1000 periods), Newton on both
  // maps, and the exact run's own 1000 periods all reach the checkpoint, so that a study told to
  // stop (parameter_grid.cpp throws from it) stops within a period of any stage.
  struct Counter : PointObserver {
    long periods = 0, checkpoints = 0, throw_at = -1;
    StepObserver steps_of_period(int) override {
      ++periods;
      return {};
    }
    void checkpoint() override {
      if (++checkpoints == throw_at) throw std::runtime_error("stop");
    }
  };
  const PointCase point(pwl::test::figure5_cell(10.0, 1.9));
  PointSettings s = record(500, 500);
  s.steps_per_period = 18;
  s.check_periods = true;
  s.confirm = Confirmation::regular;
  Counter counter;
  const PointResult r = evaluate_point(point, Vector::Zero(10), s, &counter);
  REQUIRE(r.confirmation == "motion");
  CHECK(counter.periods == 1000);  // the caller's own files see the first record only
  CHECK(counter.checkpoints > 2000);
  // Thrown from inside the confirming run, the stop ends the evaluation.
  Counter stopper;
  stopper.throw_at = 1500;
  CHECK_THROWS_WITH(evaluate_point(point, Vector::Zero(10), s, &stopper), "stop");
  CHECK(stopper.checkpoints == 1500);
}
