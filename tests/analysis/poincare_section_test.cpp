// Hyperplane crossings and stroboscopic sampling of sampled flows with known solutions: the
// interpolation errors must be small and shrink at the order of the interpolant.
#include "pwl/analysis/poincare_section.hpp"

#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "pwl/errors.hpp"

using pwl::Vector;
using namespace pwl::analysis;
using Catch::Matchers::Contains;

namespace {

constexpr double pi = std::numbers::pi;

Vector circle(double t) {
  Vector s(2);
  s << std::sin(t), std::cos(t);
  return s;
}

Vector circle_rate(double t) {
  Vector s(2);
  s << std::cos(t), -std::sin(t);
  return s;
}

struct CrossingErrors {
  std::size_t count = 0;
  double max_time_error = 0.0;
  double max_state_error = 0.0;  // of the other component, cos(t*)
};

// Samples (sin t, cos t) with step h on [0.05, 400] and measures the crossings of sin t = level
// upwards against t* = asin(level) + 2 pi m.
CrossingErrors measure(double h, bool hermite, double level = 0.3) {
  std::vector<double> times;
  std::vector<Vector> states;
  std::vector<Vector> rates;
  for (double t = 0.05; t <= 400.0; t += h) {
    times.push_back(t);
    states.push_back(circle(t));
    rates.push_back(circle_rate(t));
  }
  HyperplaneSection section;
  section.component = 0;
  section.level = level;
  section.direction = CrossingDirection::up;
  const std::vector<Crossing> crossings =
      hermite ? find_crossings(section, times, states, rates) : find_crossings(section, times, states);
  CrossingErrors errors;
  errors.count = crossings.size();
  const double first = std::asin(level);
  for (const Crossing& c : crossings) {
    const double m = std::round((c.t - first) / (2.0 * pi));
    const double exact = first + 2.0 * pi * m;
    errors.max_time_error = std::max(errors.max_time_error, std::abs(c.t - exact));
    errors.max_state_error = std::max(errors.max_state_error, std::abs(c.state[1] - std::cos(exact)));
    CHECK(c.state[0] == level);
    CHECK(c.upward);
  }
  return errors;
}

}  // namespace

TEST_CASE("crossing times of a sampled circle converge at the interpolant's order", "[section]") {
  // 64 crossings in [0.05, 400] (asin(0.3) + 2 pi m for m = 0..63), at positions spread over the
  // steps, so the maximum error is that of the worst position and its ratio is the order's.
  const double h = 0.2;
  const CrossingErrors linear = measure(h, false);
  const CrossingErrors linear_half = measure(h / 2, false);
  const CrossingErrors hermite = measure(h, true);
  const CrossingErrors hermite_half = measure(h / 2, true);
  const CrossingErrors hermite_quarter = measure(h / 4, true);
  CHECK(linear.count == 64);
  CHECK(linear_half.count == 64);
  CHECK(hermite.count == 64);
  CHECK(hermite_half.count == 64);

  // Linear: O(h^2), error ratio about 4 per halving.
  CHECK(linear.max_time_error < 1e-2);
  CHECK(linear.max_time_error / linear_half.max_time_error == Approx(4.0).margin(0.8));
  // Hermite: O(h^4), ratio about 16, and far more accurate.
  CHECK(hermite.max_time_error < 3e-6);
  CHECK(hermite_half.max_time_error < 2e-7);
  CHECK(hermite.max_time_error / hermite_half.max_time_error == Approx(16.0).margin(4.0));
  CHECK(hermite_half.max_time_error / hermite_quarter.max_time_error == Approx(16.0).margin(4.0));
  CHECK(hermite.max_time_error < linear.max_time_error / 50.0);
  // The interpolated state follows: cos(t*) to the same orders.
  CHECK(hermite.max_state_error < 1e-4);
  CHECK(linear.max_state_error / linear_half.max_state_error > 3.0);
}

TEST_CASE("crossing directions", "[section]") {
  HyperplaneSection section;
  section.component = 0;
  section.level = 0.3;
  const double h = 0.05;
  std::vector<double> times;
  std::vector<Vector> states;
  for (double t = 0.05; t < 4.0 * pi; t += h) {
    times.push_back(t);
    states.push_back(circle(t));
  }
  section.direction = CrossingDirection::down;
  const std::vector<Crossing> down = find_crossings(section, times, states);
  REQUIRE(down.size() == 2);
  CHECK(down[0].t == Approx(pi - std::asin(0.3)).margin(1e-3));
  CHECK_FALSE(down[0].upward);
  section.direction = CrossingDirection::both;
  const std::vector<Crossing> both = find_crossings(section, times, states);
  REQUIRE(both.size() == 4);
  CHECK(both[0].upward);
  CHECK_FALSE(both[1].upward);
  CHECK(both[2].upward);
  CHECK(both[1].t == down[0].t);
}

