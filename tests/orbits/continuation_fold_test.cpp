// Continuation across the hysteresis of the single gap oscillator of
// tests/study/parameter_sweep_test.cpp (x'' + 0.1 x' + x + 3 max(0, x − 1.5) = 0.5 sin θt, θ from
// 0.8 to 2): its period-1 branch bends toward higher θ (the spring hardens it) and turns back
// twice. Checked against two independent computations:
//  - a brute-force sweep by the exact solver on a fine θ grid, each point from the last state of
//    the one before, upward and downward: the upward sweep falls off the large-amplitude branch at
//    the upper fold and the downward sweep jumps onto it at the lower fold, each within one grid
//    step;
//  - each fold refined independently: the branch parametrised near the fold by one state component
//    s (which varies monotonically through a fold), θ(s) solved by Newton on φ_T(θ)(y) = y with
//    y_c = s, and its extreme found by golden-section search. The located folds must agree to 1e-8.
#include <Eigen/LU>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "orbit_cases.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

ContinuationResult continue_across_hysteresis() {
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 0.8;
  o.end = 2.0;
  return continue_periodic_orbit(analysis::PointModel(pwl::test::hardening_oscillator(0.8)), Vector::Zero(2), o);
}

std::vector<double> folds_of(const ContinuationResult& r) {
  std::vector<double> folds;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.type == BifurcationType::fold) folds.push_back(b.parameter);
  }
  std::sort(folds.begin(), folds.end());
  return folds;
}

struct Jump {
  double from = 0, to = 0;  // the last grid value on the old branch, the first on the new
};

// The sweep: `count` values from `first` by `step` (negative: downward), each integrated over
// `periods` forcing periods from the final state of the one before; the jump is where the
// amplitude of the Poincaré point, √(x² + (x'/θ)²), changes by more than 0.5.
std::vector<Jump> sweep_jumps(double first, double step, int count, int periods) {
  std::vector<Jump> jumps;
  Vector y = Vector::Zero(2);
  double previous = -1;
  for (int i = 0; i < count; ++i) {
    const double theta = first + i * step;
    const NondimensionalChain c = pwl::test::hardening_oscillator(theta);
    EventDrivenSolver solver(make_chain(c));
    solver.set_state(0.0, y.head(1), y.tail(1));
    solver.advance_to(periods * c.period());
    y = pwl::test::state_of(solver);
    const double amplitude = std::hypot(y(0), y(1) / theta);
    if (previous >= 0 && std::abs(amplitude - previous) > 0.5)
      jumps.push_back({theta - step, theta});
    previous = amplitude;
  }
  return jumps;
}

// θ on the branch through the state with component c equal to s, by Newton on
// (φ_T(θ)(y) − y = 0) in the other component and θ, from (y, θ).
double theta_on_branch(int c, double s, Vector& y, double& theta) {
  const int other = 1 - c;
  y(c) = s;
  const auto residual = [&](const Vector& state, double th, Matrix* M) {
    StroboscopicMap map(analysis::PointCase(pwl::test::hardening_oscillator(th)), MethodSettings{Method::exact}, 1);
    if (M != nullptr) return Vector(map.advance_with_jacobian(state, 1, *M) - state);
    return Vector(map.advance(state, 1) - state);
  };
  for (int it = 0; it < 30; ++it) {
    Matrix M;
    const Vector F = residual(y, theta, &M);
    if (F.lpNorm<Eigen::Infinity>() <= 1e-14) break;
    const double d = 1e-7;
    const Vector dF = (residual(y, theta + d, nullptr) - residual(y, theta - d, nullptr)) / (2 * d);
    Eigen::Matrix2d J;
    J.col(0) = (M - Matrix::Identity(2, 2)).col(other);
    J.col(1) = dF;
    const Eigen::Vector2d step = J.partialPivLu().solve(-Eigen::Vector2d(F(0), F(1)));
    y(other) += step(0);
    theta += step(1);
  }
  return theta;
}

// The extreme (sign +1: largest, −1: smallest) of θ(s) for s between the states a and b of two
// branch points on either side of a fold, by golden-section search.
double refine_fold(const Vector& a, double theta_a, const Vector& b, double theta_b, double sign) {
  const int c = std::abs(a(0) - b(0)) >= std::abs(a(1) - b(1)) ? 0 : 1;
  Vector y = 0.5 * (a + b);
  double theta = 0.5 * (theta_a + theta_b);
  const auto f = [&](double s) { return sign * theta_on_branch(c, s, y, theta); };
  const double g = (std::sqrt(5.0) - 1) / 2;
  double lo = std::min(a(c), b(c)), hi = std::max(a(c), b(c));
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  while (hi - lo > 1e-7) {
    if (f1 > f2) {
      hi = x2, x2 = x1, f2 = f1;
      x1 = hi - g * (hi - lo);
      f1 = f(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2;
      x2 = lo + g * (hi - lo);
      f2 = f(x2);
    }
  }
  return sign * std::max(f1, f2);
}

}  // namespace

