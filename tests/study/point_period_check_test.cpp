// Newton's check of every period verdict inside the study pipeline (PointSettings::check_periods,
// newton_stage.cpp), against closed forms.
//
//  - The slow spiral: one mass whose stop is never reached, forced at 3.5 times its damped
//    frequency, so that its complex pair of multipliers (|μ| = exp(−ζω_n T) = 0.9822) turns 2/7 of
//    a circle a period. From rest the motion spirals onto the period-1 orbit and returns closer to
//    itself every 7 periods than every period: a record that ends while the spiral's remaining
//    amplitude is in the window between the two returns (after 1000 periods, 120 recorded) is
//    called period-7 by its search. Newton at 7 lands on the period-1 orbit: the verdict is
//    period-1, the harmonic response in closed form, with the closed-form multiplier, the
//    record's 7 kept beside it.
//  - A genuine period-2 orbit (figure 4a's chain) stays period-2, the motion on it.
//  - The checks are off by default: the record's verdict is what it was.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>

#include "orbit_cases.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// m = 1, k = 4, c = 0.04: ω_n = 2, ζ = 0.01; forced at 3.5 ω_d, amplitude 0.5; a stop 100 away.
struct SlowSpiral {
  double wd = 2.0 * std::sqrt(1.0 - 0.01 * 0.01);
  double omega = 3.5 * wd;
  double T = 2 * M_PI / omega;
  double modulus = std::exp(-0.02 * T);  // |μ| per period, closed form
  PointCase point() const {
    GapStructure s = pwl::test::single_mass(1.0, 0.04, 4.0);
    s.loads.push_back({0, 0.5, omega, 0.0});
    s.springs.push_back({0, -1, 1.0, 10.0, 100.0});
    return {s, T};
  }
};

PointSettings record_of(int transient, int recorded) {
  PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = recorded;
  return s;
}

}  // namespace

TEST_CASE("seven turns of a slow spiral are not a period-7 orbit: Newton says period-1",
          "[sweep_point][newton]") {
  const SlowSpiral spiral;
  const PointCase point = spiral.point();
  const Vector rest = Vector::Zero(2);
  // The window: the spiral's amplitude A after the transient with A |1 − μ⁷| below the period
  // search's tolerance and A |1 − μ| above it (|1 − μ⁷| = 0.12, |1 − μ| = 1.55).
  PointSettings s = record_of(1000, 120);
  const PointResult plain = evaluate_point(point, rest, s);
  INFO("record alone: " << plain.regime);
  REQUIRE(plain.regime == "period-7");  // what the record's search says
  CHECK(plain.minimal_period == 0);
  CHECK(std::isnan(plain.multiplier));

  s.check_periods = true;
  const PointResult checked = evaluate_point(point, rest, s);
  CHECK(checked.regime == "period-1");
  CHECK(checked.period == 1);
  CHECK(checked.minimal_period == 1);
  CHECK(checked.record_period == 7);
  // The PIM's period map of a linear structure is exp(H T) to the 2^N algorithm's precision.
  pwl::test::measured("slow spiral: |mu| against exp(-zeta omega_n T)",
                      std::abs(checked.multiplier - spiral.modulus));
  CHECK(checked.multiplier == Approx(spiral.modulus).epsilon(1e-9));
  // On it: the record's last state is within 1e-8 (relative) of the closed-form orbit, and the
  // verdict says so (0 periods to settle); what fooled the search is the spiral's remaining 3e-7
  // of the record's spread, over seven turns.
  const Vector orbit = pwl::test::harmonic_response(point.structure, spiral.omega);
  const double distance = (checked.final_state - orbit).lpNorm<Eigen::Infinity>();
  pwl::test::measured("slow spiral: last state from the harmonic response", distance);
  CHECK(distance <= 1e-8 * std::max(1.0, orbit.lpNorm<Eigen::Infinity>()));
  CHECK(checked.settle_periods == 0.0);
  CHECK(checked.disagreement.empty());
  CHECK(checked.decided_by == "pim");
  CHECK(checked.observed_periods == 120);
  // Nothing else of the record changes.
  CHECK(checked.lambda1 == plain.lambda1);
  CHECK(checked.K == plain.K);
  CHECK(checked.final_state == plain.final_state);

  // The truth, integrated: 200 periods more and the record's own search finds period 1.
  const PointResult settled = evaluate_point(point, rest, record_of(1200, 120));
  CHECK(settled.regime == "period-1");

  // The exact solver confirms it by Newton on its own map at period 1.
  s.confirm = Confirmation::regular;
  const PointResult confirmed = evaluate_point(point, rest, s);
  CHECK(confirmed.regime == "period-1");
  CHECK(confirmed.confirmed_by == "exact");
  CHECK(confirmed.confirmation == "newton");
  CHECK(confirmed.decided_by == "exact");
  CHECK(confirmed.multiplier == Approx(spiral.modulus).epsilon(1e-10));
}

TEST_CASE("a genuine period-2 orbit stays period-2 under Newton's check", "[sweep_point][newton]") {
  const PointCase point(pwl::test::paper_case_at("4a", 1.1));
  PointSettings s = record_of(300, 100);
  const PointResult plain = evaluate_point(point, Vector::Zero(10), s);
  REQUIRE(plain.regime == "period-2");
  s.check_periods = true;
  const PointResult checked = evaluate_point(point, Vector::Zero(10), s);
  CHECK(checked.regime == "period-2");
  CHECK(checked.minimal_period == 2);
  CHECK(checked.record_period == 2);
  CHECK(checked.multiplier < 1.0);
  CHECK(checked.settle_periods == 0.0);  // on it
  CHECK(checked.final_state == plain.final_state);
}

TEST_CASE("the period check is described, off by default, and part of the ladder",
          "[sweep_point][newton]") {
  PointSettings s;
  CHECK_FALSE(s.check_periods);
  CHECK_FALSE(s.ladder_on());
  CHECK(s.describe().find("check_periods") == std::string::npos);  // old studies read the same
  s.use_ladder();
  CHECK(s.check_periods);
  CHECK(s.ladder_on());
  CHECK(s.evidence_periods == PointSettings::kLadderEvidencePeriods);
  CHECK(s.refine_max_period == PointSettings::kLadderRefinePeriod);
  CHECK(s.confirm == Confirmation::regular);
  CHECK(s.describe().find("check_periods = true") != std::string::npos);
  CHECK(parse_confirmation("regular") == Confirmation::regular);
  CHECK(parse_confirmation("all") == Confirmation::all);
  CHECK(confirmation_name(Confirmation::all) == "all");
  CHECK_THROWS_WITH(parse_confirmation("sometimes"),
                    Catch::Contains("'sometimes'") && Catch::Contains("regular"));
}
