// The motion classifier on maps of known behaviour, with the indicators computed by the library
// itself (period search, QR Lyapunov exponents, 0-1 test), and its refusal to guess when the
// indicators disagree.
#include "pwl/analysis/motion_classifier.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/weighted_birkhoff.hpp"
#include "pwl/errors.hpp"
#include "study_cases.hpp"
#include "test_series.hpp"

using pwl::Matrix;
using pwl::Vector;
using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

// The logistic map and the Hénon map at a = 1.4, b = 0.3 (test_series.hpp).
TangentMap logistic(double r) { return pwl::test::logistic_map(r); }
TangentMap henon() { return pwl::test::henon_map(1.4, 0.3); }

// The rotation of the circle by the golden mean, seen through the smooth change of angle
// theta = h(phi) = phi + eps sin(phi), as a map of the plane that keeps the radius:
// (r, theta) -> (r, h(h^{-1}(theta) + alpha)). Its orbits are quasi-periodic and both Lyapunov
// exponents are 0, but unlike a plain rotation its Jacobian is not orthogonal: the tangent
// stretching dtheta'/dtheta = h'(phi')/h'(phi) fluctuates in [(1 - eps)/(1 + eps),
// (1 + eps)/(1 - eps)], so the QR average has to cancel it (error <= ln 3 / N for eps = 1/2).
TangentMap conjugated_golden_rotation(double eps = 0.5) {
  const double alpha = std::numbers::pi * (std::sqrt(5.0) - 1.0);
  return [alpha, eps](const Vector& s, Matrix* J) {
    const double r = s.norm();
    const double theta = std::atan2(s[1], s[0]);
    double phi = theta;  // solve phi + eps sin(phi) = theta (Kepler's equation) by Newton
    for (int i = 0; i < 50; ++i) {
      const double step = (phi + eps * std::sin(phi) - theta) / (1.0 + eps * std::cos(phi));
      phi -= step;
      if (std::abs(step) < 1e-15) break;
    }
    const double phi_next = phi + alpha;
    const double theta_next = phi_next + eps * std::sin(phi_next);
    Vector next(2);
    next << r * std::cos(theta_next), r * std::sin(theta_next);
    if (J != nullptr) {
      const double stretch = (1.0 + eps * std::cos(phi_next)) / (1.0 + eps * std::cos(phi));
      Matrix out(2, 2);  // d(x', y') / d(r, theta')
      out << std::cos(theta_next), -r * std::sin(theta_next), std::sin(theta_next),
          r * std::cos(theta_next);
      Matrix polar(2, 2);  // d(r, theta) / d(x, y)
      polar << s[0] / r, s[1] / r, -s[1] / (r * r), s[0] / (r * r);
      Matrix middle = Matrix::Identity(2, 2);
      middle(1, 1) = stretch;
      *J = out * middle * polar;
    }
    return next;
  };
}

std::vector<Vector> orbit(const TangentMap& map, Vector x, int count, int transient = 1000) {
  for (int i = 0; i < transient; ++i) x = map(x, nullptr);
  std::vector<Vector> points;
  for (int i = 0; i < count; ++i) {
    x = map(x, nullptr);
    points.push_back(x);
  }
  return points;
}

MotionEvidence lyapunov_evidence(const TangentMap& map, const Vector& x0, long iterations = 20000) {
  LyapunovOptions options;
  options.iterations = iterations;
  options.exponents = 1;
  const LyapunovResult result = lyapunov_spectrum(map, x0, options);
  MotionEvidence evidence;
  evidence.lyapunov = result.largest();
  evidence.lyapunov_error = result.error[0];
  return evidence;
}

Vector scalar(double x) { return Vector::Constant(1, x); }

Vector point(double x, double y) {
  Vector p(2);
  p << x, y;
  return p;
}

}  // namespace

