// The invariant-curve test by weighted Birkhoff averages: many digits and the exact rotation
// number on smooth invariant curves (a rigid rotation, a non-uniform circle map, an invariant
// circle of the standard map), few digits on chaotic orbits, super-convergence against the plain
// average's 1/N, and input errors that name the field.
#include "pwl/analysis/weighted_birkhoff.hpp"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "pwl/errors.hpp"
#include "test_series.hpp"

using namespace pwl;
using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
const double kGolden = (std::sqrt(5.0) - 1.0) / 2.0;  // golden mean minus 1 = [0; 1, 1, 1, ...]

// Points of a smooth closed curve in R^3 at the angles 2π turns[n]: in the (x, y) plane the curve
// r = 2 + 0.3 cos θ (star-shaped around its centre, which is not the origin: the weighted centre
// is at x = 0.15), and a third coordinate that winds twice.
Matrix curve_points(const std::vector<double>& turns) {
  Matrix points(static_cast<Index>(turns.size()), 3);
  for (std::size_t n = 0; n < turns.size(); ++n) {
    const double theta = kTwoPi * turns[n];
    const double r = 2.0 + 0.3 * std::cos(theta);
    const auto i = static_cast<Index>(n);
    points(i, 0) = r * std::cos(theta);
    points(i, 1) = r * std::sin(theta);
    points(i, 2) = std::cos(2.0 * theta + 0.4);
  }
  return points;
}

// The rigid rotation by rho on the curve.
Matrix rotation_points(int count, double rho) {
  std::vector<double> turns;
  for (int n = 0; n < count; ++n) turns.push_back(std::fmod(0.1 + n * rho, 1.0));
  return curve_points(turns);
}

// The Arnold circle map in turns, x -> x + Ω - (K/2π) sin 2πx (a diffeomorphism for K < 1), lifted.
double circle_map(double x, double omega, double K) {
  return x + omega - K / kTwoPi * std::sin(kTwoPi * x);
}

Matrix circle_map_points(int count, double omega, double K) {
  std::vector<double> turns;
  double x = 0.1;
  for (int n = 0; n < count; ++n) {
    turns.push_back(x);
    x = circle_map(x, omega, K);
    x -= std::floor(x);
  }
  return curve_points(turns);
}

// The rotation number by the plain average of the lifted map over `iterations` from x = 0.1. For
// a circle homeomorphism |F^n(x) - x - n ρ| < 1, so the error is below 1/iterations.
double circle_map_rotation_plain(double omega, double K, long iterations) {
  double x = 0.1;
  for (long n = 0; n < iterations; ++n) x = circle_map(x, omega, K);
  return (x - 0.1) / static_cast<double>(iterations);
}

// Hénon's map (a = 1.4, b = 0.3) from (0.1, 0.1), the first `transient` points left out.
Matrix henon_points(int count, int transient = 1000) {
  const analysis::TangentMap henon = pwl::test::henon_map();
  Vector s(2);
  s << 0.1, 0.1;
  for (int n = 0; n < transient; ++n) s = henon(s, nullptr);
  Matrix points(count, 2);
  for (int n = 0; n < count; ++n) {
    points.row(n) = s.transpose();
    s = henon(s, nullptr);
  }
  return points;
}

// Chirikov's standard map p' = p + K sin x, x' = x + p', with x in [0, 2π) and p in [-π, π).
Matrix standard_map_points(int count, double K, double x, double p, int transient) {
  auto step = [&] {
    p += K * std::sin(x);
    x += p;
    x -= kTwoPi * std::floor(x / kTwoPi);
    p -= kTwoPi * std::floor(p / kTwoPi + 0.5);
  };
  for (int n = 0; n < transient; ++n) step();
  Matrix points(count, 2);
  for (int n = 0; n < count; ++n) {
    points(n, 0) = x;
    points(n, 1) = p;
    step();
  }
  return points;
}

// Angle increments of the points around c in the (0, 1) plane, in turns, on the branch (-1/2, 1/2].
std::vector<double> increments_around(const Matrix& points, const Vector& c) {
  std::vector<double> turns;
  for (Index n = 0; n + 1 < points.rows(); ++n) {
    const double a = std::atan2(points(n, 1) - c[1], points(n, 0) - c[0]);
    const double b = std::atan2(points(n + 1, 1) - c[1], points(n + 1, 0) - c[0]);
    turns.push_back(std::remainder(b - a, kTwoPi) / kTwoPi);
  }
  return turns;
}

