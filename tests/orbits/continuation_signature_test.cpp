// No bifurcation missed along a branch: every change of the multipliers' signature between two
// points of a continuation (the multipliers outside the unit circle, by kind) is explained by
// events located inside the step, and a step holding more than one event is cut until each sits
// alone in its interval.
//
// Three cases, each against an independent computation:
//  - figure 5's chain (α = 5, ζ = 0.2, Δ̃ = 0) just past the grazing of spring 3 at θ = 1.4836856:
//    the complex pair near −0.94 ± 0.30i shrinks past the grazing, turns real near θ = 1.4840, and
//    one of the two real multipliers crosses −1 before θ = 1.4845, all inside one step of the
//    continuation. The period doubling is located against a bisection on the sign of det(M + I)
//    of orbits found by plain Newton at 1e-13, and its period-2 branch switched onto.
//  - a bilinear oscillator (one mass, α = 30, ζ = 0.05, Δ̃ = 0, Q = 1) followed down in θ with
//    steps of up to 0.3: one step goes from a complex pair inside the circle to a real multiplier
//    below −1, and the period doubling is found and located.
//  - figure 5's period-2 branch near θ = 1.0094 and 1.0286, where a real multiplier crosses +1
//    (a fold) and, within the same step, meets a second real multiplier beyond +1 and leaves the
//    real axis as a complex pair outside the circle: the step is cut, and each fold located.
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <limits>

#include "orbit_cases.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::measured;

namespace {

// The multipliers outside the unit circle by kind.
struct Counts {
  int above_one = 0, below_minus_one = 0, complex_pairs = 0;
};
Counts counts(const FloquetMultipliers& mu) {
  Counts c;
  for (const auto& m : mu.values) {
    if (std::abs(m) <= 1) continue;
    if (std::abs(m.imag()) <= 1e-9 * std::abs(m)) {
      (m.real() > 0 ? c.above_one : c.below_minus_one) += 1;
    } else if (m.imag() > 0) {
      ++c.complex_pairs;
    }
  }
  return c;
}

bool all_complex(const FloquetMultipliers& mu) {
  for (const auto& m : mu.values) {
    if (std::abs(m.imag()) <= 1e-9 * std::abs(m)) return false;
  }
  return true;
}

// The sign of det(M + I) = Π (μ_i + 1) of the period-k orbit of `chain` near `guess` (Newton at
// 1e-13; `guess` is updated): (−1) to the number of real multipliers below −1.
int sign_of_det_m_plus_i(const NondimensionalChain& chain, int period, Vector& guess) {
  StroboscopicMap map(analysis::PointCase(chain), MethodSettings{Method::exact}, 1);
  ShootingOptions options;
  options.tolerance = 1e-13;
  options.period = period;
  const PeriodicOrbit orbit = find_periodic_orbit(map, guess, options);
  guess = orbit.state;
  std::complex<double> product = 1.0;
  for (const auto& m : orbit.multipliers.values) product *= m + 1.0;
  return product.real() > 0 ? 1 : -1;
}

// θ where det(M + I) changes sign between a and b, by bisection to 1e-12 on orbits of `make(θ)`.
template <class Make>
double bisect_period_doubling(Make make, double a, double b, const Vector& state) {
  Vector guess = state;
  const int sa = sign_of_det_m_plus_i(make(a), 1, guess);
  guess = state;
  const int sb = sign_of_det_m_plus_i(make(b), 1, guess);
  REQUIRE(sa != sb);
  while (std::abs(b - a) > 1e-12) {
    const double m = 0.5 * (a + b);
    guess = state;
    (sign_of_det_m_plus_i(make(m), 1, guess) == sa ? a : b) = m;
  }
  return 0.5 * (a + b);
}

// The one bifurcation of `type` on `branch`, which must be the only one.
const Bifurcation& only(const ContinuationResult& r, BifurcationType type, int branch) {
  const Bifurcation* found = nullptr;
  int count = 0;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.type == type && b.branch == branch) {
      found = &b;
      ++count;
    }
  }
  INFO(bifurcation_name(type) << " on branch " << branch);
  REQUIRE(count == 1);
  return *found;
}

