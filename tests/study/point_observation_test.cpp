// What a verdict was seen over (observation_stage.cpp, rotation_fraction.hpp).
//
//  - A chaotic verdict says how long it looked and whether it held over both halves: figure 6's
//    chaos does; at α = 11.7, θ = 1.83 the exact motion is chaotic over its first 4000 periods
//    but K of its halves (computed here from the recorded states) is not K of the whole.
//  - An orbit locked on a torus gives its rotation as p/q: α = 5, θ = 1.81 by the exact solver,
//    the period-73 orbit turning 22 times (point_torus_test.cpp checks the orbit by Newton).
//  - The fractions themselves against continued fractions worked by hand.
#include <catch2/catch.hpp>
#include <cmath>

#include "orbit_cases.hpp"
#include "study_cases.hpp"
#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/analysis/rotation_fraction.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

using pwl::test::exact_record;

TEST_CASE("a chaotic verdict says how long it was seen and whether its halves agree",
          "[sweep_point][observation]") {
  // Figure 6's chaos: the same over both halves of its record.
  PointSettings pim;
  const PointResult six =
      evaluate_point(PointCase(paper_five_dof_case("6")), Vector::Zero(10), pim);
  REQUIRE(six.regime == "chaotic");
  CHECK(six.observed_periods == 500);
  CHECK(six.halves == "agree");
  CHECK(six.rotation_pq.empty());

  // α = 11.7, θ = 1.83 by the exact solver: chaotic from period 200 on, but not the same chaos
  // throughout (the motion settles on a torus long after; the verdict is what was seen).
  PointSettings s = exact_record(200, 1000);
  s.evidence_periods = 3000;
  pwl::test::StateRecorder recorder;
  const PointResult r = evaluate_point(PointCase(pwl::test::figure5_cell(11.7, 1.83)),
                                       Vector::Zero(10), s, &recorder);
  REQUIRE(r.regime == "chaotic");
  CHECK(r.observed_periods == 1000 + r.extra_periods);
  REQUIRE(recorder.states.size() == static_cast<std::size_t>(r.observed_periods));
  // The truth of the halves: K of x5 over each half of the recorded states, against the whole's.
  const auto K_of = [&](std::size_t from, std::size_t to) {
    std::vector<double> x5;
    for (std::size_t i = from; i < to; ++i) x5.push_back(recorder.states[i][4]);
    return zero_one_test(x5).K;
  };
  const std::size_t N = recorder.states.size();
  const ClassifierOptions rules;
  const auto reading = [&](double K) { return K > rules.chaotic_K ? 1 : K < rules.regular_K ? -1 : 0; };
  const double first = K_of(0, N / 2), second = K_of(N / 2, N);
  pwl::test::measured("K of the first half", first);
  pwl::test::measured("K of the second half", second);
  const bool K_differs = reading(first) != reading(r.K) || reading(second) != reading(r.K);
  CHECK(K_differs == (r.halves.find("K") != std::string::npos));
  CHECK(r.halves.rfind(K_differs ? "differ:" : "agree", 0) == 0);
}

TEST_CASE("an orbit locked on a torus gives its rotation as p/q", "[sweep_point][observation]") {
  PointSettings s = exact_record(500, 4000);
  s.refine_max_period = 150;
  const PointResult r = evaluate_point(PointCase(pwl::test::figure5_cell(5.0, 1.81)),
                                       Vector::Zero(10), s);
  REQUIRE(r.regime == "period-73");
  CHECK(r.rotation_pq == "22/73");
  CHECK(r.observed_periods == 4000);
}

TEST_CASE("rotation numbers as fractions", "[observation]") {
  // 22/73 = [0; 3, 3, 7]: convergents 1/3, 3/10, 22/73.
  CHECK(locked_denominator(22.0 / 73.0, kLockedPeriodLimit) == 73);
  CHECK(locked_denominator(22.0 / 73.0 + 1e-10, kLockedPeriodLimit) == 73);
  // 1e-6 off 22/73 is 5.3 times kLocked / 73²: not locked at 73 (nor at any q <= 1000).
  CHECK(locked_denominator(22.0 / 73.0 + 1e-6, kLockedPeriodLimit) == 0);
  // The golden mean's convergents are Fibonacci ratios, each about 1/(√5 q²) away: never locked.
  CHECK(locked_denominator((std::sqrt(5.0) - 1.0) / 2.0, kLockedPeriodLimit) == 0);
  CHECK(locked_denominator(std::nan(""), kLockedPeriodLimit) == 0);
  CHECK(rotation_fraction(22.0 / 73.0, 73) == "22/73");
  CHECK(rotation_fraction(2.0 / 4.0, 4) == "2/4");  // a period-4 orbit that turns twice
  CHECK(rotation_fraction(0.3, 73).empty());
  CHECK(rotation_fraction(0.5, 0).empty());
}
