// The higher-order PIM (switching_pim.hpp): its force moments against closed forms, its
// reduction to the plain PIM, its measured order, the figure 4a target against the exact
// event-driven solver, and a contact shorter than a step.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/pim_integrator.hpp"
#include "pwl/integrators/pim_step_operators.hpp"
#include "pwl/numerics/precise_exponential.hpp"
#include "pwl/integrators/switching_pim.hpp"
#include "test_series.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::test::fitted_order;
using pwl::test::largest_difference;
using pwl::test::single_mass;


TEST_CASE("force moments: closed form for a scalar and the Γ0, Γ1 of precise_exponential",
          "[switching]") {
  SECTION("scalar H = λ: the series η^{-r} I_r = Σ_k λ^k η^{k+1} r!/(k+r+1)!") {
    const double lambda = -0.7, eta = 1.3;
    const PolynomialForceIntegrals p = polynomial_force_integrals(
        Matrix::Constant(1, 1, lambda), eta, Matrix::Constant(1, 1, 1.0), 6);
    CHECK(std::abs(p.transition(0, 0) - std::exp(lambda * eta)) < 1e-14);
    for (int r = 0; r <= 6; ++r) {
      // Summed to convergence at η directly (the implementation starts at η/2^20 and doubles).
      double sum = 0.0, term = eta;  // λ^k η^{k+1} r!/(k+r+1)! for k = 0 is η/(r+1)
      term /= (r + 1);
      for (int k = 0; k < 60; ++k) {
        sum += term;
        term *= lambda * eta / (k + r + 2);
      }
      INFO("r = " << r);
      CHECK(std::abs(p.moments[static_cast<std::size_t>(r)](0, 0) - sum) < 1e-14);
    }
  }
  SECTION("a chain's state matrix: Ξ̂_0 = Γ0 G, Ξ̂_1 = Γ0 G - Γ1 G / η") {
    const GapStructure s = make_chain(paper_five_dof_case("4b"));
    const Matrix H = state_matrix(s);
    Matrix G = Matrix::Zero(10, 5);
    G.bottomRows(5) = -Matrix::Identity(5, 5);
    const double eta = 2 * M_PI / 200;
    const PolynomialForceIntegrals p = polynomial_force_integrals(H, eta, G, 3);
    const PreciseExponential e = precise_exponential(H, eta, G, Matrix(10, 0), Vector(0));
    CHECK((p.transition - e.transition).cwiseAbs().maxCoeff() < 1e-15);
    CHECK((p.moments[0] - e.gamma0).cwiseAbs().maxCoeff() < 1e-16);
    CHECK((p.moments[1] - (e.gamma0 - e.gamma1 / eta)).cwiseAbs().maxCoeff() < 1e-16);
  }
  CHECK_THROWS_AS(polynomial_force_integrals(Matrix::Identity(2, 2), 0.0, Matrix::Zero(2, 1), 2),
                  InputError);
}

TEST_CASE("switching PIM with d = 0, no end slope and no location is the plain PIM",
          "[switching]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double eta = chain.period() / 200;
  PimOptions po;
  po.step = eta;
  auto plain = make_pim_integrator(s, po);
  SwitchingPimOptions so;
  so.step = eta;
  so.force_degree = 0;
  so.end_derivative = false;
  so.locate_switches = false;
  auto same = make_switching_pim(s, so);
  double worst = 0.0;
  for (int k = 1; k <= 20; ++k) {
    plain->advance_to(k * chain.period());
    same->advance_to(k * chain.period());
    worst = std::max(worst, largest_difference(*plain, *same));
  }
  CHECK(worst < 1e-12);
  CHECK(same->diagnostics().switching_steps == 0);
}

