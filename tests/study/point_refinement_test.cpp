// Orbit refinement inside the study pipeline (PointSettings::refine_max_period): a slow spiral that
// a record of a few hundred periods calls quasi-periodic or uncertain is made period-1 with the
// periods it still needs, and the truth is the same pipeline integrated past them; a motion
// refinement cannot settle keeps the record's verdict; refinement off changes nothing.
#include <catch2/catch.hpp>
#include <cmath>

#include "orbit_cases.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/sweep_point.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// x'' + 0.001 x' + x + 1.5 max(0, x − 0.6) = 0.3 sin(0.8 t): its period-1 orbit's leading
// multiplier is about 0.998 a period, so the motion from rest spirals onto it for thousands of
// periods (tests/orbits/orbit_refinement_test.cpp measures the spiral with the exact solver).
PointCase slow_spiral() {
  pwl::test::GapOscillator g;
  g.zeta = 0.0005;
  g.q = 0.3;
  g.theta = 0.8;
  return g.point_case();
}

PointSettings settings(int transient, int recorded, int refine) {
  PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = recorded;
  s.refine_max_period = refine;
  return s;
}

}  // namespace

TEST_CASE("refinement settles a slow spiral in the pipeline, and the long run agrees",
          "[sweep_point][refinement]") {
  const PointCase point = slow_spiral();
  const Vector rest = Vector::Zero(2);
  const PointResult plain = evaluate_point(point, rest, settings(200, 300, 0));
  INFO("record alone: " << plain.regime);
  CHECK((plain.regime == "quasi-periodic" || plain.regime == "uncertain"));
  CHECK(std::isnan(plain.settle_periods));

  const PointResult refined = evaluate_point(point, rest, settings(200, 300, 64));
  REQUIRE(refined.regime == "period-1");
  CHECK(refined.period == 1);
  REQUIRE(std::isfinite(refined.settle_periods));
  pwl::test::measured("slow spiral: periods to settle", refined.settle_periods);
  CHECK(refined.settle_periods > 1000);
  // Everything but the verdict is the record's own.
  CHECK(refined.lambda1 == plain.lambda1);
  CHECK(refined.K == plain.K);
  CHECK(refined.final_state == plain.final_state);

  // The truth: the same pipeline, refinement off, with the transient carried past the predicted
  // settling time (1.5 times it): the record alone then finds period 1.
  const int transient = 500 + static_cast<int>(1.5 * refined.settle_periods);
  const PointResult settled = evaluate_point(point, rest, settings(transient, 100, 0));
  CHECK(settled.regime == "period-1");
}

TEST_CASE("refinement leaves a motion it cannot settle, and settled regimes, as they are",
          "[sweep_point][refinement]") {
  // Figure 5's parameters on the 5-DOF chain: the record finds no period (quasi-periodic here;
  // uncertain with other record lengths); Newton finds no orbit that describes the motion, so the
  // verdict stays.
  NondimensionalChain unsettled = paper_five_dof_case("5");
  const PointResult a = evaluate_point(PointCase(unsettled), Vector::Zero(10), settings(250, 400, 0));
  const PointResult b = evaluate_point(PointCase(unsettled), Vector::Zero(10), settings(250, 400, 64));
  REQUIRE((a.regime == "quasi-periodic" || a.regime == "uncertain"));
  CHECK(b.regime == a.regime);
  CHECK(std::isnan(b.settle_periods));
  // Figure 6's chaos is not refined at all (only quasi-periodic and uncertain records are).
  NondimensionalChain chaos = paper_five_dof_case("6");
  const PointResult e = evaluate_point(PointCase(chaos), Vector::Zero(10), settings(200, 200, 0));
  const PointResult f = evaluate_point(PointCase(chaos), Vector::Zero(10), settings(200, 200, 64));
  CHECK(e.regime == "chaotic");
  CHECK(indicator_cells(e) == indicator_cells(f));
  // A period-2 motion (figure 4a) is not refined at all: the same result bit for bit.
  NondimensionalChain periodic = paper_five_dof_case("4a");
  const PointResult c = evaluate_point(PointCase(periodic), Vector::Zero(10), settings(200, 100, 0));
  const PointResult d = evaluate_point(PointCase(periodic), Vector::Zero(10), settings(200, 100, 64));
  CHECK(c.regime == "period-2");
  CHECK(indicator_cells(c) == indicator_cells(d));
  CHECK(c.final_state == d.final_state);
}

TEST_CASE("the refinement setting is checked and described", "[sweep_point][refinement]") {
  PointSettings s;
  std::string why;
  s.refine_max_period = -1;
  CHECK_FALSE(s.is_valid(1, &why));
  CHECK(why.find("refine max period = -1") != std::string::npos);
  s.refine_max_period = 1001;
  CHECK_FALSE(s.is_valid(1, &why));
  s.refine_max_period = 0;
  CHECK(s.describe().find("refine_max_period") == std::string::npos);  // old studies read the same
  s.refine_max_period = 150;
  CHECK(s.describe().find("refine_max_period = 150\n") != std::string::npos);
}
