// Construction from the period (BandedExponentialOptions::from_period, lib/src/banded/
// periodic_cut.hpp): a chain whose middle repeats gets its step operators from a short chain with
// the same ends. Truth: the same operators or stepper with every row built from its own
// substructure (from_period = false). The rows are claimed to be bit for bit the same, so the
// motion over a thousand steps with switches must be too (a hundred where the clearances
// between neighbours switch tens of times a step); chains that do not repeat in the middle, or are
// too short to gain, must be built row by row.
#include <catch2/catch.hpp>
#include <string>

#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/integrators/banded_switching_pim.hpp"
#include "pwl/model/chain_builders.hpp"
#include "step_operator_bits.hpp"

using namespace pwl;

namespace {

struct Pair {
  std::unique_ptr<SwitchingPim> from_period, row_by_row;
};

Pair both(const GapStructure& s, double eta) {
  BandedSwitchingPimOptions o;
  o.pim.step = eta;
  Pair p;
  p.from_period = make_banded_switching_pim(s, o);
  o.band.from_period = false;
  p.row_by_row = make_banded_switching_pim(s, o);
  return p;
}

// Largest difference of x and x' over `steps` steps of eta from the state (x0, 0), checked at
// every step; also returns the switches located and the largest |x|.
struct Run {
  double difference = 0.0;
  double largest = 0.0;
  long switches = 0;
};

Run run(Pair& p, const Vector& x0, double eta, int steps) {
  const Vector zero = Vector::Zero(x0.size());
  p.from_period->set_state(0.0, x0, zero);
  p.row_by_row->set_state(0.0, x0, zero);
  Run r;
  for (int k = 1; k <= steps; ++k) {
    p.from_period->advance_to(k * eta);
    p.row_by_row->advance_to(k * eta);
    r.difference = std::max(
        {r.difference, (p.from_period->position() - p.row_by_row->position()).cwiseAbs().maxCoeff(),
         (p.from_period->velocity() - p.row_by_row->velocity()).cwiseAbs().maxCoeff()});
    r.largest = std::max(r.largest, p.row_by_row->position().cwiseAbs().maxCoeff());
  }
  r.switches = p.row_by_row->diagnostics().switches;
  CHECK(p.from_period->diagnostics().switches == r.switches);
  CHECK(p.from_period->diagnostics().switching_steps ==
        p.row_by_row->diagnostics().switching_steps);
  return r;
}

// The paper's chain with defects at both ends, of different lengths (so the short chain's middle
// is not the long one's), and a clearance spring between every pair of neighbours.
GapStructure defective_chain(int n) {
  ChainParameters p = paper_large_chain(n);
  p.mass.assign(static_cast<std::size_t>(n), 1.0);
  p.k1.assign(static_cast<std::size_t>(n), 1.0);
  for (int i = 0; i < 37; ++i) p.mass[static_cast<std::size_t>(i)] = 1.0 + 0.013 * i;
  p.k1[static_cast<std::size_t>(n - 3)] = 1.8;
  p.loads[5].amplitude = 0.4;
  GapStructure s = make_chain(p);
  for (int i = 0; i + 1 < n; ++i) {
    s.springs.push_back({i, i + 1, -1.0, 0.7, 0.05});  // closes as the neighbours approach
  }
  return s;
}

// Cells of two masses (1 and 1.5 kg, springs 1 and 2.5 N/m between them), each heavy mass tied
// to the light one before it by a clearance whose first listed end is the later mass
// (other_dof < dof), and a pair of stops at every fourth light mass listed in reverse order; the
// loads on the light masses only.
GapStructure two_mass_cells(int n) {
  ChainParameters p = paper_large_chain(n);
  p.mass.assign(static_cast<std::size_t>(n), 1.0);
  p.k1.assign(static_cast<std::size_t>(n), 1.0);
  for (int i = 1; i < n; i += 2) {
    p.mass[static_cast<std::size_t>(i)] = 1.5;
    p.k1[static_cast<std::size_t>(i)] = 2.5;
  }
  std::vector<HarmonicLoad> loads;
  for (const HarmonicLoad& l : p.loads) {
    if (l.dof % 2 == 0) loads.push_back(l);
  }
  p.loads = loads;
  GapStructure s = make_chain(p);
  s.springs.clear();
  for (int i = n - 1; i >= 1; i -= 2) s.springs.push_back({i, i - 1, 1.0, 0.8, 0.02});
  for (int i = n - 4; i >= 0; i -= 4) {
    s.springs.push_back({i, -1, -1.0, 1.2, 0.1});
    s.springs.push_back({i, -1, 1.0, 0.6, 0.1});
  }
  return s;
}

}  // namespace

TEST_CASE("construction from the period: the paper's chain moves bit for bit as built row by row",
          "[banded][switching][period]") {
  // 600 masses, loads alternating (the chain repeats every two masses), from an initial ramp, at
  // the paper's coarsest switching step: every spring switches again and again.
  const int n = 600;
  const double eta = 0.2;
  Pair p = both(make_chain(paper_large_chain(n)), eta);
  CHECK(p.from_period->diagnostics().from_period);
  CHECK_FALSE(p.row_by_row->diagnostics().from_period);
  const Vector x0 = Vector::LinSpaced(n, 0.5, -0.5);
  const Run r = run(p, x0, eta, 1000);
  INFO("switches " << r.switches << ", largest |x| " << r.largest);
  CHECK(r.switches > 300);
  CHECK(r.largest > 0.1);
  CHECK(r.difference == 0.0);
}