double mod1(double x) { return x - std::floor(x); }

// The distance of two rotation numbers on the circle (1 - 1e-12 is close to 0).
double circle_distance(double a, double b) {
  const double d = mod1(a - b);
  return std::min(d, 1.0 - d);
}

}  // namespace

TEST_CASE("weighted Birkhoff: the weights are the normalised bump", "[weighted_birkhoff]") {
  const std::vector<double> w = weighted_birkhoff_weights(10);
  REQUIRE(w.size() == 10);
  CHECK(w[0] == 0.0);
  double total = 0.0;
  for (double v : w) total += v;
  CHECK(total == Approx(1.0).epsilon(1e-15));
  // w(t) = exp(-1/(t(1-t))): w(1/2) / w(1/10) = exp(-4 + 1/0.09).
  CHECK(w[5] / w[1] == Approx(std::exp(-4.0 + 1.0 / 0.09)).epsilon(1e-12));
  CHECK(w[3] == Approx(w[7]).epsilon(1e-14));  // symmetric about t = 1/2
  // The average of a constant is the constant, and of a linear ramp its midpoint (symmetry).
  CHECK(weighted_birkhoff_average(std::vector<double>(50, 2.5)) == Approx(2.5).epsilon(1e-15));
  std::vector<double> ramp;
  for (int n = 0; n <= 100; ++n) ramp.push_back(n);  // 101 values, weights w(n/101)
  // Σ w(n/101) n with w symmetric about n = 50.5 (w(0) = 0 pairs with the missing n = 101).
  CHECK(weighted_birkhoff_average(ramp) == Approx(50.5).epsilon(1e-13));
}

TEST_CASE("weighted Birkhoff: a rigid irrational rotation on a smooth curve",
          "[weighted_birkhoff]") {
  for (double rho : {kGolden, std::sqrt(2.0) - 1.0}) {
    CAPTURE(rho);
    const WeightedBirkhoffResult result = weighted_birkhoff_test(rotation_points(2000, rho));
    // Measured: 3.3e-16 (golden) and 2.2e-16 (sqrt 2 - 1).
    CHECK(std::abs(result.rotation_number - rho) < 1e-13);
    CHECK(result.rotation_digits >= 13.0);  // measured 15.3, 14.9
    CHECK(result.digits >= 10.0);           // measured 12.6, 10.8
    CHECK(result.smooth_invariant_curve);
    CHECK(result.has_rotation);
    CHECK(result.points == 2000);
    CHECK(result.observables_used == 9);
    REQUIRE(result.observable_digits.size() == 9);
    REQUIRE(result.averages.size() == 9);
    // The weighted centre is the average over the uniform measure of the rotation: the mean of
    // (2 + 0.3 cos θ) cos θ is 0.15, of its sine 0, of cos(2θ + 0.4) 0.
    REQUIRE(result.centre.size() == 3);
    CHECK(result.centre[0] == Approx(0.15).margin(1e-12));
    CHECK(result.centre[1] == Approx(0.0).margin(1e-12));
    CHECK(result.centre[2] == Approx(0.0).margin(1e-12));
    CHECK(result.averages[0] == result.centre[0]);
  }
  // The verdict follows options.torus_digits: 12.6 digits are not 14.
  WeightedBirkhoffOptions strict;
  strict.torus_digits = 14.0;
  CHECK_FALSE(
      weighted_birkhoff_test(rotation_points(2000, kGolden), strict).smooth_invariant_curve);
  // The rotation the other way round: -ρ mod 1.
  const WeightedBirkhoffResult reverse = weighted_birkhoff_test(rotation_points(2000, -kGolden));
  CHECK(circle_distance(reverse.rotation_number, 1.0 - kGolden) < 1e-13);
}

