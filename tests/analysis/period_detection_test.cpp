// Period detection on Poincaré points: logistic-map cycles of known period, fixed points, chaotic
// and quasi-periodic sequences that must not be called periodic, and the tolerance rules.
#include "pwl/analysis/period_detection.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "pwl/errors.hpp"
#include "test_series.hpp"

using pwl::Vector;
using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

// Logistic-map values after a transient of 2000 from x = 0.3 (test_series.hpp).
std::vector<double> logistic_orbit(double r, int count) {
  return pwl::test::logistic_series(r, count, 2000, 0.3);
}

// Points of the rotation of the unit circle by the golden mean.
std::vector<Vector> golden_rotation(int count) {
  const double alpha = 2.0 * std::numbers::pi * (std::sqrt(5.0) - 1.0) / 2.0;
  std::vector<Vector> points;
  for (int n = 0; n < count; ++n) {
    Vector p(2);
    p << std::cos(n * alpha), std::sin(n * alpha);
    points.push_back(p);
  }
  return points;
}

}  // namespace

TEST_CASE("logistic map cycles: period 1, 2 and 4", "[period]") {
  SECTION("r = 2.8: a fixed point") {
    const PeriodResult result = detect_period(logistic_orbit(2.8, 200));
    CHECK(result.period == 1);
    CHECK(result.fixed_point);
    CHECK(result.distinct_points == 1);
  }
  SECTION("r = 3.2: period 2") {
    const PeriodResult result = detect_period(logistic_orbit(3.2, 200));
    CHECK(result.period == 2);
    CHECK_FALSE(result.fixed_point);
    CHECK(result.distinct_points == 2);
    CHECK(result.mismatch <= 1e-6);
    // The two points of the 2-cycle are (r + 1 +- sqrt((r + 1)(r - 3))) / (2r) apart by
    // sqrt((r + 1)(r - 3)) / r, which is the cloud's diameter.
    CHECK(result.diameter == Approx(std::sqrt(4.2 * 0.2) / 3.2).epsilon(1e-12));
    CHECK(result.scale == result.diameter);
  }
  SECTION("r = 3.5: period 4, not its multiples") {
    const PeriodResult result = detect_period(logistic_orbit(3.5, 200));
    CHECK(result.period == 4);
    CHECK(result.best_k == 4);
    CHECK(result.distinct_points == 4);
    CHECK(result.points_used == 3 * 4);  // cycles = 2: two periods compared with those before
  }
  SECTION("r = 3.83: the period-3 window") {
    const PeriodResult result = detect_period(logistic_orbit(3.83, 200));
    CHECK(result.period == 3);
    CHECK(result.distinct_points == 3);
  }
}

TEST_CASE("chaotic and quasi-periodic sequences have no period", "[period]") {
  SECTION("logistic map at r = 4") {
    const PeriodResult result = detect_period(logistic_orbit(4.0, 500));
    CHECK(result.period == 0);
    CHECK_FALSE(result.fixed_point);
    CHECK(result.mismatch > 1e-3);  // far from any period, not a near miss
    // Nearly all of the last (cycles + 1) * k_max = 192 points are distinct (two of 192 random
    // points in [0, 1] may fall within 1e-6 of each other).
    CHECK(result.distinct_points >= 180);
    CHECK(result.distinct_points <= 192);
  }
  SECTION("rotation by the golden mean") {
    const PeriodResult result = detect_period(golden_rotation(500));
    CHECK(result.period == 0);
    // The closest returns of a golden-mean rotation within 64 steps miss by ~2 pi / (sqrt(5) 55),
    // i.e. a few percent of the diameter.
    CHECK(result.mismatch > 1e-2);
    CHECK(result.best_k == 55);  // a Fibonacci number: the best rational approximation 34/55
  }
}

