// The banded higher-order PIM (banded_switching_pim.hpp): the same trajectory as the dense
// switching PIM on a chain whose springs switch all the time, its error against a tight
// kink-located rkf78 reference next to the plain banded PIM's, its measured order where no spring
// switches, and its input checks.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>
#include <vector>

#include <Eigen/LU>

#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_switching_pim.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "pwl/integrators/switching_pim.hpp"
#include "test_series.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::test::fitted_order;
using pwl::test::largest_difference;

namespace {

BandedSwitchingPimOptions banded_options(double step) {
  BandedSwitchingPimOptions o;
  o.pim.step = step;
  return o;
}

std::unique_ptr<Integrator> reference(const GapStructure& s, const Vector& x0) {
  ReferenceOptions r;
  r.method = RungeKuttaMethod::rkf78;
  r.relative_tolerance = r.absolute_tolerance = 1e-12;
  r.locate_kinks = true;
  auto ref = make_reference_integrator(s, r);
  ref->set_state(0.0, x0, Vector::Zero(s.dofs()));
  return ref;
}

}  // namespace

TEST_CASE("banded switching PIM follows the dense one on a 64-mass chain with contacts",
          "[banded][switching]") {
  // The paper's chain (Δ = 0: every spring switches twice per oscillation), started at rest with
  // every spring on its kink: most steps are switching steps.
  const GapStructure s = make_chain(paper_large_chain(64));
  const double eta = 0.02;
  SwitchingPimOptions dense_options;
  dense_options.step = eta;
  auto dense = make_switching_pim(s, dense_options);
  auto banded = make_banded_switching_pim(s, banded_options(eta));
  const Vector zero = Vector::Zero(s.dofs());
  dense->set_state(0.0, zero, zero);
  banded->set_state(0.0, zero, zero);
  double worst = 0.0, largest = 0.0;
  for (int k = 1; k <= 300; ++k) {
    dense->advance_to(k * eta);
    banded->advance_to(k * eta);
    worst = std::max(worst, largest_difference(*dense, *banded));
    largest = std::max(largest, dense->position().cwiseAbs().maxCoeff());
  }
  const SwitchingPimDiagnostics a = dense->diagnostics(), b = banded->diagnostics();
  INFO("largest |x| " << largest << ", difference " << worst << ", switches " << a.switches
                      << " / " << b.switches << ", switching steps " << a.switching_steps
                      << " / " << b.switching_steps);
  CHECK(largest > 0.1);
  CHECK(a.switches > 30);
  CHECK(b.switches == a.switches);
  CHECK(b.switching_steps == a.switching_steps);
  CHECK(b.steps == 300);
  CHECK(worst < 1e-11);
}

TEST_CASE("banded switching PIM: error against kink-located rkf78 far below the plain PIM's",
          "[banded][switching]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  const double eta = 0.02, t_end = 10.0;
  auto truth = reference(s, Vector::Zero(s.dofs()));
  auto pim = make_banded_switching_pim(s, banded_options(eta));
  BandedPimOptions po;
  po.step = eta;
  auto plain = make_banded_pim_integrator(s, po);
  const Vector zero = Vector::Zero(s.dofs());
  pim->set_state(0.0, zero, zero);
  plain->set_state(0.0, zero, zero);
  double worst = 0.0, worst_plain = 0.0;
  for (int k = 1; k <= 20; ++k) {
    const double t = k * t_end / 20;
    truth->advance_to(t);
    pim->advance_to(t);
    plain->advance_to(t);
    worst = std::max(worst, largest_difference(*pim, *truth));
    worst_plain = std::max(worst_plain, largest_difference(*plain, *truth));
  }
  INFO("banded switching PIM " << worst << ", plain banded PIM " << worst_plain << ", switches "
                               << pim->diagnostics().switches);
  CHECK(pim->diagnostics().switches > 20);
  CHECK(worst < 1e-8);
  CHECK(worst < 1e-3 * worst_plain);
}

TEST_CASE("banded switching PIM: order d + 3 where no spring switches", "[banded][switching]") {
  // Preloaded springs (Δ = -20) held in contact by a constant load of 40 on every mass, started
  // at rest at the static equilibrium ((K1 + K2) x = 40 + K2 Δ). The harmonic loads shake the
  // chain by far less than the 20 or more that separate it from the kinks, so no spring
  // switches, but the force follows the motion and is not linear in time: the plain PIM is
  // second order here and the default switching PIM (d = 2 with the end slope) is fifth order.
  ChainParameters p = paper_large_chain(60);
  p.gap = {-20.0};
  for (int i = 0; i < p.masses; ++i) p.loads.push_back({i, 40.0, 0.0, M_PI / 2});
  const GapStructure s = make_chain(p);
  const Matrix k_all = Matrix(s.stiffness) + Matrix::Identity(s.dofs(), s.dofs());
  const Vector x0 = k_all.lu().solve(Vector::Constant(s.dofs(), 20.0));
  const double t_end = 2.0;
  auto truth = reference(s, x0);
  truth->advance_to(t_end);
  std::vector<double> steps, errors;
  for (double eta : {0.4, 0.2, 0.1, 0.05}) {
    auto pim = make_banded_switching_pim(s, banded_options(eta));
    pim->set_state(0.0, x0, Vector::Zero(s.dofs()));
    pim->advance_to(t_end);
    CHECK(pim->diagnostics().switches == 0);
    CHECK(pim->diagnostics().switching_steps == 0);
    steps.push_back(eta);
    errors.push_back(largest_difference(*pim, *truth));
  }
  const double order = fitted_order(steps, errors);
  INFO("errors " << errors[0] << " ... " << errors.back() << ", order " << order);
  CHECK(errors.back() > 1e-10);  // well above the reference's own error
  CHECK(order > 2 + 2.5);
}

TEST_CASE("banded switching PIM: bad input names the field", "[banded][switching]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  BandedSwitchingPimOptions o;
  std::string why;
  CHECK(!o.is_valid(&why));  // no step
  CHECK(why.find("pim.step") != std::string::npos);
  o.pim.step = 0.02;
  CHECK(o.is_valid(&why));
  o.pim.force_degree = 9;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("force_degree = 9") != std::string::npos);
  CHECK_THROWS_AS(make_banded_switching_pim(s, o), InputError);
  o.pim.force_degree = 2;
  o.band.tolerance = 2.0;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("band.tolerance = 2") != std::string::npos);
  o.band.tolerance = 1e-15;
  o.lcp.dominance_limit = 1.5;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("lcp.dominance_limit") != std::string::npos);
  o.lcp.dominance_limit = 0.5;
  SECTION("a step too large for the contact stiffness names the step") {
    ChainParameters stiff = paper_large_chain(60);
    stiff.k2 = {1e6};
    try {
      make_banded_switching_pim(make_chain(stiff), o);
      FAIL("no InputError");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("step") != std::string::npos);
    }
  }
  SECTION("a mass matrix that is not diagonal") {
    GapStructure full = s;
    Matrix M = Matrix(full.mass);
    M(0, 1) = M(1, 0) = 0.1;
    full.mass = to_sparse(M);
    CHECK_THROWS_AS(make_banded_switching_pim(full, o), InputError);
  }
}