TEST_CASE("switching PIM: order d + 3 on the gap oscillator, switches inside steps", "[switching]") {
  // x'' + x + α max(0, x) = 0 from x = 0, x' = 1 (closed form: half-periods π/√(1+α) touching
  // and π slack). The steps are not commensurate with the switching times. The plain PIM is
  // second order here; the located switches leave the smooth steps' order d + 3.
  const double alpha = 3.0, r = std::sqrt(1 + alpha), period = M_PI / r + M_PI;
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, alpha, 0.0});
  auto exact = [&](double t) {
    const double u = std::fmod(t, period);
    return u < M_PI / r ? std::sin(r * u) / r : -std::sin(u - M_PI / r);
  };
  for (int degree : {1, 2}) {
    std::vector<double> steps, errors;
    for (int n : {40, 80, 160, 320}) {
      SwitchingPimOptions so;
      so.step = period / (n + 0.37);
      so.force_degree = degree;
      auto pim = make_switching_pim(s, so);
      pim->set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
      double worst = 0.0;
      pim->advance_to(400 * so.step, [&](double t, const Vector& x, const Vector&) {
        worst = std::max(worst, std::abs(x[0] - exact(t)));
      });
      CHECK(pim->diagnostics().switches > 0);
      steps.push_back(so.step);
      errors.push_back(worst);
    }
    const double order = fitted_order(steps, errors);
    INFO("d = " << degree << ": errors " << errors[0] << " ... " << errors.back() << ", order "
                << order);
    CHECK(order > degree + 3 - 0.5);
  }
}

TEST_CASE("switching PIM meets 1e-9 on figure 4a at η = T/200 against the exact solver",
          "[switching]") {
  // Poincaré points (the state once per forcing period) over 300 periods, the first 100 of
  // them the transient onto the period-2 orbit. The plain PIM at the same step misses by
  // about 1e-3.
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  EventDrivenSolver exact(s);
  SwitchingPimOptions so;
  so.step = T / 200;
  auto pim = make_switching_pim(s, so);
  PimOptions po;
  po.step = T / 200;
  auto plain = make_pim_integrator(s, po);
  double worst = 0.0, worst_plain = 0.0;
  for (int k = 1; k <= 300; ++k) {
    exact.advance_to(k * T);
    pim->advance_to(k * T);
    plain->advance_to(k * T);
    worst = std::max(worst, largest_difference(*pim, exact));
    worst_plain = std::max(worst_plain, largest_difference(*plain, exact));
  }
  INFO("switching PIM " << worst << ", plain PIM " << worst_plain);
  CHECK(worst < 1e-9);
  CHECK(worst_plain > 1e-4);
  // Every switch the exact solver saw was located (5 per period on this orbit).
  CHECK(pim->diagnostics().switches == exact.diagnostics().events);
  CHECK(exact.diagnostics().events > 1400);
}

TEST_CASE("switching PIM: measured order on figure 4a", "[switching]") {
  // Against the exact solver over 30 periods at η = T/50 ... T/400: order 5 for the default
  // d = 2 with the end slope, 2 for the plain PIM.
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  std::vector<Vector> truth;
  EventDrivenSolver exact(s);
  for (int k = 1; k <= 30; ++k) {
    exact.advance_to(k * T);
    Vector st(10);
    st << exact.position(), exact.velocity();
    truth.push_back(st);
  }
  std::vector<double> steps, errors, plain_errors;
  for (int n : {50, 100, 200, 400}) {
    SwitchingPimOptions so;
    so.step = T / n;
    auto pim = make_switching_pim(s, so);
    PimOptions po;
    po.step = T / n;
    auto plain = make_pim_integrator(s, po);
    double worst = 0.0, worst_plain = 0.0;
    for (int k = 1; k <= 30; ++k) {
      pim->advance_to(k * T);
      plain->advance_to(k * T);
      Vector a(10), b(10);
      a << pim->position(), pim->velocity();
      b << plain->position(), plain->velocity();
      worst = std::max(worst, (a - truth[static_cast<std::size_t>(k - 1)]).cwiseAbs().maxCoeff());
      worst_plain =
          std::max(worst_plain, (b - truth[static_cast<std::size_t>(k - 1)]).cwiseAbs().maxCoeff());
    }
    steps.push_back(T / n);
    errors.push_back(worst);
    plain_errors.push_back(worst_plain);
  }
  const double order = fitted_order(steps, errors);
  const double plain_order = fitted_order(steps, plain_errors);
  INFO("switching order " << order << ", plain order " << plain_order);
  CHECK(order > 4.5);
  CHECK(plain_order > 1.5);  // second order, seen over steps not yet all asymptotic
  CHECK(plain_order < 2.5);
}

