// Matrix-free continuation against the dense one where both are cheap: figure 4a's chain with
// solver = krylov at 10 state components (the matrix-free code path: bordered GMRES, Arnoldi's
// Ritz vectors), whose period doubling it must locate where the dense continuation does (within
// 1e-8) and switch onto through the Ritz vector of the multiplier −1, onto genuine period-2
// orbits. The 150-mass comparison is matrix_free_branch_150_test.cpp, the 1000-mass multipliers
// chain1000_multipliers_test.cpp.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "continuation_cases.hpp"

using namespace pwl;
using namespace pwl::orbits;
using pwl::test::follow;
using pwl::test::measured;

namespace {

// Figure 4a's period-1 orbit at θ = 1.1 (Newton from the middle of its settled period-2 motion).
Vector figure_4a_orbit(const NondimensionalChain& chain, const MethodSettings& method) {
  StroboscopicMap map(analysis::PointCase(chain), method, 1);
  const auto points = pwl::test::poincare_points(map, Vector::Zero(10), 300, 2);
  return find_periodic_orbit(map, 0.5 * (points[0] + points[1]), ShootingOptions{}).state;
}

// Its branch in θ from 1.1 toward 1.2, past the period doubling.
ContinuationOptions figure_4a_options(const MethodSettings& method) {
  ContinuationOptions o;
  o.parameter = analysis::SweepParameter::theta;
  o.start = 1.1;
  o.end = 1.2;
  o.method = method;
  o.max_points = 80;
  return o;
}

}  // namespace

TEST_CASE("matrix-free continuation locates figure 4a's period doubling and switches branch",
          "[orbits]") {
  const NondimensionalChain chain = pwl::test::paper_case_at("4a", 1.1);
  const MethodSettings method{Method::exact};
  const Vector start = figure_4a_orbit(chain, method);
  ContinuationOptions o = figure_4a_options(method);
  o.switch_branches = true;
  o.max_branches = 1;
  const ContinuationResult dense = follow(chain, start, o, ShootingSolver::dense);
  const ContinuationResult free = follow(chain, start, o, ShootingSolver::krylov);
  REQUIRE(free.matrix_free);
  const Bifurcation* d = pwl::test::first_doubling(dense);
  const Bifurcation* f = pwl::test::first_doubling(free);
  REQUIRE(d != nullptr);
  REQUIRE(f != nullptr);
  measured("figure 4a: matrix-free period doubling against dense", std::abs(f->parameter - d->parameter));
  CHECK(std::abs(f->parameter - d->parameter) <= 1e-8);
  CHECK(std::abs(f->multiplier + 1.0) <= 1e-6);
  // Switched onto: a period-2 branch of genuine period-2 orbits from the doubling.
  REQUIRE(f->to_branch == 1);
  const int period_two = pwl::test::check_period_two_branch(
      free, 1, f->parameter, [](double theta) { return pwl::test::paper_case_at("4a", theta); },
      method, 1, 1e-3, 1e-4);
  CHECK(period_two >= 5);
}

TEST_CASE("matrix-free continuation claims no stability change from multipliers that did not converge",
          "[orbits]") {
  // The same branch with Arnoldi starved (a basis of 3 for 10 state components, no restart): its
  // Ritz values are not the multipliers, and the period doubling the dense continuation locates
  // on this branch must not be claimed from them, nor any other stability change; the result
  // counts the points and says why in a note.
  const NondimensionalChain chain = pwl::test::paper_case_at("4a", 1.1);
  const MethodSettings method{Method::exact};
  ContinuationOptions o = figure_4a_options(method);
  o.shooting.arnoldi.count = 2;
  o.shooting.arnoldi.krylov_dimension = 3;
  o.shooting.arnoldi.max_restarts = 0;
  const ContinuationResult starved =
      follow(chain, figure_4a_orbit(chain, method), o, ShootingSolver::krylov);
  REQUIRE(starved.matrix_free);
  CHECK(starved.unconverged_multipliers > 0);
  for (const Bifurcation& b : starved.bifurcations) CHECK(b.type == BifurcationType::grazing);
  const bool noted = std::any_of(starved.notes.begin(), starved.notes.end(), [](const std::string& n) {
    return n.find("did not converge") != std::string::npos;
  });
  CHECK(noted);
}
