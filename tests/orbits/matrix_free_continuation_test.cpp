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
#include <cstdio>
#include <cstdlib>
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

TEST_CASE("with GMRES recycling the matrix-free branch is the same branch", "[orbits]") {
  // Plain GMRES (60 vectors, nothing recycled) against GCRO-DR cycles of 4 vectors of which 2 are
  // recycled from one cycle to the next (gmres.hpp): the 11 unknowns of each bordered system need
  // restarts there (cycles of 8 did not: the solves are that short). The branch, its period
  // doubling and its stability must not change beyond the corrector's tolerance. Restarted GMRES
  // on cycles of the same 4 vectors, nothing recycled, is the control: with no space GCRO-DR is
  // that GMRES bit for bit, so a different count shows the recycled vectors were used. (Cheaper
  // they are not, two new vectors a cycle being too few: 2065 products against 1687.)
  const NondimensionalChain chain = pwl::test::paper_case_at("4a", 1.1);
  const MethodSettings method{Method::exact};
  const Vector start = figure_4a_orbit(chain, method);
  ContinuationOptions plain_options = figure_4a_options(method);
  plain_options.shooting.gmres_recycled = 0;
  ContinuationOptions short_options = plain_options;
  short_options.shooting.gmres_dimension = 4;
  short_options.shooting.gmres_restarts = 100;
  ContinuationOptions recycled_options = short_options;
  recycled_options.shooting.gmres_recycled = 2;
  const ContinuationResult plain = follow(chain, start, plain_options, ShootingSolver::krylov);
  const ContinuationResult restarted = follow(chain, start, short_options, ShootingSolver::krylov);
  const ContinuationResult recycled =
      follow(chain, start, recycled_options, ShootingSolver::krylov);
  // The same space carried to each new operator (the next Newton iterate, the next point) by
  // forming its image again (ShootingOptions::gmres_reform): the same branch again, on other
  // products.
  ContinuationOptions carried_options = recycled_options;
  carried_options.shooting.gmres_reform = true;
  const ContinuationResult carried = follow(chain, start, carried_options, ShootingSolver::krylov);
  INFO("GMRES products: 60 vectors " << plain.krylov_products << ", cycles of 4 "
                                     << restarted.krylov_products << ", recycled "
                                     << recycled.krylov_products);
  if (std::getenv("PWL_TEST_VERBOSE") != nullptr) {
    std::printf("GMRES products: 60 vectors %ld, cycles of 4 %ld, cycles of 4 recycling 2 %ld, "
                "and carrying them across operators %ld\n",
                static_cast<long>(plain.krylov_products),
                static_cast<long>(restarted.krylov_products),
                static_cast<long>(recycled.krylov_products),
                static_cast<long>(carried.krylov_products));
  }
  CHECK(recycled.krylov_products != restarted.krylov_products);
  CHECK(carried.krylov_products != recycled.krylov_products);
  const Bifurcation* a = pwl::test::first_doubling(plain);
  const Bifurcation* b = pwl::test::first_doubling(recycled);
  const Bifurcation* c = pwl::test::first_doubling(restarted);
  REQUIRE(a != nullptr);
  REQUIRE(b != nullptr);
  REQUIRE(c != nullptr);
  CHECK(std::abs(c->parameter - a->parameter) <= 1e-8);
  measured("figure 4a: period doubling with recycling against without",
           std::abs(a->parameter - b->parameter));
  CHECK(std::abs(a->parameter - b->parameter) <= 1e-8);
  CHECK(plain.bifurcations.size() == recycled.bifurcations.size());
  const Bifurcation* d = pwl::test::first_doubling(carried);
  REQUIRE(d != nullptr);
  measured("figure 4a: period doubling with the space carried across operators against without",
           std::abs(a->parameter - d->parameter));
  CHECK(std::abs(a->parameter - d->parameter) <= 1e-8);
  CHECK(plain.bifurcations.size() == carried.bifurcations.size());
  // Both branches' points carry one stability on each side of the doubling, the same in both, and
  // it changes there.
  int kinds[3][2] = {};  // [run][side]: 1 points stable; −1 unstable; 2 mixed
  const ContinuationResult* runs[3] = {&plain, &recycled, &carried};
  for (int run = 0; run < 3; ++run) {
    int seen[2][2] = {{0, 0}, {0, 0}};  // [side][stable]
    for (const BranchPoint& pt : runs[run]->points) {
      if (pt.branch != 0 || std::abs(pt.parameter - a->parameter) < 1e-6) continue;
      ++seen[pt.parameter > a->parameter][pt.orbit.stable() ? 1 : 0];
    }
    for (int side = 0; side < 2; ++side) {
      INFO("run " << run << ", side " << side << ": " << seen[side][1] << " stable, "
                  << seen[side][0] << " unstable");
      CHECK(seen[side][0] + seen[side][1] >= 3);
      kinds[run][side] = seen[side][0] > 0 && seen[side][1] > 0 ? 2 : seen[side][1] > 0 ? 1 : -1;
    }
  }
  CHECK(kinds[0][0] == kinds[1][0]);
  CHECK(kinds[0][1] == kinds[1][1]);
  CHECK(kinds[0][0] == kinds[2][0]);
  CHECK(kinds[0][1] == kinds[2][1]);
  CHECK(kinds[0][0] != 2);
  CHECK(kinds[0][1] != 2);
  CHECK(kinds[0][0] == -kinds[0][1]);
}

TEST_CASE("matrix-free continuation claims no stability change from multipliers that did not converge",
          "[orbits]") {
  // The same branch with the eigen-solver starved (a basis of 3 for 10 state components, no
  // restart; Arnoldi's and Davidson's alike): its
  // Ritz values are not the multipliers, and the period doubling the dense continuation locates
  // on this branch must not be claimed from them, nor any other stability change; the result
  // counts the points and says why in a note.
  const NondimensionalChain chain = pwl::test::paper_case_at("4a", 1.1);
  const MethodSettings method{Method::exact};
  ContinuationOptions o = figure_4a_options(method);
  o.shooting.arnoldi.count = 2;
  o.shooting.arnoldi.krylov_dimension = 3;
  o.shooting.arnoldi.davidson_dimension = 3;
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