TEST_CASE("weighted Birkhoff: a non-uniform circle map on the curve", "[weighted_birkhoff]") {
  // The Arnold circle map at K = 0.5. Ω was tuned (offline, by bisection) so that ρ is the noble
  // number 2 - golden mean = [0; 2, 1, 1, ...]; the 10^7-iteration plain average below confirms
  // it to its own accuracy of 1e-7, independently of the weighted averages.
  const double K = 0.5;
  const double omega = 0.385473612322550;
  const double truth = 1.0 - kGolden;
  const double plain = circle_map_rotation_plain(omega, K, 10'000'000);
  REQUIRE(std::abs(plain - truth) < 1e-7);  // measured 1.1e-9

  const WeightedBirkhoffResult result = weighted_birkhoff_test(circle_map_points(2000, omega, K));
  CHECK(std::abs(result.rotation_number - plain) < 1e-6);   // what the plain average can check
  CHECK(std::abs(result.rotation_number - truth) < 1e-10);  // measured 1.0e-15
  CHECK(result.digits >= 10.0);                             // measured 12.2
  CHECK(result.rotation_digits >= 12.0);                    // measured 15.1
  CHECK(result.smooth_invariant_curve);
}

TEST_CASE("weighted Birkhoff: rotation near 1/2, increments on both sides of half a turn",
          "[weighted_birkhoff]") {
  // Ω tuned so that ρ = [0; 2, 4, 1, 1, 1, ...] = 1/(2 + 1/(4 + golden mean - 1)) ≈ 0.4512. The
  // circle map and the curve spread the increments over about [0.387, 0.514] turns: a cut at
  // ±π, the usual (-π, π], would mix increments of +0.49 and -0.49 turns.
  const double K = 0.5;
  const double omega = 0.451715280355164;
  const double truth = 1.0 / (2.0 + 1.0 / (4.0 + kGolden));
  const double plain = circle_map_rotation_plain(omega, K, 10'000'000);
  REQUIRE(std::abs(plain - truth) < 1e-7);  // measured 2.7e-9

  const Matrix points = circle_map_points(2000, omega, K);
  const WeightedBirkhoffResult result = weighted_birkhoff_test(points);
  CHECK(std::abs(result.rotation_number - plain) < 1e-6);
  CHECK(std::abs(result.rotation_number - truth) < 1e-10);  // measured 5.0e-16
  CHECK(result.rotation_digits >= 12.0);                    // measured 15.2
  CHECK(result.digits >= 9.0);                              // measured 10.8
  CHECK(result.smooth_invariant_curve);
  // The case does exercise the branch: some increments around the centre exceed half a turn.
  const std::vector<double> increments = increments_around(points, result.centre);
  const auto wrapped =
      std::count_if(increments.begin(), increments.end(), [](double d) { return d < 0.0; });
  CHECK(wrapped > 10);
  CHECK(wrapped < static_cast<long>(increments.size()) - 10);
}

TEST_CASE("weighted Birkhoff: an invariant circle of the standard map", "[weighted_birkhoff]") {
  // K = 2, around the elliptic fixed point (π, 0): an invariant circle through (π + 0.6, 0).
  const Matrix points = standard_map_points(2000, 2.0, std::numbers::pi + 0.6, 0.0, 0);
  const WeightedBirkhoffResult result = weighted_birkhoff_test(points);
  CHECK(result.digits >= 9.0);  // measured 11.3
  CHECK(result.smooth_invariant_curve);
  // The plain average of the same increments over 10^6 points, whose error is the bounded
  // oscillation of the angle over 10^6 (the circle is star-shaped around its centre).
  const Matrix many = standard_map_points(1'000'000, 2.0, std::numbers::pi + 0.6, 0.0, 0);
  const std::vector<double> increments = increments_around(many, result.centre);
  double sum = 0.0;
  for (double d : increments) sum += d;
  const double plain = mod1(sum / static_cast<double>(increments.size()));
  CHECK(circle_distance(result.rotation_number, plain) < 1e-5);
  // Near the elliptic point (trace 2 - K = 0) the rotation is a quarter turn, and it moves away
  // from it on outer circles: 0.7606 here.
  CHECK(circle_distance(result.rotation_number, 0.75) < 0.02);
  CHECK(result.rotation_digits >= 10.0);  // measured 11.9
  // The default torus_digits = 6 calls it a curve from 1000 points (7.4 digits) on; 500 points
  // (5.4) are not enough.
  const WeightedBirkhoffResult thousand = weighted_birkhoff_test(points.topRows(1000));
  CHECK(thousand.digits > 7.0);
  CHECK(thousand.smooth_invariant_curve);
  CHECK_FALSE(weighted_birkhoff_test(points.topRows(500)).smooth_invariant_curve);
}

