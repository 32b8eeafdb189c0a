// The banded stepper against the dense one (make_pim_integrator): the same trajectory, step by
// step, on chains with contacts, uniform and with cells that differ.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>

#include <omp.h>

#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_propagator.hpp"
#include "pwl/integrators/banded_step_operators.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_integrator.hpp"

using namespace pwl;

namespace {

struct Comparison {
  double worst = 0.0;     // max |banded - dense| over x and x' and the steps
  double largest = 0.0;   // max |x| over the steps
  long contact_steps = 0; // steps with some spring force positive
  long pivots = 0;        // LCP pivots: springs that closed or opened
};

Comparison compare(const GapStructure& s, double eta, int steps) {
  PimOptions dense_options;
  dense_options.step = eta;
  BandedPimOptions banded_options;
  banded_options.step = eta;
  auto dense = make_pim_integrator(s, dense_options);
  auto banded = make_banded_pim_integrator(s, banded_options);
  const Vector zero = Vector::Zero(s.dofs());
  dense->set_state(0.0, zero, zero);
  banded->set_state(0.0, zero, zero);
  Comparison c;
  for (int k = 1; k <= steps; ++k) {
    dense->advance_to(k * eta);
    banded->advance_to(k * eta);
    c.worst = std::max(c.worst, (dense->position() - banded->position()).cwiseAbs().maxCoeff());
    c.worst = std::max(c.worst, (dense->velocity() - banded->velocity()).cwiseAbs().maxCoeff());
    c.largest = std::max(c.largest, dense->position().cwiseAbs().maxCoeff());
    if (s.spring_forces(dense->position()).maxCoeff() > 0.0) ++c.contact_steps;
  }
  CHECK(dense->stats().steps == banded->stats().steps);
  CHECK(dense->stats().lcp_pivots == banded->stats().lcp_pivots);
  c.pivots = dense->stats().lcp_pivots;
  return c;
}

}  // namespace

TEST_CASE("Banded and dense steppers give the same trajectory on a 200-mass chain", "[banded]") {
  // The paper's chain (section 4.2) with 200 masses at its step: springs close and open.
  const Comparison c = compare(make_chain(paper_large_chain(200)), 0.02, 1000);
  INFO("largest |x| " << c.largest << ", steps in contact " << c.contact_steps << ", pivots "
                        << c.pivots);
  CHECK(c.contact_steps > 300);
  CHECK(c.pivots > 300);
  CHECK(c.largest > 0.1);
  CHECK(c.worst < 1e-12);
}

TEST_CASE("Banded and dense steppers agree on a chain whose cells differ", "[banded]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  ChainParameters p = paper_large_chain(90);
  p.mass.clear();
  p.k1.clear();
  p.damping.clear();
  p.k2.clear();
  p.gap.clear();
  for (int i = 0; i < 90; ++i) {
    p.mass.push_back(u(rng));
    p.k1.push_back(u(rng));
    p.damping.push_back(0.1 * u(rng));
    p.k2.push_back(4.0 * u(rng));
    p.gap.push_back(0.1 * (u(rng) - 1.0));
  }
  const Comparison c = compare(make_chain(p), 0.05, 600);
  INFO("largest |x| " << c.largest << ", steps in contact " << c.contact_steps << ", pivots "
                        << c.pivots);
  CHECK(c.contact_steps > 200);
  CHECK(c.pivots > 100);
  CHECK(c.worst < 1e-12);
}

TEST_CASE("The banded stepper reports its observer steps and spring forces", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  BandedPimOptions o;
  o.step = 0.1;
  BandedPropagator propagator(make_banded_step_operators(s, o.step), o.lcp);
  propagator.set_state(0.0, Vector::Constant(60, 0.01), Vector::Zero(60));
  // P = k2 max(0, x - Δ) at the start.
  CHECK((propagator.spring_forces() - s.spring_forces(Vector::Constant(60, 0.01))).norm() == 0.0);
  for (int k = 0; k < 30; ++k) propagator.step();
  CHECK(propagator.time() == Approx(3.0).epsilon(1e-15));
  Vector x, v;
  propagator.position(x);
  propagator.velocity(v);
  CHECK(x.size() == 60);
  // The bytes the step operators must occupy, from their sizes: every distinct stored row's
  // values, and per row its first column and its index into the shared rows; with the state, the
  // predicted state and the spring forces now and next. The propagator holds those and its
  // bookkeeping (transposed force columns, the loads' harmonics, the springs' rows), which is no
  // larger than the operators themselves.
  {
    const BandedStepOperators ops = make_banded_step_operators(s, o.step);
    const auto bytes_of = [](const BandedMatrix& a) {
      return static_cast<std::size_t>(a.stored_rows() * a.width()) * sizeof(double) +
             static_cast<std::size_t>(a.rows()) * (sizeof(Index) + sizeof(std::int32_t));
    };
    const std::size_t operators = bytes_of(ops.transition) + bytes_of(ops.force_now) +
                                  bytes_of(ops.force_next) + bytes_of(ops.lcp_matrix);
    const std::size_t state = static_cast<std::size_t>(4 * 60 + 2 * 60) * sizeof(double);
    CAPTURE(propagator.memory_bytes(), operators, state);
    CHECK(propagator.memory_bytes() >= operators + state);
    CHECK(propagator.memory_bytes() <= 2 * (operators + state));
  }

  auto integrator = make_banded_pim_integrator(s, o);
  integrator->set_state(0.0, Vector::Zero(60), Vector::Zero(60));
  int calls = 0;
  double last = 0.0;
  integrator->advance_to(2.0, [&](double t, const Vector& xs, const Vector&) {
    ++calls;
    CHECK(t == Approx(last + 0.1).epsilon(1e-12));
    CHECK(xs.size() == 60);
    last = t;
  });
  CHECK(calls == 20);
  CHECK(integrator->stats().steps == 20);
  CHECK_THROWS_AS(integrator->advance_to(2.05), InputError);
  CHECK(integrator->method() == Method::pim_banded);
  CHECK(method_traits(integrator->method()).banded);
}

