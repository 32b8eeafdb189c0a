// The paper's step rule against the dense exponential of the whole chain: at the step it picks
// the energy stays within q degrees of freedom, at twice that step it does not.
#include <catch2/catch.hpp>

#include "pwl/integrators/banded_step_rule.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/precise_exponential.hpp"

using namespace pwl;

namespace {

// Largest, over the rows and the four blocks of the dense T, of the entries more than q from the
// diagonal relative to that block row's sum (the rule's measure).
double leaked(const GapStructure& s, double eta, Index q) {
  const Index n = s.dofs();
  const Matrix T = precise_exponential(state_matrix(s), eta);
  double worst = 0.0;
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (Index i = 0; i < n; ++i) {
        double total = 0.0, beyond = 0.0;
        for (Index j = 0; j < n; ++j) {
          const double v = std::abs(T(a * n + i, b * n + j));
          total += v;
          if (std::abs(i - j) > q) beyond += v;
        }
        worst = std::max(worst, beyond / total);
      }
  return worst;
}

}  // namespace

TEST_CASE("The step rule shortens the step when the band is too small", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  BandedStepRuleOptions o;
  o.wished_step = 0.32;
  for (Index q : {2, 3, 5}) {
    o.band = q;
    const BandedStepChoice c = select_banded_step(s, o);
    INFO("q = " << q << ": step " << c.step << " after doubling " << c.exceeded_after);
    CHECK(c.step < o.wished_step);
    CHECK(c.exceeded_after > 0);
    // A power-of-two fraction of the wished step, whose exponential the doublings passed through.
    const double ratio = o.wished_step / c.step;
    CHECK(ratio == Approx(std::exp2(std::round(std::log2(ratio)))).epsilon(1e-14));
    // Independent truth: the dense exponential of the whole chain.
    CHECK(leaked(s, c.step, q) <= o.tolerance);
    CHECK(leaked(s, 2 * c.step, q) > o.tolerance);
    CHECK(c.leaked_at_step <= o.tolerance);
    CHECK(c.leaked_at_step == Approx(leaked(s, c.step, q)).epsilon(0.05).margin(1e-17));
  }
  // The paper's 11-dof substructure (q = 5) picks its η = 0.02 s.
  o.band = 5;
  CHECK(select_banded_step(s, o).step == Approx(0.02).epsilon(1e-12));
}

TEST_CASE("The step rule keeps the wished step when the band is wide enough", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  BandedStepRuleOptions o;
  o.wished_step = 0.32;
  o.band = 12;
  const BandedStepChoice c = select_banded_step(s, o);
  CHECK(c.exceeded_after == -1);
  CHECK(c.step == o.wished_step);
  CHECK(leaked(s, c.step, o.band) <= o.tolerance);
  CHECK(c.leaked.size() == static_cast<std::size_t>(o.exponential.doublings + 1));
  // A uniform chain, R = q + guard: the R rows nearest the wall (their substructures are
  // shorter), one interior row, and the R + 1 rows whose substructure holds the free end.
  CHECK(c.substructures == 2 * (o.band + o.guard) + 2);
}

TEST_CASE("The step rule rejects bad options by name", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(30));
  BandedStepRuleOptions o;
  o.wished_step = 0.1;
  o.band = 0;
  CHECK_THROWS_WITH(select_banded_step(s, o), Catch::Contains("band = 0"));
  o.band = 3;
  o.wished_step = -1.0;
  CHECK_THROWS_WITH(select_banded_step(s, o), Catch::Contains("wished_step = -1"));
  // Energy crosses more than one dof even within τ0 = η1 / 2^20.
  o.band = 1;
  o.wished_step = 1e7;
  CHECK_THROWS_WITH(select_banded_step(s, o), Catch::Contains("larger band"));
}