TEST_CASE("switching PIM finds a contact shorter than its step", "[switching]") {
  // x = sin t reaches a gap at 1 - 1e-9 for about 1e-4 around π/2; the step is 0.1. Slack, the
  // motion is linear and the steps are exact; the step with the touch is followed in pieces.
  const double alpha = 3.0, gap = 1.0 - 1e-9;
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, alpha, gap});
  SwitchingPimOptions so;
  so.step = 0.1;
  auto pim = make_switching_pim(s, so);
  pim->set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
  pim->advance_to(3.0);
  const double t1 = std::asin(gap);
  const double v1 = std::sqrt((1 - gap) * (1 + gap));
  const double w = std::sqrt(1 + alpha);
  const double t2 = t1 + (M_PI - 2 * std::atan2(gap / (1 + alpha) * w, v1)) / w;
  REQUIRE(t2 - t1 < 1e-3 * so.step);
  CHECK(pim->diagnostics().switches == 2);
  CHECK(std::abs(pim->position()[0] - (gap * std::cos(3.0 - t2) - v1 * std::sin(3.0 - t2))) <
        1e-12);
}

TEST_CASE("switching PIM finds a contact that opens and closes inside one long step from x = 0",
          "[switching]") {
  // x = sin t from x = 0: the gap polynomials' even terms vanish at the step start (a phase where
  // a truncated series understates the peak: to degree 4 it peaks at 0.943, below the gap at
  // 0.97). The contact lasts from asin 0.97 = 1.325 to 1.816, inside the one step of 1.9
  // (η ω_max = 1.99, at the step guard's limit); the series locates both switches and the end
  // is the closed form's.
  const double alpha = 0.1, gap = 0.97, eta = 1.9;
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, alpha, gap});
  SwitchingPimOptions so;
  so.step = eta;
  auto pim = make_switching_pim(s, so);
  pim->set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
  pim->advance_to(eta);
  const double t1 = std::asin(gap);
  const double v1 = std::sqrt((1 - gap) * (1 + gap));
  const double w = std::sqrt(1 + alpha);
  const double t2 = t1 + (M_PI - 2 * std::atan2(gap / (1 + alpha) * w, v1)) / w;
  REQUIRE(t2 < eta);
  CHECK(pim->diagnostics().switches == 2);
  CHECK(pim->diagnostics().switching_steps == 1);
  const double after = eta - t2;  // free again from x = gap, x' = -v1
  CHECK(std::abs(pim->position()[0] - (gap * std::cos(after) - v1 * std::sin(after))) < 1e-12);
  CHECK(std::abs(pim->velocity()[0] - (-gap * std::sin(after) - v1 * std::cos(after))) < 1e-12);
}

TEST_CASE("switching PIM: bad input names the field", "[switching]") {
  const GapStructure s = make_chain(paper_five_dof_case("4a"));
  SwitchingPimOptions o;
  std::string why;
  CHECK(!o.is_valid(&why));  // no step
  CHECK(why.find("step") != std::string::npos);
  o.step = 0.1;
  o.force_degree = 9;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("force_degree") != std::string::npos);
  CHECK_THROWS_AS(make_switching_pim(s, o), InputError);
  SECTION("a contact too stiff for the derivative terms at this step") {
    NondimensionalChain stiff = paper_five_dof_case("4a");
    stiff.alpha = {1e6};
    const GapStructure hard = make_chain(stiff);
    SwitchingPimOptions so;
    so.step = stiff.period() / 200;
    try {
      make_switching_pim(hard, so);
      FAIL("no InputError");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("step") != std::string::npos);
    }
    so.force_degree = 0;
    so.end_derivative = false;
    CHECK_NOTHROW(make_switching_pim(hard, so));
  }
}

namespace {

// The state [x; x'] of an integrator.
Vector state_of(const Integrator& integrator) {
  Vector y(2 * integrator.dofs());
  y << integrator.position(), integrator.velocity();
  return y;
}

// Central differences (step h) of the flow y(t0) -> y(t1) of the integrators `make` builds, in
// every state direction: an approximation of the flow's Jacobian.
template <class Make>
Matrix flow_differences(const Make& make, double t0, double t1, const Vector& y0, double h) {
  const Index n = y0.size() / 2;
  const auto flow = [&](const Vector& y) {
    const auto integrator = make();
    integrator->set_state(t0, y.head(n), y.tail(n));
    integrator->advance_to(t1);
    return state_of(*integrator);
  };
  Matrix d(2 * n, 2 * n);
  for (Index j = 0; j < 2 * n; ++j) {
    Vector plus = y0, minus = y0;
    plus[j] += h;
    minus[j] -= h;
    d.col(j) = (flow(plus) - flow(minus)) / (2 * h);
  }
  return d;
}

}  // namespace