TEST_CASE("construction from the period: defects near both ends and springs between neighbours",
          "[banded][switching][period]") {
  const int n = 400;
  const double eta = 0.1;
  const GapStructure s = defective_chain(n);
  Pair p = both(s, eta);
  CHECK(p.from_period->diagnostics().from_period);
  Vector x0 = Vector::Zero(n);
  for (int i = 0; i < n; ++i) x0[i] = 0.3 * std::sin(0.05 * i);
  const Run r = run(p, x0, eta, 100);
  INFO("switches " << r.switches << ", largest |x| " << r.largest);
  CHECK(r.switches > 1000);
  CHECK(r.difference == 0.0);
  // The operators' layout is the long chain's: a tangent column through the same steps agrees too.
  Matrix t1 = Matrix::Zero(2 * n, 2), t2 = t1;
  t1(0, 0) = t2(0, 0) = 1.0;
  t1(n + n / 2, 1) = t2(n + n / 2, 1) = 1.0;
  p.from_period->set_state(0.0, x0, Vector::Zero(n));
  p.row_by_row->set_state(0.0, x0, Vector::Zero(n));
  p.from_period->advance_with_tangent(1.5, t1);
  p.row_by_row->advance_with_tangent(1.5, t2);
  CHECK((t1 - t2).cwiseAbs().maxCoeff() == 0.0);
  CHECK(t1.cwiseAbs().maxCoeff() > 0.0);
}

TEST_CASE("construction from the period: cells of two masses, springs listed backwards",
          "[banded][switching][period]") {
  const int n = 400;
  const double eta = 0.1;
  Pair p = both(two_mass_cells(n), eta);
  CHECK(p.from_period->diagnostics().from_period);
  const Vector x0 = Vector::LinSpaced(n, 0.2, -0.2);
  const Run r = run(p, x0, eta, 100);
  INFO("switches " << r.switches << ", largest |x| " << r.largest);
  CHECK(r.switches > 100);
  CHECK(r.difference == 0.0);
}

TEST_CASE(
    "construction from the period: chains that do not repeat in the middle are built row by row",
    "[banded][switching][period]") {
  SECTION("a defect in the middle") {
    ChainParameters p = paper_large_chain(600);
    p.mass.assign(600, 1.0);
    p.mass[300] = 1.2;
    BandedSwitchingPimOptions o;
    o.pim.step = 0.2;
    CHECK_FALSE(make_banded_switching_pim(make_chain(p), o)->diagnostics().from_period);
  }
  SECTION("too short to leave a quarter out") {
    BandedSwitchingPimOptions o;
    o.pim.step = 0.2;
    CHECK_FALSE(make_banded_switching_pim(make_chain(paper_large_chain(120)), o)
                    ->diagnostics()
                    .from_period);
  }
  SECTION("rows stored one by one (share_rows = false)") {
    BandedSwitchingPimOptions o;
    o.pim.step = 0.2;
    o.band.share_rows = false;
    CHECK_FALSE(make_banded_switching_pim(make_chain(paper_large_chain(600)), o)
                    ->diagnostics()
                    .from_period);
  }
}

namespace {

void check_step_operators_equal(const GapStructure& s, double eta) {
  BandedExponentialOptions band;
  const BandedStepOperators a = make_banded_step_operators(s, eta, band);
  band.from_period = false;
  const BandedStepOperators b = make_banded_step_operators(s, eta, band);
  INFO("laid out " << a.truncation.laid_out << " of " << s.dofs() << " dofs, band "
                   << a.truncation.band);
  CHECK(a.truncation.laid_out >= s.dofs() / 4);
  CHECK(a.truncation.laid_out % 2 == 0);
  pwl::test::check_same_step_operators(a, b);
}

}  // namespace

TEST_CASE("construction from the period: the banded PIM's operators are those built row by row",
          "[banded][period]") {
  SECTION("the paper's chain at the paper's step") {
    check_step_operators_equal(make_chain(paper_large_chain(600)), 0.02);
  }
  SECTION("at a step whose band is wide") {
    check_step_operators_equal(make_chain(paper_large_chain(900)), 0.5);
  }
  SECTION("defects near both ends, springs between neighbours") {
    check_step_operators_equal(defective_chain(700), 0.1);
  }
  SECTION("a band wider than the first cut keeps: the short chain built again for its reach") {
    check_step_operators_equal(make_chain(paper_large_chain(1200)), 4.0);
  }
  SECTION("cells of two masses, springs listed backwards, every fourth mass without one") {
    check_step_operators_equal(two_mass_cells(640), 0.1);
  }
  SECTION("a gap spring on every tenth mass only, gaps that do not repeat") {
    GapStructure s = make_chain(paper_large_chain(800));
    std::vector<GapSpring> sparse;
    for (std::size_t i = 0; i < s.springs.size(); ++i) {
      if (i % 10 == 3) sparse.push_back(s.springs[i]);
    }
    for (std::size_t k = 0; k < sparse.size(); ++k)
      sparse[k].gap = 0.01 * static_cast<double>(k % 7);
    s.springs = sparse;
    check_step_operators_equal(s, 0.05);
  }
}
