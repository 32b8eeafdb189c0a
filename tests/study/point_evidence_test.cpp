// Verdicts a researcher can trust, on cells of the shipped (θ, α) map of the paper's 5-DOF chain
// (figure 5: ζ = 0.2, Δ̃ = 0) that 500 recorded periods of the PIM leave "uncertain":
//  - adaptive evidence (PointSettings::evidence_periods): a record whose λ1 error bar straddles the
//    margin is doubled until it does not; the truth is the exact event-driven solver's own long
//    record;
//  - confirmation by the exact solver (PointSettings::confirm): a small chaotic motion that the
//    PIM's O(η²) error makes of a stable period-4 orbit; the truth is Newton on the exact map;
//  - banded chaos: K of every k-th point when the whole series' K is held down by band hopping;
//    the truth is λ1 by two nearby trajectories of the exact solver.
#include <catch2/catch.hpp>
#include <cmath>

#include "orbit_cases.hpp"
#include "study_cases.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// Cell (i, j) of apps/scenes/theta_alpha_map.toml: θ = 0.5 + 2.5 i / 39, α = 1 + 0.5 j.
NondimensionalChain map_cell(int i, int j) {
  return pwl::test::figure5_cell(1.0 + 0.5 * j, 0.5 + 2.5 * i / 39.0);
}

PointSettings record(int transient, int recorded) {
  PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = recorded;
  return s;
}

const Vector kRest = Vector::Zero(10);

}  // namespace

TEST_CASE("an uncertain record is carried on until its indicators agree",
          "[sweep_point][evidence]") {
  // θ = 2.1667, α = 1: λ1 = 0.0021 ± 0.0029 after 500 points, an error bar across the margin.
  const PointCase cell(map_cell(26, 0));
  const PointResult short_record = evaluate_point(cell, kRest, record(500, 500));
  REQUIRE(short_record.regime == "uncertain");
  CHECK(short_record.extra_periods == 0);

  PointSettings adaptive = record(500, 500);
  adaptive.evidence_periods = 3500;
  const PointResult settled = evaluate_point(cell, kRest, adaptive);
  CHECK(settled.regime == "quasi-periodic");
  CHECK(settled.extra_periods == 500);  // one doubling
  // The doubled record is a record of 1000 periods, bit for bit.
  const PointResult plain = evaluate_point(cell, kRest, record(500, 1000));
  CHECK(plain.regime == settled.regime);
  CHECK(plain.lambda1 == settled.lambda1);
  CHECK(plain.K == settled.K);
  CHECK(plain.final_state == settled.final_state);

  // A budget too small: θ = 2.1667, α = 2 needs two doublings (1000 periods are still
  // uncertain, 2000 are quasi-periodic); with 500 more periods allowed it stays uncertain, the
  // budget spent.
  const PointCase slower(map_cell(26, 2));
  const PointResult doubled_twice = evaluate_point(slower, kRest, adaptive);
  CHECK(doubled_twice.regime == "quasi-periodic");
  CHECK(doubled_twice.extra_periods == 1500);
  adaptive.evidence_periods = 500;
  const PointResult spent = evaluate_point(slower, kRest, adaptive);
  CHECK(spent.regime == "uncertain");
  CHECK(spent.extra_periods == 500);

  // The truth: the exact solver's own record of 2000 periods.
  PointSettings exact = record(500, 2000);
  exact.method = MethodSettings{Method::exact};
  const PointResult truth = evaluate_point(cell, kRest, exact);
  CHECK(truth.regime == "quasi-periodic");
}

TEST_CASE("the exact solver confirms what the PIM leaves uncertain", "[sweep_point][evidence]") {
  // θ = 0.8205, α = 10: the PIM at T/200 finds a small chaotic-looking motion (λ1 = +0.10, no
  // period, best near-return 16) where the exact motion is a stable period-4 orbit.
  const PointCase cell(map_cell(5, 18));
  const PointResult pim = evaluate_point(cell, kRest, record(500, 500));
  REQUIRE(pim.regime == "uncertain");
  CHECK(pim.lambda1 > 0.05);
  CHECK(pim.confirmed_by.empty());

  PointSettings checked = record(500, 500);
  checked.confirm = Confirmation::uncertain;
  const PointResult confirmed = evaluate_point(cell, kRest, checked);
  CHECK(confirmed.regime == "period-4");
  CHECK(confirmed.confirmed_by == "exact");
  CHECK(confirmed.lambda1 < -0.1);
  // A verdict that needs no check is left alone (figure 5's own θ = 2 is not uncertain here).
  const PointResult other = evaluate_point(PointCase(map_cell(0, 0)), kRest, checked);
  CHECK(other.confirmed_by.empty());

  // The truth: Newton on the exact solver's map from the confirmed motion's last state.
  orbits::StroboscopicMap exact(cell, MethodSettings{Method::exact}, 1);
  orbits::ShootingOptions o;
  o.period = 4;
  const orbits::PeriodicOrbit orbit = orbits::find_periodic_orbit(exact, confirmed.final_state, o);
  CHECK(orbit.period == 4);
  CHECK(orbit.stable());
  pwl::test::measured("confirmed motion from its period-4 orbit",
                      (orbit.state - confirmed.final_state).lpNorm<Eigen::Infinity>());
  CHECK((orbit.state - confirmed.final_state).lpNorm<Eigen::Infinity>() < 1e-6);
}

TEST_CASE("banded chaos is told by K of every k-th point", "[sweep_point][evidence]") {
  // θ = 0.8205, α = 5: λ1 = +0.076 ± small, but K of the whole series of x5 is about 0.05: the
  // motion hops between bands near a long orbit. K of every best-k-th point is near 1.
  const PointCase cell(map_cell(5, 8));
  PointSettings s = record(500, 500);
  s.components = {4};  // x5, the observable
  const PointResult r = evaluate_point(cell, kRest, s);
  CHECK(r.regime == "chaotic");
  CHECK(r.K > 0.8);
  const double whole = zero_one_test(r.poincare).K;
  pwl::test::measured("banded chaos: K of the whole series", whole);
  CHECK(whole < 0.2);

  // The truth: λ1 by two nearby trajectories of the exact solver, clearly positive.
  PointSettings exact = record(500, 500);
  exact.method = MethodSettings{Method::exact};
  exact.lyapunov_estimate = LyapunovEstimate::two_trajectories;
  const PointResult truth = evaluate_point(cell, kRest, exact);
  pwl::test::measured("banded chaos: exact λ1 by two trajectories", truth.lambda1);
  CHECK(truth.lambda1 - truth.lambda1_error > 0.02);
}

TEST_CASE("the evidence settings are checked and described", "[sweep_point][evidence]") {
  PointSettings s;
  std::string why;
  s.evidence_periods = -5;
  CHECK_FALSE(s.is_valid(1, &why));
  CHECK(why.find("evidence periods = -5") != std::string::npos);
  s.evidence_periods = 0;
  CHECK(s.describe().find("evidence_periods") == std::string::npos);
  CHECK(s.describe().find("confirm") == std::string::npos);
  s.evidence_periods = 3500;
  s.confirm = Confirmation::uncertain;
  CHECK(s.describe().find("evidence_periods = 3500\n") != std::string::npos);
  CHECK(s.describe().find("confirm = uncertain\n") != std::string::npos);
  CHECK(parse_confirmation("aperiodic") == Confirmation::aperiodic);
  CHECK_THROWS_WITH(parse_confirmation("always"), Catch::Contains("confirmation 'always'"));
}