TEST_CASE("switching PIM: the tangent map is the derivative of its own one-period map",
          "[switching][tangent]") {
  // Figure 4a from the state reached after 100 periods (on the period-2 orbit), one period on: the
  // springs open and close five times in it, so the period has smooth steps and switching
  // steps. The tangent of
  // the identity is the Jacobian of the switching PIM's map; central differences of that map
  // (h = 1e-6) agree with it up to their own error (the map is smooth between switches, and the
  // located switches' timing enters only through the spring force at the switch, which is zero).
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  struct Variant {
    int degree;
    bool end_slope;
    bool locate;
  };
  // Without located switches the smooth step's LCP alone changes the modes (and the tangent
  // takes the general path rather than the mode's operators).
  for (const Variant variant : {Variant{2, true, true}, Variant{0, false, true},
                                Variant{3, false, true}, Variant{2, true, false}}) {
    CAPTURE(variant.degree, variant.end_slope, variant.locate);
    SwitchingPimOptions so;
    so.step = T / 200;
    so.force_degree = variant.degree;
    so.end_derivative = variant.end_slope;
    so.locate_switches = variant.locate;
    const auto make = [&] { return make_switching_pim(s, so); };
    auto start = make();
    start->advance_to(100 * T);
    const Vector y0 = state_of(*start);

    auto tangent_run = make();
    tangent_run->set_state(100 * T, start->position(), start->velocity());
    Matrix J = Matrix::Identity(10, 10);
    tangent_run->advance_with_tangent(101 * T, J);
    // The motion is that of advance_to from the same start, to the last bit.
    auto plain_run = make();
    plain_run->set_state(100 * T, start->position(), start->velocity());
    plain_run->advance_to(101 * T);
    CHECK((state_of(*tangent_run) - state_of(*plain_run)).cwiseAbs().maxCoeff() == 0.0);
    if (variant.locate) {
      CHECK(tangent_run->diagnostics().switches >= 4);
      CHECK(tangent_run->diagnostics().switching_steps >= 4);
    }

    const Matrix D = flow_differences(make, 100 * T, 101 * T, y0, 1e-6);
    const double scale = J.cwiseAbs().maxCoeff();
    const double relative = (J - D).cwiseAbs().maxCoeff() / scale;
    INFO("|J| " << scale << ", |J - differences| / |J| = " << relative);
    CHECK(scale > 1e-2);
    CHECK(relative < 1e-6);
  }
  SECTION("a tangent with the wrong number of rows is refused") {
    SwitchingPimOptions so;
    so.step = T / 200;
    auto pim = make_switching_pim(s, so);
    Matrix wrong = Matrix::Identity(5, 5);
    CHECK_THROWS_AS(pim->advance_with_tangent(T, wrong), InputError);
    // Nothing moved, and the integrator still works.
    CHECK(pim->time() == 0.0);
    CHECK_NOTHROW(pim->advance_to(T));
  }
}

TEST_CASE("switching PIM: the tangent map converges to the exact flow's Jacobian at order 5",
          "[switching][tangent]") {
  // Figure 4a, one period from the exact solver's state after 100 periods (five switches in
  // it). The exact flow's Jacobian from central differences of the event-driven solver (exact up
  // to rounding, so the differences are good to about 1e-9); the switching PIM's tangent at
  // η = T/10 ... T/40 approaches it at the order of the method (d = 2 with the end slope: 5).
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  EventDrivenSolver exact(s);
  exact.advance_to(100 * T);
  const Vector y0 = state_of(exact);
  const Matrix J_exact = flow_differences(
      [&] { return make_event_driven_solver(s); }, 100 * T, 101 * T, y0, 1e-6);
  std::vector<double> steps, errors;
  for (int n : {10, 20, 40}) {
    SwitchingPimOptions so;
    so.step = T / n;
    auto pim = make_switching_pim(s, so);
    pim->set_state(100 * T, y0.head(5), y0.tail(5));
    Matrix J = Matrix::Identity(10, 10);
    pim->advance_with_tangent(101 * T, J);
    steps.push_back(so.step);
    errors.push_back((J - J_exact).cwiseAbs().maxCoeff() / J_exact.cwiseAbs().maxCoeff());
  }
  const double order = fitted_order(steps, errors);
  INFO("relative errors " << errors[0] << ", " << errors[1] << ", " << errors[2] << "; order "
                          << order);
  CHECK(errors[2] < errors[1]);
  CHECK(errors[1] < errors[0]);
  CHECK(errors[2] > 3e-8);  // well above the differences' own error
  CHECK(order > 4.0);
}