TEST_CASE("logistic map at r = 4 is chaotic", "[classifier]") {
  const MotionEvidence evidence = lyapunov_evidence(logistic(4.0), scalar(0.1234));
  REQUIRE(*evidence.lyapunov == Approx(std::log(2.0)).margin(1e-2));
  const Classification c = classify_motion(orbit(logistic(4.0), scalar(0.1234), 2000), evidence);
  CHECK(c.regime == Regime::chaotic);
  CHECK(c.name() == "chaotic");
  CHECK(c.period == 0);
  CHECK(c.period_search.period == 0);
  REQUIRE(c.zero_one_K.has_value());
  CHECK(*c.zero_one_K > 0.9);
  CHECK(c.zero_one_source == "points");
  CHECK_THAT(c.reason, Contains("chaotic") && Contains("K = "));
}

TEST_CASE("Henon map is chaotic", "[classifier]") {
  const Vector x0 = point(0.1, 0.1);
  const Classification c =
      classify_motion(orbit(henon(), x0, 2000), lyapunov_evidence(henon(), x0));
  CHECK(c.regime == Regime::chaotic);
  CHECK(*c.zero_one_K > 0.9);
}

TEST_CASE("golden-mean rotation is quasi-periodic", "[classifier]") {
  const TangentMap map = conjugated_golden_rotation();
  const Vector x0 = point(1.0, 0.0);
  LyapunovOptions options;
  options.iterations = 10000;
  const LyapunovResult lyapunov = lyapunov_spectrum(map, x0, options);
  CHECK(std::abs(lyapunov.per_iteration[0]) < 1e-3);
  CHECK(std::abs(lyapunov.per_iteration[1]) < 1e-3);

  const std::vector<Vector> points = orbit(map, x0, 2000);
  MotionEvidence evidence;
  evidence.lyapunov = lyapunov.largest();
  evidence.lyapunov_error = lyapunov.error[0];
  const Classification c = classify_motion(points, evidence);
  CHECK(c.period_search.period == 0);
  REQUIRE(c.zero_one_K.has_value());
  CHECK(*c.zero_one_K < 0.1);
  CHECK(c.regime == Regime::quasi_periodic);
  CHECK(c.name() == "quasi-periodic");
}

TEST_CASE("logistic map cycles: period-2, period-4 and a fixed point", "[classifier]") {
  SECTION("r = 3.2") {
    const MotionEvidence evidence = lyapunov_evidence(logistic(3.2), scalar(0.3));
    CHECK(*evidence.lyapunov < 0.0);
    const Classification c = classify_motion(orbit(logistic(3.2), scalar(0.3), 200), evidence);
    CHECK(c.regime == Regime::periodic);
    CHECK(c.period == 2);
    CHECK(c.name() == "period-2");
    CHECK_FALSE(c.zero_one_K.has_value());  // not needed once a period is found
  }
  SECTION("r = 3.5") {
    const MotionEvidence evidence = lyapunov_evidence(logistic(3.5), scalar(0.3));
    CHECK(*evidence.lyapunov < 0.0);
    const Classification c = classify_motion(orbit(logistic(3.5), scalar(0.3), 200), evidence);
    CHECK(c.regime == Regime::periodic);
    CHECK(c.period == 4);
    CHECK(c.name() == "period-4");
  }
  SECTION("r = 2.8: equilibrium, or period-1 for a stroboscopic map") {
    const std::vector<Vector> points = orbit(logistic(2.8), scalar(0.3), 200);
    const Classification c = classify_motion(points);
    CHECK(c.regime == Regime::equilibrium);
    CHECK(c.name() == "equilibrium");
    ClassifierOptions options;
    options.fixed_point_is_equilibrium = false;
    const Classification forced = classify_motion(points, {}, options);
    CHECK(forced.regime == Regime::periodic);
    CHECK(forced.name() == "period-1");
  }
}