TEST_CASE("weighted Birkhoff: a curve seen in a bad plane", "[weighted_birkhoff]") {
  // The golden-mean rotation θ_n on curves whose projection does not wind once around the centre.
  auto points_of = [](int count, auto&& point) {
    Matrix points(count, 2);
    for (int n = 0; n < count; ++n) {
      const double theta = kTwoPi * std::fmod(0.1 + n * kGolden, 1.0);
      const auto [x, y] = point(theta);
      points(n, 0) = x;
      points(n, 1) = y;
    }
    return points;
  };
  // A crescent (polar angle 0.6π sin θ, radius 2 + 0.3 cos θ): its centre lies in its hollow, the
  // curve does not go around it, the increments spread over more than a turn. The averages of the
  // observables still converge (a smooth curve), the rotation number does not: 2.97 digits.
  const Matrix crescent = points_of(2000, [](double theta) {
    const double phi = 0.6 * std::numbers::pi * std::sin(theta);
    const double r = 2.0 + 0.3 * std::cos(theta);
    return std::pair{r * std::cos(phi), r * std::sin(phi)};
  });
  const WeightedBirkhoffResult bent = weighted_birkhoff_test(crescent);
  CHECK(bent.digits >= 10.0);  // measured 12.5
  CHECK(bent.smooth_invariant_curve);
  CHECK(bent.rotation_digits < 4.0);
  // A projection winding twice around its centre (polar angle 2θ): the rotation number converges
  // to 2ρ mod 1 with many digits, which the digits cannot reveal (the header says so).
  const Matrix twice = points_of(2000, [](double theta) {
    const double r = 2.0 + 0.3 * std::cos(theta);
    return std::pair{r * std::cos(2.0 * theta), r * std::sin(2.0 * theta)};
  });
  const WeightedBirkhoffResult doubled = weighted_birkhoff_test(twice);
  CHECK(std::abs(doubled.rotation_number - mod1(2.0 * kGolden)) < 1e-12);
  CHECK(doubled.rotation_digits >= 12.0);
}

TEST_CASE("weighted Birkhoff: chaotic orbits give few digits", "[weighted_birkhoff]") {
  // Measured digits for N = 250 / 500 / 1000 / 2000 / 16000:
  //   Hénon (a = 1.4, b = 0.3):           1.92 / 1.72 / 1.90 / 2.29 / 2.41
  //   standard map K = 2 from (0.1, 0.1): 0.89 / 1.18 / 1.40 / 1.47 / 1.05
  for (int N : {250, 500, 1000, 2000, 16000}) {
    CAPTURE(N);
    const WeightedBirkhoffResult henon = weighted_birkhoff_test(henon_points(N));
    CHECK(henon.digits < 4.0);
    CHECK_FALSE(henon.smooth_invariant_curve);
    CHECK(henon.rotation_digits < 4.0);
    const WeightedBirkhoffResult standard =
        weighted_birkhoff_test(standard_map_points(N, 2.0, 0.1, 0.1, 1000));
    CHECK(standard.digits < 4.0);
    CHECK_FALSE(standard.smooth_invariant_curve);
  }
}

