// Orbit refinement against independent truth: a lightly damped linear oscillator (its orbit the
// harmonic response, its multipliers exp(λ T) in closed form, its approach counted period by
// period); a gap oscillator whose slow spiral onto a period-1 orbit is integrated out by the exact
// solver (the orbit and the count of periods it takes); candidate periods of a period-3 record;
// an unstable orbit inside figure 6's chaos, which does not describe the motion.
#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/orbit_refinement.hpp"
#include "test_structures.hpp"

using namespace pwl;
using namespace pwl::orbits;

namespace {

double inf_norm(const Vector& v) { return v.lpNorm<Eigen::Infinity>(); }

// Forcing periods from y until |y − orbit|_∞ <= tolerance, at most `limit`.
long periods_until(StroboscopicMap& map, Vector y, const Vector& orbit, double tolerance,
                   long limit) {
  for (long k = 0; k < limit; ++k) {
    if (inf_norm(y - orbit) <= tolerance) return k;
    y = map.advance(y, 1);
  }
  return limit;
}

}  // namespace

TEST_CASE("orbit refinement settles a lightly damped linear oscillator's slow approach",
          "[orbits][refinement]") {
  // m x'' + c x' + k x = q sin(ω t), c small: |μ| = exp(−c T / 2m) ≈ 0.996 a period.
  GapStructure s = pwl::test::single_mass(1.0, 0.003, 1.0);
  s.loads.push_back({0, 0.4, 1.3, 0.0});
  const double omega = 1.3, T = 2 * M_PI / omega;
  StroboscopicMap map(analysis::PointCase(s, T), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> points =
      pwl::test::poincare_points(map, Vector::Zero(2), 100, 300);  // from rest
  const Vector last = points.back();

  const OrbitRefinement r = refine_orbit(map, points, last);
  INFO(r.describe());
  REQUIRE(r.found);
  CHECK(r.orbit.period == 1);
  const Vector expected = pwl::test::harmonic_response(s, omega);
  CHECK(inf_norm(r.orbit.state - expected) <= 1e-12);
  const double rate = std::exp(-0.003 / 2 * T);  // the closed-form |μ| per period
  CHECK(r.contraction_per_period == Approx(rate).epsilon(1e-10));
  CHECK(r.attracting);
  CHECK_FALSE(r.on_orbit);
  // Step 4: carried on until the multiplier predicts half the distance, the motion shrank its
  // distance about as predicted (a linear map: the slowest mode's factor, up to the rotation of
  // the error in the phase plane).
  CHECK(r.approach_confirmed);
  CHECK(r.predicted_factor == Approx(0.5).epsilon(0.01));
  CHECK(r.measured_factor == Approx(0.5).epsilon(0.1));
  CHECK(r.explains_motion());
  CHECK(r.distance == Approx(inf_norm(last - expected)).epsilon(1e-9));
  // The estimate against the count, period by period, to the same tolerance.
  const long counted = periods_until(map, last, expected, r.tolerance, 100000);
  pwl::test::measured("linear oscillator: periods to settle estimated", r.periods_to_settle);
  pwl::test::measured("linear oscillator: periods to settle counted", static_cast<double>(counted));
  CHECK(counted > 2000);  // a long transient indeed
  CHECK(std::abs(r.periods_to_settle - counted) <= 0.05 * counted);
  CHECK(r.describe().find("attracting") != std::string::npos);
}

TEST_CASE("orbit refinement settles a gap oscillator's slow spiral onto its period-1 orbit",
          "[orbits][refinement]") {
  pwl::test::GapOscillator g;
  g.zeta = 0.0005;
  g.q = 0.3;
  g.theta = 0.8;
  StroboscopicMap map(g.point_case(), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> points = pwl::test::poincare_points(map, Vector::Zero(2), 200, 300);
  const Vector last = points.back();

  const OrbitRefinement r = refine_orbit(map, points, last);
  INFO(r.describe());
  REQUIRE(r.found);
  REQUIRE(r.orbit.period == 1);
  REQUIRE(r.attracting);
  CHECK_FALSE(r.on_orbit);
  CHECK(r.approach_confirmed);
  pwl::test::measured("gap oscillator: distance factor measured", r.measured_factor);
  // Of the predicted order (measured 0.49 against 0.50 on the window maxima; faster is allowed,
  // slower than the square root is not).
  CHECK(r.measured_factor <= std::sqrt(r.predicted_factor));
  CHECK(r.measured_factor >= r.predicted_factor * r.predicted_factor);
  // The truth: the same exact solver, integrated until the motion stops moving.
  Vector y = last;
  long settled = -1;
  for (long k = 1; k <= 60000; ++k) {
    const Vector next = map.advance(y, 1);
    if (inf_norm(next - y) <= 1e-13) {
      settled = k;
      y = next;
      break;
    }
    y = next;
  }
  REQUIRE(settled > 0);
  pwl::test::measured("gap oscillator: orbit against the motion integrated out",
                      inf_norm(r.orbit.state - y));
  CHECK(inf_norm(r.orbit.state - y) <= 1e-10);
  // The motion came within the tolerance after about the periods the multiplier predicts.
  const long counted = periods_until(map, last, r.orbit.state, r.tolerance, 100000);
  pwl::test::measured("gap oscillator: periods to settle estimated", r.periods_to_settle);
  pwl::test::measured("gap oscillator: periods to settle counted", static_cast<double>(counted));
  CHECK(counted > 1000);
  CHECK(std::abs(r.periods_to_settle - counted) <= 0.15 * counted);
}

TEST_CASE("an attracting orbit the motion does not approach is not taken for the motion's",
          "[orbits][refinement]") {
  // One mass of the nondimensional chain, ζ = 0.001, α = 0.5, Δ̃ = 0.5, Q = 0.5, θ = 0.8: from
  // rest the motion ends on a period-3 orbit (the truth below: the exact solver, 6000 periods
  // on), while a stable period-1 orbit coexists with it. After 300 periods Newton from the last
  // state at period 1 (the only candidate allowed here) converges to the period-1 orbit,
  // attracting; the motion is not approaching it.
  const NondimensionalChain c = pwl::test::one_mass(0.5, 0.001, 0.5, 0.5, 0.8);
  StroboscopicMap map(analysis::PointCase(c), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> early = pwl::test::poincare_points(map, Vector::Zero(2), 300, 300);
  RefinementOptions only_one;
  only_one.max_period = 1;
  const OrbitRefinement r = refine_orbit(map, early, early.back(), only_one);
  INFO(r.describe());
  REQUIRE(r.found);
  REQUIRE(r.orbit.period == 1);
  CHECK(r.attracting);
  CHECK_FALSE(r.on_orbit);
  CHECK_FALSE(r.approach_confirmed);
  CHECK_FALSE(r.explains_motion());
  CHECK(r.describe().find("does not approach it as predicted") != std::string::npos);

  // The truth: 6000 periods on, the motion repeats every 3 periods, not every period, and
  // stays far from the period-1 orbit.
  const Vector settled = map.advance(early.back(), 6000);
  CHECK(inf_norm(map.advance(settled, 3) - settled) <= 1e-8);
  CHECK(inf_norm(map.advance(settled, 1) - settled) > 1e-2);
  CHECK(inf_norm(settled - r.orbit.state) > 0.1);

  // With the candidates from the record's near returns (period 3 among them), the period-1
  // orbit is passed over and the period-3 orbit found, approached as predicted.
  const OrbitRefinement late = refine_orbit(map, early, early.back());
  INFO(late.describe());
  REQUIRE(late.found);
  CHECK(late.orbit.period == 3);
  CHECK(late.explains_motion());
  double nearest = inf_norm(settled - late.orbit.state);
  Vector y = late.orbit.state;
  for (int j = 1; j < 3; ++j) {
    y = map.advance(y, 1);
    nearest = std::min(nearest, inf_norm(settled - y));
  }
  CHECK(nearest <= 1e-8);
}

TEST_CASE("a motion that keeps its distance from an attracting orbit is not taken for the orbit's",
          "[orbits][refinement]") {
  // A cell of the shipped (θ, α) map (figure 5's chain, α = 6.5, θ = 0.5 + 22 · 2.5/39), by the
  // map's PIM (η = T/200): Newton finds a period-1 orbit that is attracting for the PIM's map
  // (|μ| = 0.9973; by the exact solver it is slightly unstable, 1.0017), and the motion stays
  // about 0.04 from it, rising and falling, for 40000 periods (pwl analyze). A check on one
  // distance 255 periods on (an earlier version) passed it on the map's run ("approaches it,
  // reached after about 5454 more periods"); the window maxima do not.
  NondimensionalChain chain = paper_five_dof_case("5");
  chain.alpha = {6.5};
  chain.theta = 0.5 + 22 * 2.5 / 39;
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::pim}, 200);
  const std::vector<Vector> points = pwl::test::poincare_points(map, Vector::Zero(10), 700, 300);
  const OrbitRefinement r = refine_orbit(map, points, points.back());
  INFO(r.describe());
  REQUIRE(r.found);
  REQUIRE(r.orbit.period == 1);
  CHECK(r.attracting);
  CHECK_FALSE(r.approach_confirmed);
  CHECK(r.measured_factor > 0.9);
  CHECK_FALSE(r.explains_motion());
  // The truth: 3000 periods on, the motion is still that far from the orbit.
  const Vector later = map.advance(points.back(), 3000);
  CHECK(inf_norm(later - r.orbit.state) > 0.02);
}

TEST_CASE("candidate periods of a period-3 record are 3, not its multiples",
          "[orbits][refinement]") {
  std::vector<Vector> points;
  const Vector a = Vector::Constant(2, 1.0), b = Vector::Constant(2, -0.5),
               c = Vector::Constant(2, 0.25);
  for (int i = 0; i < 200; ++i) {
    const Vector& p = i % 3 == 0 ? a : i % 3 == 1 ? b : c;
    points.push_back(p + Vector::Constant(2, 1e-6 * std::sin(0.37 * i)));  // a little wobble
  }
  const std::vector<int> k = candidate_periods(points, 100, 3);
  REQUIRE_FALSE(k.empty());
  CHECK(k.front() == 3);
  for (int p : k) CHECK((p == 3 || p % 3 != 0));
}

TEST_CASE("an unstable orbit inside chaos is found but does not describe the motion",
          "[orbits][refinement]") {
  StroboscopicMap map(analysis::PointCase(paper_five_dof_case("6")), MethodSettings{Method::exact},
                      1);
  const std::vector<Vector> points = pwl::test::poincare_points(map, Vector::Zero(10), 300, 300);
  // Newton from the recorded point that moves least in one period (the period-1 orbit of
  // chaotic_saddle_orbit_test.cpp), the candidates limited to period 1.
  std::size_t best = 0;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    if (inf_norm(points[i + 1] - points[i]) < inf_norm(points[best + 1] - points[best])) best = i;
  }
  RefinementOptions o;
  o.max_period = 1;
  const OrbitRefinement r = refine_orbit(map, points, points[best], o);
  INFO(r.describe());
  REQUIRE(r.found);
  CHECK(r.orbit.period == 1);
  CHECK(r.orbit.multipliers.largest_modulus() > 1.0);
  CHECK_FALSE(r.attracting);
  CHECK_FALSE(r.on_orbit);
  CHECK(r.distance > 1e-3);
  CHECK_FALSE(r.explains_motion());
  CHECK(r.describe().find("does not describe the motion") != std::string::npos);
}