TEST_CASE("unbounded motion is reported before it overflows", "[classifier]") {
  // x -> 2x + 1 from 1: values[n] = 2^{n+2} - 1, about 5e30 after 100 iterations: finite, but
  // far beyond the divergence bound 1e12.
  std::vector<double> values;
  double x = 1.0;
  for (int n = 0; n < 100; ++n) {
    x = 2.0 * x + 1.0;
    values.push_back(x);
  }
  REQUIRE(std::isfinite(values.back()));
  const Classification c = classify_motion(values);
  CHECK(c.regime == Regime::unbounded);
  CHECK(c.name() == "unbounded");
  // 2^39 - 1 = 5.5e11 is within the bound, values[38] = 2^40 - 1 = 1.1e12 the first beyond it.
  CHECK_THAT(c.reason, Contains("points[38][0] = 1099511627775"));
  CHECK(c.period_search.points_used == 0);          // checked first: no period search ran

  SECTION("a lower bound catches it earlier") {
    ClassifierOptions options;
    options.divergence_bound = 100.0;
    CHECK_THAT(classify_motion(values, {}, options).reason, Contains("points[5][0] = 127"));
  }
  SECTION("a NaN is unbounded too, not an error") {
    std::vector<double> nan_values(10, 0.5);
    nan_values[3] = std::nan("");
    const Classification n = classify_motion(nan_values);
    CHECK(n.regime == Regime::unbounded);
    CHECK_THAT(n.reason, Contains("points[3][0]") && Contains("nan"));
  }
  SECTION("as is a non-finite observable") {
    MotionEvidence evidence;
    evidence.observable.assign(200, 0.5);
    evidence.observable[150] = std::numeric_limits<double>::infinity();
    const Classification n = classify_motion(std::vector<double>(10, 0.5), evidence);
    CHECK(n.regime == Regime::unbounded);
    CHECK_THAT(n.reason, Contains("observable[150]"));
  }
}

TEST_CASE("disagreeing indicators give uncertain, not a guess", "[classifier]") {
  const std::vector<Vector> chaotic = orbit(logistic(4.0), scalar(0.1234), 2000);
  SECTION("chaotic-looking points with a negative lambda") {
    MotionEvidence evidence;
    evidence.lyapunov = -0.5;
    const Classification c = classify_motion(chaotic, evidence);
    CHECK(c.regime == Regime::uncertain);
    CHECK(*c.zero_one_K > 0.9);
    CHECK_THAT(c.reason, Contains("disagree"));
  }
  SECTION("positive lambda but K says regular") {
    MotionEvidence evidence;
    evidence.lyapunov = 0.69;
    evidence.zero_one_K = 0.05;
    const Classification c = classify_motion(chaotic, evidence);
    CHECK(c.regime == Regime::uncertain);
    CHECK(c.zero_one_source == "given");
    CHECK_THAT(c.reason, Contains("disagree"));
  }
  SECTION("a period with a clearly positive lambda") {
    MotionEvidence evidence;
    evidence.lyapunov = 0.5;
    evidence.lyapunov_error = 0.01;
    const Classification c = classify_motion(orbit(logistic(3.5), scalar(0.3), 200), evidence);
    CHECK(c.regime == Regime::uncertain);
    CHECK(c.period_search.period == 4);
    CHECK(c.period == 0);
  }
  SECTION("a period with lambda near 0 within its error is still periodic") {
    MotionEvidence evidence;
    evidence.lyapunov = 0.004;
    evidence.lyapunov_error = 0.01;
    const Classification c = classify_motion(orbit(logistic(3.5), scalar(0.3), 200), evidence);
    CHECK(c.regime == Regime::periodic);
  }
  SECTION("no period, regular K, but lambda inconclusive") {
    const std::vector<Vector> rotation = orbit(conjugated_golden_rotation(), point(1.0, 0.0), 2000);
    MotionEvidence evidence;
    evidence.lyapunov = 0.004;  // |lambda| + error = 0.014 > margin 0.005, lambda - error < margin
    evidence.lyapunov_error = 0.01;
    CHECK(classify_motion(rotation, evidence).regime == Regime::uncertain);
    evidence.lyapunov_error = 0.0005;  // now |lambda| + error <= margin
    CHECK(classify_motion(rotation, evidence).regime == Regime::quasi_periodic);
  }
  SECTION("negative lambda and no period up to k_max") {
    std::vector<double> long_cycle;
    for (int n = 0; n < 400; ++n) long_cycle.push_back(std::cos(2.0 * std::numbers::pi * n / 100.0));
    MotionEvidence evidence;
    evidence.lyapunov = -0.1;
    const Classification c = classify_motion(long_cycle, evidence);
    CHECK(c.regime == Regime::uncertain);
    CHECK_THAT(c.reason, Contains("k_max"));
    ClassifierOptions options;
    options.period.k_max = 100;
    const Classification found = classify_motion(long_cycle, evidence, options);
    CHECK(found.regime == Regime::periodic);
    CHECK(found.period == 100);
  }
}