TEST_CASE("make_pim_integrator_auto picks banded for long banded chains", "[banded]") {
  PimOptions o;
  o.step = 0.05;
  const auto form = [&](const GapStructure& s) { return make_pim_integrator_auto(s, o)->method(); };
  CHECK(form(make_chain(paper_large_chain(80))) == Method::pim_banded);
  CHECK(method_traits(form(make_chain(paper_large_chain(80)))).banded);
  CHECK(form(make_chain(paper_large_chain(10))) == Method::pim_dense);
  CHECK_FALSE(method_traits(form(make_chain(paper_large_chain(10)))).banded);
  // A spring from one end of the chain to the other is not banded: dense.
  GapStructure far = make_chain(paper_large_chain(80));
  far.springs.push_back({0, 79, 1.0, 1.0, 0.5});
  const BandedLayout layout = banded_layout(far);
  CHECK_FALSE(layout.banded);
  CHECK(layout.spring_reach == 79);
  CHECK(form(far) == Method::pim_dense);
  CHECK(banded_layout(make_chain(paper_large_chain(80))).cell_dofs == 1);
}

TEST_CASE("The banded stepper validates its input and reports divergence", "[banded]") {
  const GapStructure s = make_chain(paper_large_chain(60));
  BandedPimOptions o;
  CHECK_THROWS_WITH(make_banded_pim_integrator(s, o), Catch::Contains("step = 0"));
  o.step = 0.1;
  o.band.tolerance = 2.0;
  CHECK_THROWS_WITH(make_banded_pim_integrator(s, o), Catch::Contains("band.tolerance = 2"));
  o.band.tolerance = 1e-15;
  GapStructure consistent = s;
  consistent.mass.coeffRef(3, 4) = 0.1;
  consistent.mass.coeffRef(4, 3) = 0.1;
  CHECK_THROWS_WITH(make_banded_pim_integrator(consistent, o), Catch::Contains("diagonal"));
  // An undamped free chain pushed by a constant load runs away; a small bound catches it.
  ChainParameters p = paper_large_chain(60);
  p.damping = {0.0};
  p.loads = {{0, 1.0, 0.0, M_PI / 2}};  // sin(0 t + π/2) = 1
  GapStructure pushed = make_chain(p);
  pushed.springs.clear();
  o.divergence_bound = 1.0;
  auto integrator = make_banded_pim_integrator(pushed, o);
  integrator->set_state(0.0, Vector::Zero(60), Vector::Zero(60));
  CHECK_THROWS_AS(integrator->advance_to(1000.0), DivergenceError);
}

TEST_CASE("A long chain's steps spread over threads give the one-thread motion to the bit",
          "[banded][threads]") {
  // 60000 masses: 120000 state rows, past the 10^5 rows from which the tiles of a step go to the
  // OpenMP threads (thread_rows.hpp). Each row's sum is the same on any thread, so the motion
  // and the spring forces must agree exactly, contacts included. Besides each mass's grounded
  // spring, gap springs join the two masses on either side of every tile boundary (a tile is
  // 4096 rows, 2048 masses) and every 500th pair: their gaps read rows of two tiles.
  GapStructure s = make_chain(paper_large_chain(60000));
  std::vector<GapSpring> springs;
  for (const GapSpring& g : s.springs) {
    if (g.dof > 0 && (g.dof % 2048 == 0 || g.dof % 500 == 0)) {
      springs.push_back({g.dof - 1, g.dof, 1.0, 2.0, 0.0});
    }
    springs.push_back(g);
  }
  s.springs = springs;
  const BandedStepOperators ops = make_banded_step_operators(s, 0.1, BandedExponentialOptions{});
  const Vector rest = Vector::Zero(s.dofs());
  double between = 0.0;  // the largest force of a spring between two masses over the steps
  const auto run = [&](int threads) {
    omp_set_num_threads(threads);
    BandedPropagator p(ops);
    p.set_state(0.0, rest, rest);
    for (int k = 0; k < 100; ++k) {
      p.step();
      const Vector forces = p.spring_forces();
      for (std::size_t j = 0; j < s.springs.size(); ++j) {
        if (s.springs[j].other_dof >= 0) between = std::max(between, forces[static_cast<Index>(j)]);
      }
    }
    return std::make_pair(Vector(p.state()), p.spring_forces());
  };
  const int threads = std::max(2, omp_get_max_threads());
  const auto one = run(1);
  const auto many = run(threads);
  omp_set_num_threads(threads);
  REQUIRE(one.second.cwiseAbs().maxCoeff() > 0.0);  // springs in contact
  REQUIRE(between > 0.0);
  CHECK((one.first - many.first).cwiseAbs().maxCoeff() == 0.0);
  CHECK((one.second - many.second).cwiseAbs().maxCoeff() == 0.0);
}