TEST_CASE("tolerance, scale and cycles", "[period]") {
  // A period-3 sequence in 3-D with a small perturbation on every point.
  std::vector<Vector> cycle(3, Vector(3));
  cycle[0] << 1.0, 0.0, -1.0;
  cycle[1] << 0.5, 2.0, 0.0;
  cycle[2] << -1.0, 1.0, 0.5;
  const std::vector<double> chaotic = logistic_orbit(4.0, 60);  // aperiodic noise in [0, 1]
  auto noisy = [&](double amplitude) {
    std::vector<Vector> points;
    for (int n = 0; n < 60; ++n) {
      Vector p = cycle[n % 3];
      p[n % 3] += amplitude * (2.0 * chaotic[n] - 1.0);  // |noise| <= amplitude
      points.push_back(p);
    }
    return points;
  };

  SECTION("noise well below tolerance * diameter: period 3") {
    const PeriodResult result = detect_period(noisy(1e-8));
    CHECK(result.period == 3);
    CHECK(result.distinct_points == 3);
  }
  SECTION("noise above it: no period, unless the tolerance is loosened") {
    CHECK(detect_period(noisy(1e-4)).period == 0);
    PeriodOptions loose;
    loose.tolerance = 1e-3;
    CHECK(detect_period(noisy(1e-4), loose).period == 3);
  }
  SECTION("an explicit scale replaces the automatic one") {
    PeriodOptions options;
    options.scale = 1e3;  // tolerance * scale = 1e-3 > 2e-4 mismatch
    const PeriodResult result = detect_period(noisy(1e-4), options);
    CHECK(result.scale == 1e3);
    CHECK(result.period == 3);
  }
  SECTION("one chance repetition is not enough when cycles = 2") {
    // ... a b c d e f x y x y: the last two points repeat the two before, but not the two
    // before those.
    std::vector<double> values{0.11, 0.52, 0.93, 0.24, 0.65, 0.36, 0.7, 0.2, 0.7, 0.2};
    CHECK(detect_period(values).period == 0);
    PeriodOptions once;
    once.cycles = 1;
    CHECK(detect_period(values, once).period == 2);
  }
  SECTION("the floors let a fixed point with rounding noise count as one") {
    std::vector<double> values;
    for (double u : logistic_orbit(4.0, 50)) values.push_back(1e-13 * (u - 0.5));  // aperiodic
    // Around 0 the relative floor is useless, and the default absolute floor 1e-9 gives a
    // radius of 1e-15, below the 1e-13 noise; a floor of 1e-6 (radius 1e-12) admits it.
    CHECK(detect_period(values).period == 0);
    PeriodOptions options;
    options.absolute_floor = 1e-6;
    const PeriodResult result = detect_period(values, options);
    CHECK(result.period == 1);
    CHECK(result.fixed_point);
    // Without floors the noise is judged against its own spread and looks aperiodic.
    options.absolute_floor = 0.0;
    options.relative_floor = 0.0;
    CHECK(detect_period(values, options).period == 0);
  }
  SECTION("the relative floor handles a fixed point away from the origin") {
    std::vector<double> values;
    for (double u : logistic_orbit(4.0, 50)) values.push_back(5.0 + 1e-12 * (u - 0.5));
    const PeriodResult result = detect_period(values);  // scale = 1e-3 * 5: radius 5e-9
    CHECK(result.period == 1);
    CHECK(result.scale == Approx(5e-3).epsilon(1e-9));
  }
  SECTION("identical points with no floors at all") {
    PeriodOptions options;
    options.absolute_floor = 0.0;
    options.relative_floor = 0.0;
    const PeriodResult result = detect_period(std::vector<double>(10, 0.0), options);
    CHECK(result.period == 1);
    CHECK(result.mismatch == 0.0);
  }
}

TEST_CASE("too few points to test a period", "[period]") {
  // cycles = 2 needs 3 points for k = 1 and 6 for k = 2: a 2-cycle seen in 5 points is not
  // testable, and is not reported as anything.
  const std::vector<double> values{0.2, 0.8, 0.2, 0.8, 0.2};
  const PeriodResult result = detect_period(values);
  CHECK(result.period == 0);
  CHECK(result.points_used == 3);  // only k = 1 could be tested
  CHECK(result.best_k == 1);
  const PeriodResult none = detect_period(std::vector<double>{0.2, 0.8});
  CHECK(none.period == 0);
  CHECK(none.points_used == 0);
  CHECK(std::isinf(none.mismatch));
}

TEST_CASE("period detection input errors name the field and the value", "[period][errors]") {
  PeriodOptions options;
  options.k_max = 0;
  CHECK_THROWS_MATCHES(detect_period(logistic_orbit(3.2, 20), options), pwl::InputError,
                       Catch::Matchers::Message("PeriodOptions.k_max = 0 must be >= 1"));
  options = {};
  options.tolerance = -1e-3;
  CHECK_THROWS_WITH(detect_period(logistic_orbit(3.2, 20), options),
                    Contains("tolerance") && Contains("-0.001"));
  CHECK_THROWS_WITH(detect_period(std::vector<Vector>{}), Contains("points") && Contains("0"));

  std::vector<Vector> points(3, Vector::Zero(2));
  points[1][0] = std::nan("");
  CHECK_THROWS_WITH(detect_period(points), Contains("points[1][0]") && Contains("nan"));
  points[1][0] = 0.0;
  points[2] = Vector::Zero(3);
  CHECK_THROWS_WITH(detect_period(points), Contains("points[2]") && Contains("3"));
}