TEST_CASE("the torus test vetoes chaos on a curve and settles inconclusive indicators on one",
          "[classifier][torus]") {
  // The golden rotation's points lie on a smooth closed curve: the torus test scores many digits
  // on them (weighted_birkhoff_test.cpp), and the Hénon attractor's only about 2.
  const std::vector<Vector> curve = orbit(conjugated_golden_rotation(), point(1.0, 0.0), 2000);
  const double curve_digits = weighted_birkhoff_test(pwl::test::as_rows(curve)).digits;
  CHECK(curve_digits > 8.0);
  const std::vector<Vector> henon_points = orbit(henon(), point(0.1, 0.1), 2000);
  const double henon_digits = weighted_birkhoff_test(pwl::test::as_rows(henon_points)).digits;
  CHECK(henon_digits < 2.5);

  SECTION("λ1 > 0 and K chaotic on a curve: uncertain, not chaotic") {
    MotionEvidence evidence;
    evidence.lyapunov = 0.1;
    evidence.lyapunov_error = 0.01;
    evidence.zero_one_K = 0.9;
    CHECK(classify_motion(curve, evidence).regime == Regime::chaotic);  // without the test
    evidence.torus_digits = curve_digits;
    const Classification c = classify_motion(curve, evidence);
    CHECK(c.regime == Regime::uncertain);
    CHECK_THAT(c.reason, Contains("smooth invariant curve") && Contains("torus test"));
    // A failed torus test does not stand in the way of chaos.
    MotionEvidence chaos = evidence;
    chaos.torus_digits = henon_digits;
    CHECK(classify_motion(henon_points, chaos).regime == Regime::chaotic);
  }
  SECTION("an inconclusive λ1 holding 0 and K in between: quasi-periodic on a curve only") {
    MotionEvidence evidence;
    evidence.lyapunov = 0.004;
    evidence.lyapunov_error = 0.01;
    evidence.zero_one_K = 0.5;
    CHECK(classify_motion(curve, evidence).regime == Regime::uncertain);
    evidence.torus_digits = curve_digits;
    CHECK(classify_motion(curve, evidence).regime == Regime::quasi_periodic);
    evidence.torus_digits = 3.0;  // between broken (2.5) and curve (5): no help
    CHECK(classify_motion(curve, evidence).regime == Regime::uncertain);
  }
  SECTION("a λ1 whose error bar excludes 0 is not settled by the curve") {
    MotionEvidence evidence;
    evidence.lyapunov = -0.008;  // inconclusive against the margin, but below 0: a long period
    evidence.lyapunov_error = 0.005;
    evidence.zero_one_K = 0.1;
    evidence.torus_digits = curve_digits;
    CHECK(classify_motion(curve, evidence).regime == Regime::uncertain);
  }
  SECTION("bad torus digits and thresholds are named") {
    MotionEvidence evidence;
    evidence.torus_digits = -1.0;
    CHECK_THROWS_WITH(classify_motion(curve, evidence), Contains("torus_digits = -1"));
    ClassifierOptions options;
    options.broken_digits = 6.0;
    std::string why;
    CHECK_FALSE(options.is_valid(&why));
    CHECK_THAT(why, Contains("broken_digits = 6"));
  }
}

