// A period doubling on the paper's 5-DOF chain (figure 4a: α = 2, Δ̃ = 0, ζ = 0.2): the period-1
// orbit at θ = 1 has a multiplier ≈ −2.25, and the period-2 motion the paper shows is born from it.
// Continuation in θ from 1 upward must meet the multiplier −1, locate it (checked against a
// bisection on θ of the multiplier of orbits found by plain Newton), and switch onto the period-2
// branch there.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

NondimensionalChain chain_at(double theta) { return pwl::test::paper_case_at("4a", theta); }

// The real multiplier nearest −1 of the period-1 orbit at θ (Newton from `guess`, updated).
double multiplier_near_minus_one(double theta, Vector& guess) {
  StroboscopicMap map(analysis::PointCase(chain_at(theta)), MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  const PeriodicOrbit orbit = find_periodic_orbit(map, guess, options);
  guess = orbit.state;
  double best = std::numeric_limits<double>::quiet_NaN();
  for (const auto& mu : orbit.multipliers.values) {
    if (mu.imag() != 0) continue;
    if (std::isnan(best) || std::abs(mu.real() + 1) < std::abs(best + 1)) best = mu.real();
  }
  return best;
}

}  // namespace

TEST_CASE("figure 4a's period-1 orbit doubles its period where continuation says", "[orbits]") {
  // The period-1 orbit at θ = 1.1 (figure 4a's θ = 1 plus 0.1, past its grazings at 1.004 and
  // 1.011, to keep the branches short): between the two points of the period-2 attractor.
  StroboscopicMap map(analysis::PointCase(chain_at(1.1)), MethodSettings{Method::exact}, 1);
  const auto points = pwl::test::poincare_points(map, Vector::Zero(10), 300, 2);
  REQUIRE((points[1] - points[0]).norm() > 0.1);
  const PeriodicOrbit start = find_periodic_orbit(map, 0.5 * (points[0] + points[1]));
  REQUIRE(start.multipliers.values[0].real() < -1);

  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 1.1;
  o.end = 1.2;
  o.switch_branches = true;
  o.max_branches = 1;
  o.max_points = 80;  // per branch
  const ContinuationResult r =
      continue_periodic_orbit(analysis::PointModel(chain_at(1.1)), start.state, o);

  const Bifurcation* pd = nullptr;
  int doublings = 0;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.branch == 0 && b.type == BifurcationType::period_doubling) {
      pd = &b;
      ++doublings;
    }
  }
  REQUIRE(doublings == 1);
  INFO("period doubling at theta = " << pd->parameter << ", multiplier " << pd->multiplier);
  CHECK(pd->period == 1);
  measured("period doubling: |mu + 1|", std::abs(pd->multiplier + 1.0));
  CHECK(std::abs(pd->multiplier + 1.0) <= 1e-6);

  // Independently: bisection on θ of (multiplier nearest −1) + 1 of Newton's orbits.
  double a = pd->parameter - 2e-3, b = pd->parameter + 2e-3;
  Vector guess = pd->state;
  const double fa = multiplier_near_minus_one(a, guess) + 1;
  guess = pd->state;
  const double fb = multiplier_near_minus_one(b, guess) + 1;
  REQUIRE(fa * fb < 0);
  while (b - a > 1e-12) {
    const double m = 0.5 * (a + b);
    guess = pd->state;
    ((multiplier_near_minus_one(m, guess) + 1 > 0) == (fa > 0) ? a : b) = m;
  }
  measured("period doubling: located - bisection", pd->parameter - 0.5 * (a + b));
  CHECK(std::abs(pd->parameter - 0.5 * (a + b)) <= 1e-8);

  // The period-2 branch switched onto starts there.
  REQUIRE(pd->to_branch == 1);
  const BranchPoint* first = nullptr;
  int period_two_points = 0;
  for (const BranchPoint& p : r.points) {
    if (p.branch != 1) continue;
    if (first == nullptr) first = &p;
    ++period_two_points;
    CHECK(p.orbit.period == 2);
  }
  REQUIRE(first != nullptr);
  CHECK(period_two_points >= 5);
  INFO("the period-2 branch starts at theta = " << first->parameter);
  measured("period-2 branch start - period doubling", first->parameter - pd->parameter);
  measured("period-2 branch start: distance from the period-1 orbit",
           (first->orbit.state - pd->state).norm());
  CHECK(std::abs(first->parameter - pd->parameter) <= 1e-5);
  StroboscopicMap there(analysis::PointCase(chain_at(first->parameter)),
                        MethodSettings{Method::exact}, 1);
  const Vector y = first->orbit.state;
  // A genuine period-2 orbit: closes after two periods, not after one, and its two points lie on
  // either side of the period-1 orbit it split from, near it.
  CHECK((there.advance(y, 2) - y).lpNorm<Eigen::Infinity>() <= 1e-9);
  const Vector other = there.advance(y, 1);
  CHECK((other - y).norm() > 1e-4);
  const double d1 = (y - pd->state).norm(), d2 = (other - pd->state).norm();
  CHECK(d1 < 0.1);
  CHECK(d2 < 0.1);
  CHECK((y - pd->state).dot(other - pd->state) < 0);
}