TEST_CASE("weighted Birkhoff: super-convergence against the plain average's 1/N",
          "[weighted_birkhoff]") {
  // Rotation number error of the weighted average against the truth at N = 25 .. 200 (before it
  // reaches rounding at about N = 400), and of the plain average of the same increments (the
  // largest over N .. N+9, since the plain error oscillates with the phase at which the record
  // ends). Measured: weighted 4.4e-7, 1.3e-8, 1.6e-10, 3.9e-14; plain 6.7e-4, 3.3e-4, 1.8e-4,
  // 9.2e-5.
  WeightedBirkhoffOptions options;
  options.min_points = 20;
  std::vector<double> sizes;
  std::vector<double> weighted_errors;
  std::vector<double> plain_errors;
  for (int N : {25, 50, 100, 200}) {
    const WeightedBirkhoffResult result =
        weighted_birkhoff_test(rotation_points(N, kGolden), options);
    weighted_errors.push_back(std::abs(result.rotation_number - kGolden));
    double worst = 0.0;
    for (int extra = 0; extra < 10; ++extra) {
      const Matrix points = rotation_points(N + extra, kGolden);
      const Vector centre = weighted_birkhoff_test(points, options).centre;
      const std::vector<double> increments = increments_around(points, centre);
      double sum = 0.0;
      for (double d : increments) sum += d;
      const double plain = sum / static_cast<double>(increments.size());
      worst = std::max(worst, circle_distance(plain, kGolden));
    }
    plain_errors.push_back(worst);
    sizes.push_back(N);
  }
  for (std::size_t i = 0; i + 1 < sizes.size(); ++i) {
    CAPTURE(sizes[i]);
    // Each doubling: faster than N^-4 for the weighted average (factor 16), about 2 for the plain.
    CHECK(weighted_errors[i + 1] < weighted_errors[i] / 16.0);
    CHECK(plain_errors[i + 1] > plain_errors[i] / 2.5);
    CHECK(plain_errors[i + 1] < plain_errors[i] / 1.6);
  }
  CHECK(pwl::test::fitted_order(sizes, plain_errors) == Approx(-1.0).margin(0.1));
  CHECK(weighted_errors.back() < 1e-12);
  CHECK(plain_errors.back() > 1e-5);

  // The digits of the observables at N = 250 .. 2000: more than 1.2 digits per doubling (an error
  // falling like 1/N gains 0.3). Measured 5.89 / 7.45 / 10.03 / 12.59.
  std::vector<double> digits;
  for (int N : {250, 500, 1000, 2000}) {
    digits.push_back(weighted_birkhoff_test(rotation_points(N, kGolden)).digits);
  }
  for (std::size_t i = 0; i + 1 < digits.size(); ++i) {
    CAPTURE(i);
    CHECK(digits[i + 1] - digits[i] > 1.2);
  }
  // ... while on the chaotic Hénon attractor they stay below 3 over the same sizes.
  for (int N : {250, 500, 1000, 2000}) CHECK(weighted_birkhoff_test(henon_points(N)).digits < 3.0);
}

TEST_CASE("weighted Birkhoff: periodic orbits and fixed points", "[weighted_birkhoff]") {
  // A period-5 orbit repeats its points: the halves agree to rounding, as on a torus (the caller
  // runs the period search first), and ρ is the rational 2/5 exactly.
  const WeightedBirkhoffResult periodic = weighted_birkhoff_test(rotation_points(1000, 0.4));
  CHECK(periodic.digits >= 13.0);
  CHECK(periodic.smooth_invariant_curve);
  CHECK(std::abs(periodic.rotation_number - 0.4) < 1e-13);
  // A period-2 record as an integration gives it (the 5-DOF chain's at α = 3, θ = 1 alternates
  // between two points, each repeated to about 1e-13): u is 0 or 1 up to about 1e-12 on every
  // coordinate, so sin(π u) varies by rounding only. Measured against its own spread its halves
  // would disagree in the first digit; against its natural size 1 they agree to rounding.
  Matrix two(600, 3);
  for (Index i = 0; i < two.rows(); ++i) {
    const double jitter = 1e-13 * std::sin(1.7 * static_cast<double>(i));
    if (i % 2 == 0) {
      two.row(i) << -0.00847362 + jitter, -0.42518106 - jitter, 1.3 + jitter;
    } else {
      two.row(i) << -0.85799977 - jitter, -1.15825157 + jitter, 0.7 - jitter;
    }
  }
  const WeightedBirkhoffResult alternating = weighted_birkhoff_test(two);
  CHECK(alternating.digits >= 11.0);
  CHECK(alternating.smooth_invariant_curve);  // as any periodic record (see the header)
  // A fixed point: nothing varies, nothing is measured, and it is not called a curve.
  const Matrix still = Matrix::Constant(300, 4, 0.25);
  WeightedBirkhoffOptions no_rotation;
  no_rotation.rotation = false;
  const WeightedBirkhoffResult fixed = weighted_birkhoff_test(still, no_rotation);
  CHECK(fixed.observables_used == 0);
  CHECK_FALSE(fixed.smooth_invariant_curve);
  CHECK_FALSE(fixed.has_rotation);
  CHECK(fixed.digits == Approx(-std::log10(std::numeric_limits<double>::epsilon())));
}