TEST_CASE("orbit refinement refuses bad options and states naming the field",
          "[orbits][refinement][errors]") {
  pwl::test::GapOscillator g;
  StroboscopicMap map(g.point_case(), MethodSettings{Method::exact}, 1);
  const std::vector<Vector> points(10, Vector::Zero(2));
  const auto message = [&](const RefinementOptions& o, const Vector& y) {
    try {
      refine_orbit(map, points, y, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  RefinementOptions o;
  o.max_period = 0;
  CHECK(message(o, Vector::Zero(2)).find("max period = 0") != std::string::npos);
  o = {};
  o.candidates = 0;
  CHECK(message(o, Vector::Zero(2)).find("candidates = 0") != std::string::npos);
  o = {};
  o.max_check_periods = 0;
  CHECK(message(o, Vector::Zero(2)).find("max check periods = 0") != std::string::npos);
  o = {};
  o.on_orbit_tolerance = -1;
  CHECK(message(o, Vector::Zero(2)).find("on-orbit tolerance = -1") != std::string::npos);
  o = {};
  o.shooting.tolerance = 0;
  CHECK(message(o, Vector::Zero(2)).find("tolerance = 0") != std::string::npos);
  o = {};
  CHECK(message(o, Vector::Zero(3)).find("last state has 3 components") != std::string::npos);
  CHECK(message(o, Vector::Constant(2, std::nan(""))).find("not finite") != std::string::npos);
}
