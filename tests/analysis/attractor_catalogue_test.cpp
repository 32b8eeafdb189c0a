// Telling attractors apart (attractor_catalogue.hpp) on tails whose truth is known by
// construction: the points of a period-k orbit at every phase, samples of one circle and of two
// circles, and two samples of the Hénon attractor against its mirror image.
#include <catch2/catch.hpp>
#include <cmath>

#include "pwl/analysis/attractor_catalogue.hpp"
#include "pwl/errors.hpp"

using namespace pwl;
using namespace pwl::analysis;

namespace {

// A period-k tail: `rows` points cycling through `orbit` (k rows), starting at phase `phase`,
// each moved by `noise` along a fixed direction (what is left of a still settling approach).
MotionTail periodic_tail(const Matrix& orbit, int rows, int phase, double noise = 0.0) {
  MotionTail t;
  t.period = static_cast<int>(orbit.rows());
  t.regime = "period-" + std::to_string(t.period);
  t.points.resize(rows, orbit.cols());
  for (int r = 0; r < rows; ++r) {
    t.points.row(r) = orbit.row((r + phase) % orbit.rows());
    t.points.row(r).array() += noise;
  }
  return t;
}

// `rows` points of a circle of radius r about (cx, 0) at rotation number ρ from angle a0: a torus
// of a stroboscopic map, seen in two coordinates.
MotionTail circle_tail(double r, double cx, double rho, double a0, int rows,
                       const std::string& regime = "quasi-periodic") {
  MotionTail t;
  t.regime = regime;
  t.points.resize(rows, 2);
  for (int k = 0; k < rows; ++k) {
    const double a = a0 + 2 * M_PI * rho * k;
    t.points(k, 0) = cx + r * std::cos(a);
    t.points(k, 1) = r * std::sin(a);
  }
  return t;
}

// `rows` points of the Hénon map (a = 1.4, b = 0.3) after 1000 iterations from (x0, y0), mirrored
// (x, y) -> (-x, -y) when `mirror`: a chaotic attractor and a disjoint copy of it.
MotionTail henon_tail(double x0, double y0, int rows, bool mirror) {
  double x = x0, y = y0;
  for (int k = 0; k < 1000; ++k) {
    const double xn = 1.0 - 1.4 * x * x + y;
    y = 0.3 * x;
    x = xn;
  }
  MotionTail t;
  t.regime = "chaotic";
  t.points.resize(rows, 2);
  for (int k = 0; k < rows; ++k) {
    const double xn = 1.0 - 1.4 * x * x + y;
    y = 0.3 * x;
    x = xn;
    t.points(k, 0) = mirror ? -x : x;
    t.points(k, 1) = mirror ? -y : y;
  }
  return t;
}

}  // namespace

TEST_CASE("a period-k orbit is one attractor whatever the phase its tail stops at",
          "[attractor_catalogue]") {
  Matrix orbit(3, 4);
  orbit << 1.0, 0.2, -0.3, 0.5,  //
      -0.4, 1.1, 0.6, -0.2,      //
      0.3, -0.9, 0.1, 0.8;
  AttractorCatalogue catalogue;
  CHECK(catalogue.match(periodic_tail(orbit, 64, 0), 10) == 1);
  for (int phase : {1, 2}) CHECK(catalogue.match(periodic_tail(orbit, 64, phase)) == 1);
  // Still settling, 1e-5 of the orbit's size away: the same orbit.
  CHECK(catalogue.match(periodic_tail(orbit, 64, 1, 1e-5)) == 1);
  // A different period-3 orbit (every coordinate moved by 0.05, 4% of its size): another attractor.
  CHECK(catalogue.match(periodic_tail(orbit, 64, 2, 0.05)) == 2);
  // Its first point alone as a period-1 orbit: not the period-3 orbit.
  CHECK(catalogue.match(periodic_tail(orbit.topRows(1), 10, 0)) == 3);
  REQUIRE(catalogue.attractors().size() == 3);
  CHECK(catalogue.attractor(1).motions == 4);
  CHECK(catalogue.attractor(1).first == 10);
  CHECK(catalogue.attractor(1).period == 3);
  CHECK(catalogue.attractor(3).period == 1);
}

TEST_CASE("two period-1 points are told apart relative to their size", "[attractor_catalogue]") {
  // Tiny orbits (size 1e-9): the tolerance is relative, so 1e-11 apart is still two orbits'
  // 1% and 1e-14 apart is one.
  Matrix a(1, 2), b(1, 2), c(1, 2);
  a << 1e-9, 0.0;
  b << 1e-9 + 1e-11, 0.0;
  c << 1e-9 + 1e-14, 0.0;
  AttractorCatalogue catalogue;
  CHECK(catalogue.match(periodic_tail(a, 8, 0)) == 1);
  CHECK(catalogue.match(periodic_tail(b, 8, 0)) == 2);
  CHECK(catalogue.match(periodic_tail(c, 8, 0)) == 1);
}

