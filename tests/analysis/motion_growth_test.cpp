// The classifier's rule 4a, secular growth, on sequences whose growth is known: a motion whose
// amplitude grows like t (or faster) without reaching the divergence bound is unbounded; a torus,
// a transient approaching a bounded motion and a contracting map are not.
#include <catch2/catch.hpp>
#include <cmath>

#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/errors.hpp"

using namespace pwl;
using namespace pwl::analysis;
using Catch::Contains;

namespace {

// Points on a circle of radius `amplitude(k)` turned by the golden angle each iteration: a
// rotation whose radius follows the given law (a torus for a constant one).
template <class Amplitude>
std::vector<Vector> spiral(int count, Amplitude amplitude) {
  const double angle = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Vector> points;
  for (int k = 0; k < count; ++k) {
    const double r = amplitude(k);
    Vector p(2);
    p << r * std::cos(angle * k), r * std::sin(angle * k);
    points.push_back(p);
  }
  return points;
}

// λ1 = 0 and K regular: what a rotation gives, so that without rule 4a the verdict is
// quasi-periodic.
MotionEvidence rotation_evidence(double first_point_time) {
  MotionEvidence e;
  e.lyapunov = 0.0;
  e.lyapunov_error = 1e-4;
  e.zero_one_K = 0.01;
  e.first_point_time = first_point_time;
  return e;
}

}  // namespace

TEST_CASE("an amplitude growing like t after a transient is unbounded, with its exponent",
          "[classifier][growth]") {
  // Recorded from iteration 501 to 1000, amplitude t: it doubles over the record.
  const std::vector<Vector> points = spiral(500, [](int k) { return 501.0 + k; });
  const Classification c = classify_motion(points, rotation_evidence(501.0));
  CHECK(c.regime == Regime::unbounded);
  REQUIRE(c.growth_exponent.has_value());
  CHECK(*c.growth_exponent == Approx(1.0).margin(1e-3));
  CHECK_THAT(c.reason, Contains("the amplitude grows like t^1.00 over the record (t^1.00 over its "
                                "second half)") &&
                           Contains("rises in each of 8 blocks"));
  SECTION("without rule 4a the same points are quasi-periodic") {
    ClassifierOptions options;
    options.detect_growth = false;
    CHECK(classify_motion(points, rotation_evidence(501.0), options).regime ==
          Regime::quasi_periodic);
  }
  SECTION("a faster growth too: exponential, far below the divergence bound") {
    const std::vector<Vector> fast =
        spiral(500, [](int k) { return std::exp(0.004 * (501.0 + k)); });
    const Classification f = classify_motion(fast, rotation_evidence(501.0));
    CHECK(f.regime == Regime::unbounded);
    CHECK(*f.growth_exponent > 2.0);  // t^(0.004 t) over t in [501, 1000]
  }
}

TEST_CASE("a torus, a settling transient, a slow rise and a contracting map are not growth",
          "[classifier][growth]") {
  SECTION("a torus: a constant radius") {
    const Classification c =
        classify_motion(spiral(500, [](int) { return 2.0; }), rotation_evidence(501.0));
    CHECK(c.regime == Regime::quasi_periodic);
    CHECK(std::abs(*c.growth_exponent) < 1e-6);
  }
  SECTION("a transient settling onto the torus: 2 (1 - e^(-t/τ)), τ = 150, from rest") {
    // It rises in every block, at first nearly like t, but its exponent falls over the record.
    const Classification c = classify_motion(
        spiral(500, [](int k) { return 2.0 * (1.0 - std::exp(-(1.0 + k) / 150.0)); }),
        rotation_evidence(1.0));
    INFO(c.reason << "; exponent " << *c.growth_exponent);
    CHECK(c.regime != Regime::unbounded);
  }
  SECTION("a sub-linear rise, like sqrt(t)") {
    const Classification c = classify_motion(spiral(500, [](int k) { return std::sqrt(1.0 + k); }),
                                             rotation_evidence(1.0));
    CHECK(c.regime != Regime::unbounded);
    CHECK(*c.growth_exponent == Approx(0.5).margin(0.02));
  }
  SECTION("a rise too small to tell: 2% over the record") {
    const Classification c =
        classify_motion(spiral(500, [](int k) { return 25000.0 + k; }), rotation_evidence(25000.0));
    CHECK(c.regime != Regime::unbounded);
  }
  SECTION("a map that contracts: the rise is a transient, however it looks") {
    MotionEvidence contracting = rotation_evidence(501.0);
    contracting.lyapunov = -0.05;
    const Classification c =
        classify_motion(spiral(500, [](int k) { return 501.0 + k; }), contracting);
    CHECK(c.regime != Regime::unbounded);
    CHECK_FALSE(c.growth_exponent.has_value());  // the rule did not run
  }
  SECTION("too few points to cut into blocks") {
    const Classification c =
        classify_motion(spiral(31, [](int k) { return 1.0 + k; }), rotation_evidence(1.0));
    CHECK_FALSE(c.growth_exponent.has_value());
  }
}

TEST_CASE("the growth rule's settings and the first point's time are checked",
          "[classifier][growth]") {
  const std::vector<Vector> points = spiral(100, [](int) { return 1.0; });
  MotionEvidence e;
  e.first_point_time = 0.0;
  CHECK_THROWS_WITH(classify_motion(points, e),
                    Contains("MotionEvidence.first_point_time = 0 must be finite and > 0"));
  e.first_point_time = std::nan("");
  CHECK_THROWS_AS(classify_motion(points, e), InputError);
  ClassifierOptions o;
  o.growth_blocks = 3;
  CHECK_THROWS_WITH(classify_motion(points, {}, o), Contains("growth_blocks = 3"));
  o = {};
  o.growth_exponent = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(classify_motion(points, {}, o), InputError);
}