TEST_CASE("a sample exactly on the section is counted once", "[section]") {
  // s(t) = t - 1 sampled at 0, 0.5, 1, 1.5, 2: the sample at t = 1 lies on s = 0.
  std::vector<double> times{0.0, 0.5, 1.0, 1.5, 2.0};
  std::vector<Vector> states;
  std::vector<Vector> rates;
  for (double t : times) {
    states.push_back(Vector::Constant(1, t - 1.0));
    rates.push_back(Vector::Constant(1, 1.0));
  }
  HyperplaneSection section;
  section.direction = CrossingDirection::both;
  for (bool hermite : {false, true}) {
    const std::vector<Crossing> crossings =
        hermite ? find_crossings(section, times, states, rates) : find_crossings(section, times, states);
    REQUIRE(crossings.size() == 1);
    CHECK(crossings[0].t == 1.0);
    CHECK(crossings[0].upward);
  }
}

TEST_CASE("Hermite finds a crossing between two samples on the same side", "[section]") {
  // sin t near its peak: both samples below 0.99, the trajectory above it in between.
  const double t0 = pi / 2 - 0.3;
  const double t1 = pi / 2 + 0.3;
  HyperplaneSection section;
  section.level = 0.99;
  CHECK_FALSE(find_crossing(section, t0, circle(t0), t1, circle(t1)).has_value());
  const auto up = find_crossing(section, t0, circle(t0), circle_rate(t0), t1, circle(t1), circle_rate(t1));
  REQUIRE(up.has_value());
  CHECK(up->t == Approx(std::asin(0.99)).margin(1e-2));
  section.direction = CrossingDirection::down;
  const auto down =
      find_crossing(section, t0, circle(t0), circle_rate(t0), t1, circle(t1), circle_rate(t1));
  REQUIRE(down.has_value());
  CHECK(down->t == Approx(pi - std::asin(0.99)).margin(1e-2));
  // With both directions the earlier one is reported.
  section.direction = CrossingDirection::both;
  const auto first =
      find_crossing(section, t0, circle(t0), circle_rate(t0), t1, circle(t1), circle_rate(t1));
  REQUIRE(first.has_value());
  CHECK(first->t == up->t);
}

namespace {

// x = (sin w t, 0.5 cos 2 w t) with its velocity and acceleration.
StateSample oscillator(double t, double w) {
  StateSample s;
  s.t = t;
  s.x.resize(2);
  s.v.resize(2);
  s.a.resize(2);
  s.x << std::sin(w * t), 0.5 * std::cos(2 * w * t);
  s.v << w * std::cos(w * t), -w * std::sin(2 * w * t);
  s.a << -w * w * std::sin(w * t), -2 * w * w * std::cos(2 * w * t);
  return s;
}

struct StroboscopicErrors {
  std::size_t count = 0;
  double x = 0.0;
  double v = 0.0;
};

StroboscopicErrors stroboscopic_errors(double h, bool accelerations) {
  const double w = 1.3;
  const double T = 2 * pi / w;
  const double t0 = 0.1;
  std::vector<StateSample> samples;
  for (long n = 0; n * h <= 20 * T + 1.0; ++n) {  // past the last target t0 + 20 T
    StateSample s = oscillator(n * h, w);
    if (!accelerations) s.a = Vector();
    samples.push_back(s);
  }
  const std::vector<StateSample> strobe = stroboscopic_samples(samples, t0, T);
  StroboscopicErrors errors;
  errors.count = strobe.size();
  for (std::size_t k = 0; k < strobe.size(); ++k) {
    const double t = t0 + static_cast<double>(k) * T;
    CHECK(strobe[k].t == t);
    const StateSample exact = oscillator(t, w);
    errors.x = std::max(errors.x, (strobe[k].x - exact.x).cwiseAbs().maxCoeff());
    errors.v = std::max(errors.v, (strobe[k].v - exact.v).cwiseAbs().maxCoeff());
  }
  return errors;
}

}  // namespace