TEST_CASE("samples of one torus match; two tori and a torus against chaos do not",
          "[attractor_catalogue]") {
  const double rho = (std::sqrt(5.0) - 1.0) / 2.0;
  AttractorCatalogue catalogue;
  CHECK(catalogue.match(circle_tail(1.0, 0.0, rho, 0.0, 64)) == 1);
  // The same circle from another angle, called "uncertain" (a shorter settling): the same torus.
  CHECK(catalogue.match(circle_tail(1.0, 0.0, rho, 1.234, 64, "uncertain")) == 1);
  CHECK(catalogue.match(circle_tail(1.0, 0.0, rho, 4.0, 200)) == 1);
  // A concentric circle 50% larger (0.5 apart, about 5 spacings of 64 points), and one beside it:
  // two more tori.
  CHECK(catalogue.match(circle_tail(1.5, 0.0, rho, 0.0, 64)) == 2);
  CHECK(catalogue.match(circle_tail(1.0, 3.0, rho, 0.0, 64)) == 3);
  // A period-5 orbit on the first circle is no torus.
  MotionTail locked = circle_tail(1.0, 0.0, 0.2, 0.0, 64);
  locked.regime = "period-5";
  locked.period = 5;
  CHECK(catalogue.match(locked) == 4);
  CHECK(catalogue.attractor(1).motions == 3);
}

TEST_CASE("the Hénon attractor from two starts is one attractor, its mirror image another",
          "[attractor_catalogue]") {
  AttractorCatalogue catalogue;
  CHECK(catalogue.match(henon_tail(0.1, 0.1, 200, false)) == 1);
  CHECK(catalogue.match(henon_tail(-0.3, 0.05, 200, false)) == 1);
  CHECK(catalogue.match(henon_tail(0.1, 0.1, 200, true)) == 2);
  CHECK(catalogue.match(henon_tail(0.5, -0.1, 200, true)) == 2);
  // A torus through the attractor's region is none of them.
  CHECK(catalogue.match(circle_tail(0.5, 0.0, 0.3819660112501051, 0.0, 200)) == 3);
}

TEST_CASE("unbounded motions share the attractor at infinity; failed ones have none",
          "[attractor_catalogue]") {
  AttractorCatalogue catalogue;
  MotionTail unbounded{"unbounded", 0, Matrix()};
  MotionTail failed{"failed", 0, Matrix()};
  CHECK(catalogue.match(failed) == 0);
  CHECK(catalogue.match(unbounded, 4) == 1);
  CHECK(catalogue.match(circle_tail(1.0, 0.0, 0.3, 0.0, 32)) == 2);
  CHECK(catalogue.match(unbounded) == 1);
  CHECK(catalogue.attractor(1).name() == "unbounded");
  CHECK(catalogue.attractor(1).motions == 2);
  CHECK(catalogue.attractors().size() == 2);
}

TEST_CASE("bad tails and options are refused with the value", "[attractor_catalogue]") {
  AttractorMatchOptions bad;
  bad.periodic_tolerance = 0.0;
  std::string why;
  CHECK_FALSE(bad.is_valid(&why));
  CHECK(why.find("periodic_tolerance = 0") != std::string::npos);
  bad.periodic_tolerance = 1e-3;
  bad.cloud_factor = std::nan("");
  CHECK_FALSE(bad.is_valid(&why));
  CHECK(why.find("cloud_factor = nan") != std::string::npos);
  CHECK_THROWS_AS(AttractorCatalogue(bad), InputError);

  AttractorCatalogue catalogue;
  Matrix orbit(4, 2);
  orbit.setRandom();
  // A period-4 motion with 3 points of its tail.
  MotionTail short_tail = periodic_tail(orbit, 3, 0);
  short_tail.period = 4;
  short_tail.regime = "period-4";
  CHECK_THROWS_WITH(catalogue.match(short_tail),
                    Catch::Contains("needs at least 4 points of its tail; 3 given"));
  CHECK(catalogue.match(periodic_tail(orbit, 8, 0)) == 1);
  CHECK_THROWS_WITH(catalogue.match(MotionTail{"chaotic", 0, Matrix::Zero(8, 3)}),
                    Catch::Contains("a tail of 3 columns among tails of 2"));
  CHECK_THROWS_WITH(catalogue.match(MotionTail{"spinning", 0, Matrix::Zero(8, 2)}),
                    Catch::Contains("unknown regime 'spinning'"));
  CHECK_THROWS_AS(catalogue.attractor(2), InputError);
}
