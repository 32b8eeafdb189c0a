// A period doubling on a long chain, matrix-free: the paper's kind of chain (α = 2, ζ = 0.2,
// Δ̃ = 0, loads ±1 on alternate masses) of PWL_DOUBLING_MASSES masses has, past the Neimark–Sacker
// points where its period-1 orbit lost stability, a multiplier crossing −1. Followed by the
// matrix-free continuation (Newton–Krylov on the bordered system, Arnoldi's leading multipliers,
// no monodromy formed) and by the dense one (the whole monodromy at every point):
//  - the period doubling is found by both and located within 1e-8 of each other in θ, with its
//    multiplier within 1e-6 of −1;
//  - both count the same multipliers outside the unit circle at every point of the period-1
//    branch (an unstable branch: many of them);
//  - the matrix-free continuation switches onto the period-2 branch through the Ritz vector of −1,
//    and its points are genuine period-2 orbits: two periods of an independent integration (the
//    same map, a fresh integrator) bring them back to themselves, one does not.
// (Release build only.)
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <vector>

#include "continuation_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::first_doubling;
using pwl::test::follow;
using pwl::test::measured;
using pwl::test::paper_chain;

namespace {

constexpr int kMasses = 100;
constexpr double kFrom = 0.5192, kTo = 0.5200;

}  // namespace

TEST_CASE("a long chain's period doubling, matrix-free: located as dense and switched onto",
          "[orbits]") {
  const NondimensionalChain chain = paper_chain(kMasses, kFrom);
  const MethodSettings method{Method::pim_switching_banded};
  // The period-1 orbit is unstable here: the state 50 periods after rest is only Newton's guess.
  StroboscopicMap settle(analysis::PointCase(chain), method, 200);
  const Vector guess = settle.advance(Vector::Zero(2 * kMasses), 50);
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = kFrom;
  o.end = kTo;
  o.method = method;
  o.steps_per_period = 200;
  o.max_points = 40;
  o.switch_branches = true;
  o.max_branches = 1;
  // A basis smaller than the 200 state components, so that the eigen-solver (Davidson here:
  // the chain's damping is classical) restarts as on a longer chain (a basis as large as the
  // operator would make its Ritz values exact in one cycle).
  o.shooting.arnoldi.krylov_dimension = 120;
  o.shooting.arnoldi.davidson_dimension = 120;
  const ContinuationResult dense = follow(chain, guess, o, ShootingSolver::dense);
  const ContinuationResult free = follow(chain, guess, o, ShootingSolver::krylov);
  REQUIRE_FALSE(dense.matrix_free);
  REQUIRE(free.matrix_free);
  CHECK(free.monodromies == 0);
  CHECK(free.unconverged_multipliers == 0);

  const Bifurcation* d = first_doubling(dense);
  const Bifurcation* f = first_doubling(free);
  REQUIRE(d != nullptr);
  REQUIRE(f != nullptr);
  measured("long chain: matrix-free period doubling against dense", std::abs(f->parameter - d->parameter));
  CHECK(std::abs(f->parameter - d->parameter) <= 1e-8);
  CHECK(std::abs(f->multiplier + 1.0) <= 1e-6);

  // The same stability along the period-1 branch, point by point.
  int compared = 0, most_unstable = 0;
  for (const BranchPoint& p : free.points) {
    if (p.branch != 0) continue;
    const BranchPoint* q = pwl::test::nearest_point(dense, 0, p.parameter);
    REQUIRE(q != nullptr);
    if (std::abs(q->parameter - p.parameter) > 1e-9) continue;  // the two branches' steps differ
    INFO("theta = " << p.parameter);
    CHECK(p.orbit.multipliers.unstable_count() == q->orbit.multipliers.unstable_count());
    most_unstable = std::max(most_unstable, p.orbit.multipliers.unstable_count());
    ++compared;
  }
  measured("long chain: period-1 points compared", compared);
  measured("long chain: most multipliers outside the circle at one point", most_unstable);
  CHECK(compared >= 3);
  CHECK(most_unstable >= 2);

  // Switched onto: genuine period-2 orbits.
  REQUIRE(f->to_branch == 1);
  const int period_two = pwl::test::check_period_two_branch(
      free, 1, f->parameter, [](double theta) { return paper_chain(kMasses, theta); }, method, 200,
      1e-4, 1e-5);
  measured("long chain: period-2 points switched onto", period_two);
  CHECK(period_two >= 5);
}