// The two consecutive points of `branch` whose parameters bracket p.
std::pair<const BranchPoint*, const BranchPoint*> bracketing(const ContinuationResult& r,
                                                             int branch, double p) {
  const BranchPoint* previous = nullptr;
  for (const BranchPoint& point : r.points) {
    if (point.branch != branch) continue;
    if (previous != nullptr && (previous->parameter - p) * (point.parameter - p) <= 0) {
      return {previous, &point};
    }
    previous = &point;
  }
  FAIL("no two points of branch " << branch << " bracket " << p);
  return {nullptr, nullptr};
}

}  // namespace

TEST_CASE("figure 5's period doubling just past a grazing is found, located and switched onto",
          "[orbits]") {
  const auto chain = [](double theta) { return pwl::test::paper_case_at("5", theta); };
  StroboscopicMap map(analysis::PointCase(chain(1.47)), MethodSettings{Method::exact}, 1);
  const Vector guess = pwl::test::poincare_points(map, Vector::Zero(10), 200, 1).back();
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 1.47;
  o.end = 1.50;
  o.switch_branches = true;
  o.max_branches = 1;
  o.max_points = 60;  // per branch
  const ContinuationResult r = continue_periodic_orbit(analysis::PointModel(chain(1.47)), guess, o);

  // The grazing of spring 3, then the period doubling, a few 1e-4 further on.
  const Bifurcation& grazing = only(r, BifurcationType::grazing, 0);
  CHECK(grazing.spring == 2);
  CHECK(grazing.parameter == Approx(1.4836856).margin(1e-7));
  const Bifurcation& pd = only(r, BifurcationType::period_doubling, 0);
  INFO("period doubling at theta = " << pd.parameter);
  CHECK(pd.parameter > grazing.parameter);
  CHECK(pd.parameter < 1.4845);
  CHECK(pd.located);
  measured("period doubling past the grazing: |mu + 1|", std::abs(pd.multiplier + 1.0));
  CHECK(std::abs(pd.multiplier + 1.0) <= 1e-6);

  // The step it was found in goes from a complex pair inside the circle to a real multiplier
  // below −1: nothing real near −1 at its start.
  const auto [before, after] = bracketing(r, 0, pd.parameter);
  CHECK(counts(before->orbit.multipliers).below_minus_one == 0);
  CHECK(counts(after->orbit.multipliers).below_minus_one == 1);

  // Independently: bisection on the sign of det(M + I) of plain Newton orbits.
  const double truth = bisect_period_doubling(chain, grazing.parameter + 1e-5, 1.4845, pd.state);
  measured("period doubling past the grazing: located - bisection", pd.parameter - truth);
  CHECK(std::abs(pd.parameter - truth) <= 1e-8);

  // Its period-2 branch, switched onto: genuine period-2 orbits starting there.
  REQUIRE(pd.to_branch == 1);
  int period_two = 0;
  const BranchPoint* first = nullptr;
  for (const BranchPoint& p : r.points) {
    if (p.branch != 1) continue;
    if (first == nullptr) first = &p;
    CHECK(p.orbit.period == 2);
    ++period_two;
  }
  REQUIRE(first != nullptr);
  CHECK(period_two >= 10);
  CHECK(std::abs(first->parameter - pd.parameter) <= 1e-5);
  StroboscopicMap there(analysis::PointCase(chain(first->parameter)),
                        MethodSettings{Method::exact}, 1);
  const Vector y = first->orbit.state;
  CHECK((there.advance(y, 2) - y).lpNorm<Eigen::Infinity>() <= 1e-9);
  CHECK((there.advance(y, 1) - y).norm() > 1e-4);
}