TEST_CASE("stroboscopic samples between steps are Hermite-accurate", "[section]") {
  const double T = 2 * pi / 1.3;
  const double h = T / 17.3;  // the targets fall at varying places within the steps
  const StroboscopicErrors coarse = stroboscopic_errors(h, false);
  const StroboscopicErrors fine = stroboscopic_errors(h / 2, false);
  CHECK(coarse.count == 21);  // t0 + k T for k = 0..20
  CHECK(fine.count == 21);
  // Displacements from x and v: O(h^4), within the cubic Hermite bound h^4/384 max|x''''|
  // (max|x''''| = 0.5 (2 w)^4 from the second component).
  const double w = 1.3;
  CHECK(coarse.x <= std::pow(h, 4) / 384.0 * 0.5 * std::pow(2 * w, 4));
  CHECK(fine.x <= std::pow(h / 2, 4) / 384.0 * 0.5 * std::pow(2 * w, 4));
  CHECK(coarse.x / fine.x > 12.0);
  // Velocities by differentiating that interpolant: O(h^3).
  CHECK(coarse.v / fine.v > 6.0);
  CHECK(coarse.v / fine.v < 11.0);
  // With accelerations, velocities are Hermite-interpolated too: O(h^4), and more accurate.
  const StroboscopicErrors coarse_a = stroboscopic_errors(h, true);
  const StroboscopicErrors fine_a = stroboscopic_errors(h / 2, true);
  CHECK(coarse_a.x == coarse.x);
  CHECK(coarse_a.v / fine_a.v > 12.0);
  CHECK(coarse_a.v < coarse.v);
}

TEST_CASE("stroboscopic samples on step boundaries are exact", "[section]") {
  const double w = 1.3;
  const double T = 2 * pi / w;
  const double h = T / 50;  // n h and k T agree only to rounding, well within 1e-9 h
  std::vector<StateSample> samples;
  for (int n = 0; n <= 500; ++n) samples.push_back(oscillator(n * h, w));
  const std::vector<StateSample> strobe = stroboscopic_samples(samples, 0.0, T);
  REQUIRE(strobe.size() == 11);
  for (std::size_t k = 0; k < strobe.size(); ++k) {
    CHECK(strobe[k].x == samples[50 * k].x);  // the very same numbers, no interpolation
    CHECK(strobe[k].v == samples[50 * k].v);
    CHECK(strobe[k].a == samples[50 * k].a);
    CHECK(strobe[k].t == static_cast<double>(k) * T);
  }

  SECTION("a target just before the first sample snaps to it") {
    std::vector<StateSample> late(samples.begin(), samples.end());
    late.front().t = 1e-12;  // within 1e-9 of the step h ~ 0.1 after t0 = 0
    const std::vector<StateSample> s = stroboscopic_samples(late, 0.0, T);
    REQUIRE(s.size() == 11);
    CHECK(s[0].x == late.front().x);
    CHECK(s[0].t == 0.0);
  }
  SECTION("the streaming sampler gives the same samples") {
    StroboscopicSampler sampler(0.0, T);
    for (const StateSample& s : samples) sampler.observe(s.t, s.x, s.v, s.a);
    REQUIRE(sampler.samples().size() == strobe.size());
    for (std::size_t k = 0; k < strobe.size(); ++k) CHECK(sampler.samples()[k].x == strobe[k].x);
  }
}

TEST_CASE("section input errors name the field and the value", "[section][errors]") {
  HyperplaneSection section;
  section.component = 5;
  CHECK_THROWS_WITH(find_crossing(section, 0.0, circle(0.0), 0.1, circle(0.1)),
                    Contains("component = 5") && Contains("size 2"));
  section.component = -1;
  CHECK_THROWS_WITH(find_crossing(section, 0.0, circle(0.0), 0.1, circle(0.1)),
                    Contains("component = -1"));
  section = {};
  CHECK_THROWS_WITH(find_crossing(section, 0.1, circle(0.0), 0.1, circle(0.1)),
                    Contains("t0 = 0.1") && Contains("t1 = 0.1"));
  Vector bad = circle(0.1);
  bad[1] = std::nan("");
  CHECK_THROWS_WITH(find_crossing(section, 0.0, circle(0.0), 0.1, bad), Contains("s1[1]"));
  CHECK_THROWS_WITH(find_crossing(section, 0.0, circle(0.0), Vector(3), 0.1, circle(0.1),
                                  circle_rate(0.1)),
                    Contains("ds0"));
  CHECK_THROWS_WITH(find_crossings(section, {0.0, 0.0}, {circle(0.0), circle(0.0)}),
                    Contains("times[1] = 0"));

  CHECK_THROWS_WITH(StroboscopicSampler(0.0, 0.0), Contains("period = 0"));
  CHECK_THROWS_WITH(StroboscopicSampler(0.0, -1.0), Contains("period = -1"));
  StroboscopicSampler sampler(0.0, 1.0);
  sampler.observe(0.0, circle(0.0), circle_rate(0.0));
  CHECK_THROWS_WITH(sampler.observe(0.0, circle(0.0), circle_rate(0.0)), Contains("t = 0"));
  CHECK_THROWS_WITH(sampler.observe(0.5, circle(0.5), Vector(3)), Contains("v: size 3"));
  StroboscopicOptions options;
  options.snap_tolerance = 0.7;
  CHECK_THROWS_WITH(StroboscopicSampler(0.0, 1.0, options), Contains("snap_tolerance = 0.7"));
}