TEST_CASE("one indicator is enough unless both are required", "[classifier]") {
  // 50 points: too few for the 0-1 test (min_samples = 100), so only lambda speaks.
  const std::vector<Vector> short_chaotic = orbit(logistic(4.0), scalar(0.1234), 50);
  MotionEvidence evidence;
  evidence.lyapunov = 0.69;
  evidence.lyapunov_error = 0.001;
  const Classification lenient = classify_motion(short_chaotic, evidence);
  CHECK(lenient.regime == Regime::chaotic);
  CHECK_FALSE(lenient.zero_one_K.has_value());
  ClassifierOptions strict;
  strict.require_all_indicators = true;
  CHECK(classify_motion(short_chaotic, evidence, strict).regime == Regime::uncertain);

  // K alone, from the points.
  const std::vector<Vector> chaotic = orbit(logistic(4.0), scalar(0.1234), 2000);
  CHECK(classify_motion(chaotic).regime == Regime::chaotic);
  CHECK(classify_motion(chaotic, {}, strict).regime == Regime::uncertain);

  // K from a separate observable series instead of the points.
  MotionEvidence observed;
  for (const Vector& p : chaotic) observed.observable.push_back(p[0]);
  const Classification from_series = classify_motion(short_chaotic, observed);
  CHECK(from_series.zero_one_source == "observable");
  CHECK(from_series.regime == Regime::chaotic);

  // No indicator at all.
  ClassifierOptions no_points;
  no_points.zero_one_from_points = false;
  const Classification none = classify_motion(chaotic, {}, no_points);
  CHECK(none.regime == Regime::uncertain);
  CHECK_THAT(none.reason, Contains("no indicator"));
}

TEST_CASE("too few points to test any period", "[classifier]") {
  const Classification c = classify_motion(std::vector<double>{0.2, 0.8});
  CHECK(c.regime == Regime::uncertain);
  CHECK_THAT(c.reason, Contains("too few"));
}

TEST_CASE("regime names", "[classifier]") {
  CHECK(regime_name(Regime::equilibrium) == "equilibrium");
  CHECK(regime_name(Regime::periodic, 3) == "period-3");
  CHECK(regime_name(Regime::quasi_periodic) == "quasi-periodic");
  CHECK(regime_name(Regime::chaotic) == "chaotic");
  CHECK(regime_name(Regime::unbounded) == "unbounded");
  CHECK(regime_name(Regime::uncertain) == "uncertain");
}

TEST_CASE("classifier input errors name the field and the value", "[classifier][errors]") {
  const std::vector<double> values{0.1, 0.2, 0.3, 0.4};
  CHECK_THROWS_WITH(classify_motion(std::vector<Vector>{}), Contains("points") && Contains("0"));
  MotionEvidence evidence;
  evidence.lyapunov = std::nan("");
  CHECK_THROWS_WITH(classify_motion(values, evidence),
                    Contains("MotionEvidence.lyapunov") && Contains("nan"));
  evidence = {};
  evidence.lyapunov_error = -1.0;
  CHECK_THROWS_WITH(classify_motion(values, evidence), Contains("lyapunov_error = -1"));
  evidence = {};
  evidence.zero_one_K = 1.5;
  CHECK_THROWS_WITH(classify_motion(values, evidence), Contains("zero_one_K = 1.5"));

  ClassifierOptions options;
  options.regular_K = 0.9;
  CHECK_THROWS_WITH(classify_motion(values, {}, options),
                    Contains("regular_K = 0.9") && Contains("chaotic_K = 0.8"));
  options = {};
  options.period.k_max = 0;
  CHECK_THROWS_WITH(classify_motion(values, {}, options), Contains("k_max = 0"));
  options = {};
  options.observable_component = 2;
  const std::vector<Vector> chaotic = orbit(logistic(4.0), scalar(0.1234), 200);
  CHECK_THROWS_WITH(classify_motion(chaotic, {}, options),
                    Contains("observable_component = 2") && Contains("dimension 1"));
  std::vector<Vector> mixed{scalar(0.1), point(0.1, 0.2)};
  CHECK_THROWS_WITH(classify_motion(mixed), Contains("points[1]") && Contains("2"));
}