TEST_CASE("a complex pair that turns real and crosses -1 within one coarse step is a period "
          "doubling",
          "[orbits]") {
  // The bilinear oscillator's period-1 orbit from θ = 1.3 down to 1.0, with steps of up to 0.3;
  // both correctors.
  const auto chain = [](double theta) { return pwl::test::one_mass(30.0, 0.05, 0.0, 1.0, theta); };
  StroboscopicMap map(analysis::PointCase(chain(1.3)), MethodSettings{Method::exact}, 1);
  const Vector guess = pwl::test::poincare_points(map, Vector::Zero(2), 200, 1).back();
  for (const Corrector corrector : {Corrector::chord, Corrector::newton}) {
    INFO("corrector " << corrector_name(corrector));
    ContinuationOptions o;
    o.parameter = analysis::SweepParameter::theta;
    o.start = 1.3;
    o.end = 1.0;
    o.initial_step = 0.3;
    o.max_step = 0.3;
    o.corrector = corrector;
    const ContinuationResult r =
        continue_periodic_orbit(analysis::PointModel(chain(1.3)), guess, o);
    const Bifurcation& pd = only(r, BifurcationType::period_doubling, 0);
    INFO("period doubling at theta = " << pd.parameter);
    CHECK(pd.located);
    const auto [before, after] = bracketing(r, 0, pd.parameter);
    // Upward in θ the step starts with a complex pair inside the circle and ends with a real
    // multiplier below −1.
    CHECK(all_complex(before->orbit.multipliers));
    CHECK(counts(before->orbit.multipliers).below_minus_one == 0);
    CHECK(counts(after->orbit.multipliers).below_minus_one == 1);
    measured("coarse step: the period doubling's step in theta",
             std::abs(before->parameter - after->parameter));
    const double truth = bisect_period_doubling(chain, std::min(before->parameter, after->parameter),
                                                std::max(before->parameter, after->parameter),
                                                pd.state);
    measured("coarse step: located - bisection", pd.parameter - truth);
    CHECK(std::abs(pd.parameter - truth) <= 1e-8);
  }
}

TEST_CASE("a fold and a collision of multipliers in one step are told apart by cutting the step",
          "[orbits]") {
  const auto chain = [](double theta) { return pwl::test::paper_case_at("5", theta); };
  StroboscopicMap map(analysis::PointCase(chain(0.995)), MethodSettings{Method::exact}, 1);
  const Vector guess = pwl::test::poincare_points(map, Vector::Zero(10), 200, 1).back();
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 0.995;
  o.end = 1.03;
  o.switch_branches = true;
  o.max_branches = 1;
  o.max_points = 150;
  const ContinuationResult r =
      continue_periodic_orbit(analysis::PointModel(chain(0.995)), guess, o);
  CHECK(r.step_cuts >= 1);
  // The period-2 branch born at θ = 1.0098 turns at two folds, each within one step of a collision
  // of two real multipliers beyond +1.
  std::vector<const Bifurcation*> folds;
  for (const Bifurcation& b : r.bifurcations) {
    if (b.branch == 1 && b.type == BifurcationType::fold) folds.push_back(&b);
  }
  REQUIRE(folds.size() == 2);
  for (const Bifurcation* fold : folds) {
    INFO("fold at theta = " << fold->parameter);
    CHECK(fold->located);
    CHECK(std::abs(fold->multiplier - 1.0) <= 1e-6);
    // The branch turns there, so its points do not bracket the parameter: the step is the one
    // nearest the fold whose ends count differently. It has one real multiplier beyond +1 at one
    // end, a complex pair outside and none beyond +1 at the other: more than one event.
    const BranchPoint* previous = nullptr;
    std::pair<const BranchPoint*, const BranchPoint*> step{nullptr, nullptr};
    for (const BranchPoint& point : r.points) {
      if (point.branch != 1) continue;
      if (previous != nullptr) {
        const Counts c0 = counts(previous->orbit.multipliers), c1 = counts(point.orbit.multipliers);
        const bool differ = c0.above_one != c1.above_one || c0.complex_pairs != c1.complex_pairs ||
                            c0.below_minus_one != c1.below_minus_one;
        const auto distance = [&](const auto& s) {
          return std::abs(0.5 * (s.first->parameter + s.second->parameter) - fold->parameter);
        };
        if (differ && (step.first == nullptr ||
                       distance(std::pair{previous, &point}) < distance(step))) {
          step = {previous, &point};
        }
      }
      previous = &point;
    }
    REQUIRE(step.first != nullptr);
    const Counts ca = counts(step.first->orbit.multipliers);
    const Counts cb = counts(step.second->orbit.multipliers);
    measured("fold: its step's distance from the fold",
             std::abs(step.first->parameter - fold->parameter));
    CHECK(std::abs(step.first->parameter - fold->parameter) <= 1e-4);
    CHECK(ca.above_one + cb.above_one == 1);
    CHECK(ca.complex_pairs + cb.complex_pairs == 1);
    CHECK(ca.above_one != cb.above_one);
  }
  CHECK(folds[0]->parameter == Approx(1.0094211).margin(1e-6));
  CHECK(folds[1]->parameter == Approx(1.0286196).margin(1e-6));
}