TEST_CASE("the gap oscillator's orbit branch has two folds where the brute-force sweeps jump",
          "[orbits]") {
  const ContinuationResult r = continue_across_hysteresis();
  const std::vector<double> folds = folds_of(r);
  REQUIRE(folds.size() == 2);
  const double lower = folds[0], upper = folds[1];
  measured("lower fold", lower);
  measured("upper fold", upper);
  CHECK(upper - lower > 0.05);

  // The brute-force sweeps on a grid of 0.002 from 1.1 to 1.26, 300 periods per value.
  const double h = 0.002;
  const std::vector<Jump> up = sweep_jumps(1.10, h, 81, 300);
  const std::vector<Jump> down = sweep_jumps(1.26, -h, 81, 300);
  REQUIRE(up.size() == 1);
  REQUIRE(down.size() == 1);
  INFO("upward jump " << up[0].from << " -> " << up[0].to << ", downward " << down[0].from << " -> "
                      << down[0].to << "; folds " << lower << ", " << upper);
  // The old branch holds up to the grid value before the fold (the hysteresis lies between the
  // folds), and the jump is within one grid step of it.
  CHECK(up[0].from >= lower);
  CHECK(up[0].from <= upper);
  CHECK(std::abs(up[0].from - upper) <= h);
  CHECK(std::abs(up[0].to - upper) <= h);
  CHECK(down[0].from >= lower);
  CHECK(down[0].from <= upper);
  CHECK(std::abs(down[0].from - lower) <= h);
  CHECK(std::abs(down[0].to - lower) <= h);

  // Along the branch: stable up to the upper fold, one real multiplier beyond +1 between the
  // folds (a saddle), stable again after the lower fold.
  std::size_t turn_up = 0, turn_down = 0;  // the points where θ turns back
  for (std::size_t i = 1; i + 1 < r.points.size(); ++i) {
    const double before = r.points[i].parameter - r.points[i - 1].parameter;
    const double after = r.points[i + 1].parameter - r.points[i].parameter;
    if (before > 0 && after < 0) turn_up = i;
    if (before < 0 && after > 0) turn_down = i;
  }
  REQUIRE(turn_up > 0);
  REQUIRE(turn_down > turn_up);
  int middle = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const BranchPoint& p = r.points[i];
    REQUIRE(p.branch == 0);
    const auto& mu = p.orbit.multipliers;
    const double clear = std::min(std::abs(p.parameter - lower), std::abs(p.parameter - upper));
    if (clear < 1e-3) continue;  // a multiplier within reach of +1
    INFO("theta " << p.parameter << ", |mu| " << mu.largest_modulus());
    if (i > turn_up && i < turn_down) {
      ++middle;
      CHECK(mu.unstable_count() == 1);
      CHECK(mu.values[0].imag() == 0);
      CHECK(mu.values[0].real() > 1);
    } else {
      CHECK(mu.stable());
    }
  }
  CHECK(middle >= 3);
}

TEST_CASE("the located folds of the gap oscillator's orbit branch agree with refined ones to 1e-8",
          "[orbits]") {
  const ContinuationResult r = continue_across_hysteresis();
  int checked = 0;
  for (std::size_t k = 1; k + 1 < r.points.size(); ++k) {
    // k: a branch point where θ turns back; the fold lies between its neighbours.
    const BranchPoint& a = r.points[k - 1];
    const BranchPoint& b = r.points[k + 1];
    const double before = r.points[k].parameter - a.parameter;
    const double after = b.parameter - r.points[k].parameter;
    if (before * after >= 0) continue;
    const bool maximum = before > 0;
    const double refined =
        refine_fold(a.orbit.state, a.parameter, b.orbit.state, b.parameter, maximum ? 1.0 : -1.0);
    // The located fold nearest.
    const Bifurcation* fold = nullptr;
    for (const Bifurcation& f : r.bifurcations) {
      if (f.type == BifurcationType::fold &&
          (fold == nullptr ||
           std::abs(f.parameter - refined) < std::abs(fold->parameter - refined))) {
        fold = &f;
      }
    }
    REQUIRE(fold != nullptr);
    INFO("located " << fold->parameter << ", refined " << refined);
    measured(maximum ? "upper fold: located - refined" : "lower fold: located - refined",
             fold->parameter - refined);
    CHECK(std::abs(fold->parameter - refined) <= 1e-8);
    CHECK(std::abs(fold->multiplier - 1.0) <= 1e-4);
    ++checked;
  }
  CHECK(checked == 2);
}