TEST_CASE("weighted Birkhoff: scale-free, and custom observables", "[weighted_birkhoff]") {
  const Matrix points = rotation_points(2000, kGolden);
  const double reference = weighted_birkhoff_test(points).digits;
  // Units and offsets do not matter (up to the rounding of the shifted points themselves).
  const Matrix small = 1e-6 * points;
  const Matrix shifted = (points.array() + 100.0).matrix();
  CHECK(weighted_birkhoff_test(small).digits == Approx(reference).margin(0.5));
  CHECK(weighted_birkhoff_test(shifted).digits >= 10.0);
  CHECK(weighted_birkhoff_test(shifted).rotation_number == Approx(kGolden).margin(1e-12));

  // One observable of the caller's: the product of the first two coordinates.
  WeightedBirkhoffOptions options;
  options.observables = {[](const Vector& p) { return p[0] * p[1]; }};
  const WeightedBirkhoffResult torus = weighted_birkhoff_test(points, options);
  REQUIRE(torus.observable_digits.size() == 1);
  CHECK(torus.observables_used == 1);
  CHECK(torus.digits == torus.observable_digits[0]);
  CHECK(torus.digits >= 11.0);
  CHECK(torus.centre[0] == Approx(0.15).margin(1e-12));
  CHECK(weighted_birkhoff_test(henon_points(2000), options).digits < 4.0);
  // The plane of the rotation number: coordinates (1, 0) see the rotation reversed.
  WeightedBirkhoffOptions swapped;
  swapped.plane_first = 1;
  swapped.plane_second = 0;
  CHECK(circle_distance(weighted_birkhoff_test(points, swapped).rotation_number, 1.0 - kGolden) <
        1e-12);
}

TEST_CASE("weighted Birkhoff input errors name the field and the value",
          "[weighted_birkhoff][errors]") {
  const Matrix points = rotation_points(300, kGolden);
  CHECK_THROWS_MATCHES(
      weighted_birkhoff_test(rotation_points(150, kGolden)), pwl::InputError,
      Catch::Matchers::Message(
          "points: 150 rows, fewer than WeightedBirkhoffOptions.min_points = 200"));
  Matrix bad = points;
  bad(17, 1) = std::nan("");
  CHECK_THROWS_WITH(weighted_birkhoff_test(bad), Contains("points(17, 1)") && Contains("nan"));
  bad(17, 1) = -std::numeric_limits<double>::infinity();
  CHECK_THROWS_WITH(weighted_birkhoff_test(bad), Contains("points(17, 1)") && Contains("-inf"));
  CHECK_THROWS_AS(weighted_birkhoff_test(Matrix(300, 0)), pwl::InputError);

  WeightedBirkhoffOptions options;
  options.torus_digits = 0.0;
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("torus_digits = 0"));
  options = {};
  options.torus_digits = std::nan("");
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("torus_digits = nan"));
  options = {};
  options.min_points = 5;
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("min_points = 5"));
  options = {};
  options.plane_second = 3;
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options),
                    Contains("plane_second = 3") && Contains("dimension 3"));
  options = {};
  options.plane_first = 1;
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("plane_second = 1"));
  options = {};
  options.plane_first = -1;
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("plane_first = -1"));
  options = {};
  options.constant_tolerance = 2.0;
  std::string why;
  CHECK_FALSE(options.is_valid(&why));
  CHECK_THAT(why, Contains("constant_tolerance = 2"));
  options = {};
  options.observables = {[](const Vector& p) { return p[0]; }, PointObservable{}};
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options), Contains("observables[1]"));
  options.observables[1] = [](const Vector& p) {
    return p[0] > 1.0 ? std::numeric_limits<double>::quiet_NaN() : p[1];
  };
  CHECK_THROWS_WITH(weighted_birkhoff_test(points, options),
                    Contains("observables[1]") && Contains("nan"));
  // Points of dimension 1 have no plane; without the rotation they are fine.
  const Matrix line = points.col(0);
  CHECK_THROWS_WITH(weighted_birkhoff_test(line), Contains("plane_second = 1"));
  options = {};
  options.rotation = false;
  CHECK_NOTHROW(weighted_birkhoff_test(line, options));
  // A rotation that is not measured does not need a valid plane.
  options.plane_first = options.plane_second = 0;
  CHECK_NOTHROW(weighted_birkhoff_test(line, options));

  CHECK_THROWS_WITH(weighted_birkhoff_weights(1), Contains("N = 1"));
  CHECK_THROWS_AS(weighted_birkhoff_average(std::vector<double>{1.0}), pwl::InputError);
}
