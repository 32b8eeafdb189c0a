// The exact event-driven solver against closed forms, against kink-located rkf78 at tolerance
// 1e-13, and on a grazing contact far shorter than its sample spacing; its tangent map against
// the matrix exponential, central differences of its flow and the dense PIM's tangent map.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include <unsupported/Eigen/MatrixFunctions>

#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::test::single_mass;

namespace {

EventDrivenOptions representation(const std::string& name) {
  EventDrivenOptions o;
  o.representation = name;
  return o;
}

struct Event {
  double t;
  Index spring;
  bool touching;
};

// The state [x; x'] of an integrator.
Vector state_of(const Integrator& integrator) {
  Vector y(2 * integrator.dofs());
  y << integrator.position(), integrator.velocity();
  return y;
}

// H = [[0, I], [-M⁻¹K, -M⁻¹C]]: the state matrix with every gap spring slack.
Matrix slack_state_matrix(const GapStructure& s) {
  const Index n = s.dofs();
  const Matrix mass = Matrix(s.mass);
  Matrix H = Matrix::Zero(2 * n, 2 * n);
  H.topRightCorner(n, n).setIdentity();
  H.bottomLeftCorner(n, n) = -mass.lu().solve(Matrix(s.stiffness));
  H.bottomRightCorner(n, n) = -mass.lu().solve(Matrix(s.damping));
  return H;
}

// Figure 4a's chain and the state four periods from rest (at rest every spring sits on its
// kink): in the period that follows the springs open and close transversally ten times.
struct TangentCase {
  NondimensionalChain chain = paper_five_dof_case("4a");
  GapStructure structure = make_chain(chain);
  double period = chain.period();
  double t0 = 4 * period, t1 = 5 * period;
  Vector start;
  TangentCase() {
    EventDrivenSolver solver(structure);
    solver.advance_to(t0);
    start = state_of(solver);
  }
  void set_start(Integrator& integrator) const {
    const Index n = structure.dofs();
    integrator.set_state(t0, start.head(n), start.tail(n));
  }
  // The state at t1 from y at t0.
  Vector flow(const Vector& y, const EventDrivenOptions& options = {}) const {
    EventDrivenSolver solver(structure, options);
    const Index n = structure.dofs();
    solver.set_state(t0, y.head(n), y.tail(n));
    solver.advance_to(t1);
    return state_of(solver);
  }
};

}  // namespace

TEST_CASE("exact solver: forced damped linear oscillator in closed form", "[event]") {
  // x'' + 2ζω x' + ω² x = a sin Ωt; the gap spring is never reached.
  const double omega = 1.3, zeta = 0.05, a = 0.7, big = 2.1, x0 = 0.2, v0 = -0.1;
  GapStructure s = single_mass(1.0, 2 * zeta * omega, omega * omega);
  s.springs.push_back({0, -1, 1.0, 50.0, 10.0});
  s.loads.push_back({0, a, big, 0.0});
  const double denom = std::pow(omega * omega - big * big, 2) + std::pow(2 * zeta * omega * big, 2);
  const double A = a * (omega * omega - big * big) / denom;
  const double B = -a * 2 * zeta * omega * big / denom;
  const double wd = omega * std::sqrt(1 - zeta * zeta);
  const double c1 = x0 - B;
  const double c2 = (v0 - A * big + zeta * omega * c1) / wd;
  auto exact = [&](double t) {
    return A * std::sin(big * t) + B * std::cos(big * t) +
           std::exp(-zeta * omega * t) * (c1 * std::cos(wd * t) + c2 * std::sin(wd * t));
  };
  for (const char* rep : {"modal", "exponential"}) {
    EventDrivenSolver solver(s, representation(rep));
    solver.set_state(0.0, Vector::Constant(1, x0), Vector::Constant(1, v0));
    double worst = 0.0;
    for (int k = 1; k <= 400; ++k) {
      const double t = 0.137 * k;  // arbitrary times: the closed form needs no grid
      solver.advance_to(t);
      REQUIRE(solver.time() == t);
      worst = std::max(worst, std::abs(solver.position()[0] - exact(t)));
    }
    INFO(rep);
    CHECK(worst < 1e-12);
    CHECK(solver.diagnostics().events == 0);
  }
}

TEST_CASE("exact solver: free gap oscillator switches at π/√(1+α) and π", "[event]") {
  // x'' + x + α max(0, x) = 0 from x = 0, x' = 1: half a period π/√(1+α) touching (amplitude
  // 1/√(1+α)), then half a period π slack (amplitude 1), forever.
  for (double alpha : {3.0, 1e4}) {
    GapStructure s = single_mass(1.0, 0.0, 1.0);
    s.springs.push_back({0, -1, 1.0, alpha, 0.0});
    const double r = std::sqrt(1 + alpha);
    const double period = M_PI / r + M_PI;
    EventDrivenSolver solver(s);
    std::vector<Event> events;
    solver.set_event_observer([&](double t, Index j, bool on) { events.push_back({t, j, on}); });
    solver.set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
    CHECK(solver.touching(0));  // at the kink moving inwards: the contact mode
    auto exact = [&](double t) {
      const double u = std::fmod(t, period);
      return u < M_PI / r ? std::sin(r * u) / r : -std::sin(u - M_PI / r);
    };
    double worst = 0.0;
    const int cycles = 20;
    for (int k = 1; k <= 200; ++k) {
      const double t = cycles * period * k / 200.0 + 1e-3;  // off the switching times
      solver.advance_to(t);
      worst = std::max(worst, std::abs(solver.position()[0] - exact(t)));
    }
    INFO("alpha = " << alpha);
    CHECK(worst < 1e-11);
    REQUIRE(events.size() == 2 * cycles);
    double worst_time = 0.0;
    for (std::size_t i = 0; i < events.size(); ++i) {
      const int cycle = static_cast<int>(i / 2);
      const bool opening = i % 2 == 0;
      const double expected = cycle * period + (opening ? M_PI / r : period);
      CHECK(events[i].touching == !opening);
      worst_time = std::max(worst_time, std::abs(events[i].t - expected));
    }
    CHECK(worst_time < 1e-12 * cycles * period);
  }
}

TEST_CASE("exact solver: a contact far shorter than the sample spacing is found", "[event]") {
  // x'' + x = 0 with x = sin t: a gap spring at Δ = 1 - ε is touched for about 1e-4 (ε = 1e-9)
  // or 3e-6 (ε = 1e-12) around t = π/2, while the solver samples the gap about every π/4: a
  // sign check at the samples sees the gap open at every one of them.
  const double alpha = 3.0;
  for (double eps : {1e-9, 1e-12}) {
    const double gap = 1.0 - eps;
    GapStructure s = single_mass(1.0, 0.0, 1.0);
    s.springs.push_back({0, -1, 1.0, alpha, gap});
    EventDrivenSolver solver(s);
    std::vector<Event> events;
    solver.set_event_observer([&](double t, Index j, bool on) { events.push_back({t, j, on}); });
    solver.set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
    solver.advance_to(3.0);
    // Closed form: touches at t1 = asin Δ with speed v1 = √(1 - Δ²); inside, the motion
    // oscillates at ω = √(1+α) about x_e = αΔ/(1+α), starting y0 = Δ - x_e above it, and leaves
    // after (π - 2φ)/ω with tan φ = y0 ω / v1, at speed -v1.
    const double t1 = std::asin(gap);
    const double v1 = std::sqrt((1 - gap) * (1 + gap));
    const double w = std::sqrt(1 + alpha);
    const double y0 = gap / (1 + alpha);
    const double phi = std::atan2(y0 * w, v1);
    const double t2 = t1 + (M_PI - 2 * phi) / w;
    INFO("eps = " << eps << ", contact lasts " << t2 - t1);
    REQUIRE(t2 - t1 < 1.5e-4);
    REQUIRE(events.size() == 2);
    CHECK(events[0].touching);
    CHECK(!events[1].touching);
    // A crossing at speed v1 is determined only to (rounding of the gap) / v1: 8 ulp of x ~ 1.
    const double timing = 8 * 2.220446049250313e-16 / v1;
    CHECK(std::abs(events[0].t - t1) < timing);
    CHECK(std::abs(events[1].t - t2) < timing);
    const double x3 = gap * std::cos(3.0 - t2) - v1 * std::sin(3.0 - t2);
    CHECK(std::abs(solver.position()[0] - x3) < 1e-12);
    CHECK(solver.diagnostics().uncertified == 0);
  }
  SECTION("and a near miss raises no event") {
    GapStructure s = single_mass(1.0, 0.0, 1.0);
    s.springs.push_back({0, -1, 1.0, alpha, 1.0 + 1e-9});
    EventDrivenSolver solver(s);
    solver.set_state(0.0, Vector::Zero(1), Vector::Constant(1, 1.0));
    solver.advance_to(3.0);
    CHECK(solver.diagnostics().events == 0);
    CHECK(std::abs(solver.position()[0] - std::sin(3.0)) < 1e-13);
  }
}

TEST_CASE("exact solver: undamped resonance falls back to the augmented exponential", "[event]") {
  // x'' + x = sin t from rest: x = (sin t - t cos t)/2. (iωI - H) is singular here, so the modal
  // particular solution does not exist.
  GapStructure s = single_mass(1.0, 0.0, 1.0);
  s.springs.push_back({0, -1, 1.0, 5.0, 1e3});
  s.loads.push_back({0, 1.0, 1.0, 0.0});
  EventDrivenSolver solver(s);
  solver.set_state(0.0, Vector::Zero(1), Vector::Zero(1));
  double worst = 0.0;
  for (int k = 1; k <= 100; ++k) {
    const double t = 0.6 * k;
    solver.advance_to(t);
    worst = std::max(worst, std::abs(solver.position()[0] - 0.5 * (std::sin(t) - t * std::cos(t))));
  }
  CHECK(solver.diagnostics().modal_modes == 0);
  CHECK(solver.diagnostics().exponential_modes == 1);
  CHECK(worst < 1e-11);
  CHECK_THROWS_AS(EventDrivenSolver(s, representation("modal")), InputError);
}

TEST_CASE("exact solver: free-free pair colliding through a clearance spring", "[event]") {
  // Two unit masses, nothing between them but a clearance spring k2 that closes when
  // x1 - x2 > Δ. The stiffness matrix is zero: every mode has a Jordan block at 0. From
  // x = 0, x1' = u, x2' = 0: flight until r = x1 - x2 reaches Δ at Δ/u, contact for π/ω with
  // ω = √(2 k2), the speeds exchanged, flight apart. The centre of mass moves at u/2 throughout.
  const double k2 = 8.0, gap = 0.3, u = 0.5;
  GapStructure s;
  s.mass = to_sparse(Matrix::Identity(2, 2));
  s.damping = to_sparse(Matrix::Zero(2, 2));
  s.stiffness = to_sparse(Matrix::Zero(2, 2));
  s.springs.push_back({0, 1, 1.0, k2, gap});
  EventDrivenSolver solver(s);
  Vector v0(2);
  v0 << u, 0.0;
  solver.set_state(0.0, Vector::Zero(2), v0);
  const double t_end = 5.0;
  solver.advance_to(t_end);
  const double t_in = gap / u, t_out = t_in + M_PI / std::sqrt(2 * k2);
  // After the contact: r = Δ - u (t - t_out), centre u t / 2.
  const double centre = 0.5 * u * t_end, r = gap - u * (t_end - t_out);
  CHECK(solver.diagnostics().exponential_modes >= 1);
  CHECK(solver.diagnostics().events == 2);
  CHECK(std::abs(solver.position()[0] - (centre + 0.5 * r)) < 1e-12);
  CHECK(std::abs(solver.position()[1] - (centre - 0.5 * r)) < 1e-12);
  CHECK(std::abs(solver.velocity()[0] - 0.0) < 1e-12);
  CHECK(std::abs(solver.velocity()[1] - u) < 1e-12);
}

TEST_CASE("exact solver agrees with kink-located rkf78 at tolerance 1e-13", "[event]") {
  // Figure 4a (start at rest, every spring exactly at its kink with g = g' = g'' = 0) and 4b
  // (gaps 0.1, so the contact modes carry a constant preload) over 20 forcing periods, compared
  // at every period: a disagreement above 1e-10 means one of the two is wrong.
  for (const char* figure : {"4a", "4b"}) {
    const NondimensionalChain chain = paper_five_dof_case(figure);
    const GapStructure s = make_chain(chain);
    EventDrivenSolver exact(s);
    ReferenceOptions ro;
    ro.method = RungeKuttaMethod::rkf78;
    ro.relative_tolerance = ro.absolute_tolerance = 1e-13;
    ro.locate_kinks = true;
    auto reference = make_reference_integrator(s, ro);
    double worst = 0.0;
    for (int k = 1; k <= 20; ++k) {
      exact.advance_to(k * chain.period());
      reference->advance_to(k * chain.period());
      worst = std::max({worst, (exact.position() - reference->position()).cwiseAbs().maxCoeff(),
                        (exact.velocity() - reference->velocity()).cwiseAbs().maxCoeff()});
    }
    INFO(figure << ": " << exact.diagnostics().events << " events, largest difference "
                << worst);
    CHECK(exact.diagnostics().events > 50);
    CHECK(exact.diagnostics().events == reference->stats().kink_events);
    CHECK(worst < 1e-10);
  }
}

TEST_CASE("exact solver: stiff contacts, advanced a whole period at a time", "[event]") {
  // α = k2/k1 = 1000: each contact lasts about π/√1001 ≈ 0.1, a quarter of the solver's sample
  // spacing in the open mode, and advance_to jumps a whole period. Right after a spring closes
  // its gap is a few ulp positive and rising; the search must still bound it from there (a
  // root formula that cancels to zero once certified such a spring for ever, and missed its
  // reopening 0.1 later). Checked against kink-located rkf78 at 1e-12.
  NondimensionalChain chain = paper_five_dof_case("4a");
  chain.alpha = {1000.0};
  const GapStructure s = make_chain(chain);
  EventDrivenSolver exact(s);
  ReferenceOptions ro;
  ro.method = RungeKuttaMethod::rkf78;
  ro.relative_tolerance = ro.absolute_tolerance = 1e-12;
  ro.locate_kinks = true;
  auto reference = make_reference_integrator(s, ro);
  double worst = 0.0;
  for (int k = 1; k <= 6; ++k) {
    exact.advance_to(k * chain.period());
    reference->advance_to(k * chain.period());
    worst = std::max({worst, (exact.position() - reference->position()).cwiseAbs().maxCoeff(),
                      (exact.velocity() - reference->velocity()).cwiseAbs().maxCoeff()});
  }
  INFO(exact.diagnostics().events << " events, largest difference " << worst);
  CHECK(exact.diagnostics().events == reference->stats().kink_events);
  CHECK(worst < 1e-9);
}

TEST_CASE("exact solver: modal and exponential representations agree", "[event]") {
  const NondimensionalChain chain = paper_five_dof_case("4b");
  const GapStructure s = make_chain(chain);
  EventDrivenSolver modal(s, representation("modal"));
  EventDrivenSolver expo(s, representation("exponential"));
  double worst = 0.0;
  for (int k = 1; k <= 5; ++k) {
    modal.advance_to(k * chain.period());
    expo.advance_to(k * chain.period());
    worst = std::max(worst, (modal.position() - expo.position()).cwiseAbs().maxCoeff());
  }
  CHECK(modal.diagnostics().exponential_modes == 0);
  CHECK(expo.diagnostics().modal_modes == 0);
  CHECK(modal.diagnostics().events == expo.diagnostics().events);
  CHECK(worst < 1e-11);
}

TEST_CASE("exact solver: bad input names the field", "[event]") {
  const GapStructure s = make_chain(paper_five_dof_case("4a"));
  EventDrivenOptions o;
  o.representation = "jordan";
  std::string why;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("representation") != std::string::npos);
  CHECK_THROWS_AS(EventDrivenSolver(s, o), InputError);
  o = EventDrivenOptions();
  o.max_eigenvector_condition = 0.5;
  CHECK(!o.is_valid(&why));
  CHECK(why.find("max_eigenvector_condition") != std::string::npos);
  EventDrivenSolver solver(s);
  solver.advance_to(1.0);
  CHECK_THROWS_AS(solver.advance_to(0.5), InputError);
  CHECK_THROWS_AS(solver.set_state(0.0, Vector::Zero(4), Vector::Zero(5)), InputError);
}

TEST_CASE("exact solver: the tangent map of a linear structure is exp(H t)", "[event][tangent]") {
  // Figure 4a's chain with gaps no motion reaches: one mode, so the map over [0, t] is exp(H t),
  // here against Eigen's Padé exponential of the dense state matrix.
  NondimensionalChain chain = paper_five_dof_case("4a");
  chain.gap = {1e3};
  const GapStructure s = make_chain(chain);
  const Index n = s.dofs();
  const Matrix H = slack_state_matrix(s);
  Vector x0(n), v0(n);
  x0 << 0.3, -0.1, 0.2, 0.05, -0.4;
  v0 << 0.1, 0.2, -0.3, 0.0, 0.15;
  for (const char* rep : {"modal", "exponential"}) {
    EventDrivenSolver solver(s, representation(rep));
    solver.set_state(0.0, x0, v0);
    Matrix tangent = Matrix::Identity(2 * n, 2 * n);
    double worst = 0.0;
    double t = 0.0;
    for (const double dt : {0.37, 1.9, 0.0, 4.1, 10.0}) {  // maps of several calls compose
      t += dt;
      solver.advance_with_tangent(t, tangent);
      const Matrix expected = (H * t).exp();
      worst = std::max(worst, (tangent - expected).cwiseAbs().maxCoeff() /
                                  expected.cwiseAbs().maxCoeff());
    }
    INFO(rep << ": largest relative difference from exp(Ht) " << worst);
    CHECK(solver.diagnostics().events == 0);
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("exact solver: the tangent map is the derivative of the flow across switches",
          "[event][tangent]") {
  // One forcing period of figure 4a on its attractor (several transversal switches): the
  // Jacobian against central differences of the flow (h = 1e-6: the flow is smooth away from
  // grazing, so the difference quotients are good to O(h²) plus rounding/h), for both
  // representations of the modes.
  const TangentCase c;
  const Index n = c.structure.dofs();
  for (const char* rep : {"auto", "exponential"}) {
    CAPTURE(rep);
    EventDrivenSolver solver(c.structure, representation(rep));
    long switches = 0;
    solver.set_event_observer([&](double, Index, bool) { ++switches; });
    c.set_start(solver);
    Matrix tangent = Matrix::Identity(2 * n, 2 * n);
    solver.advance_with_tangent(c.t1, tangent);
    CHECK(switches >= 8);

    const double h = 1e-6;
    Matrix differences(2 * n, 2 * n);
    for (Index j = 0; j < 2 * n; ++j) {
      Vector plus = c.start, minus = c.start;
      plus[j] += h;
      minus[j] -= h;
      differences.col(j) = (c.flow(plus, representation(rep)) -
                            c.flow(minus, representation(rep))) / (2 * h);
    }
    const double scale = tangent.cwiseAbs().maxCoeff();
    const double error = (tangent - differences).cwiseAbs().maxCoeff() / scale;
    INFO(switches << " switches, |J| = " << scale << ", relative difference from central "
                  << "differences " << error);
    CHECK(scale > 1e-2);
    CHECK(error < 1e-8);
  }
}

TEST_CASE("exact solver: the dense PIM's tangent map converges to the exact one",
          "[event][tangent]") {
  // The same period by the dense PIM. Its transition exp(Hη) is exact and its state is second
  // order, but the map of a step that contains an unlocated switch sees the contact only at the
  // step's ends, and its derivative is off by O(η) there: the tangent converges at first order,
  // erratically with where the switches fall in their steps. Measured on this case (relative to
  // max |J|): T/1000 3.1e-3, T/2000 1.3e-3, T/4000 6.1e-4, T/8000 5.9e-4, T/16000 1.0e-4,
  // T/32000 5.7e-5 (the state: 6.5e-6 down to 5.8e-9, second order).
  const TangentCase c;
  const Index n = c.structure.dofs();
  EventDrivenSolver exact(c.structure);
  c.set_start(exact);
  Matrix reference = Matrix::Identity(2 * n, 2 * n);
  exact.advance_with_tangent(c.t1, reference);
  const double scale = reference.cwiseAbs().maxCoeff();
  std::vector<double> errors;
  for (const int steps : {4000, 32000}) {
    MethodSettings settings;
    settings.method = Method::pim_dense;
    settings.step = c.period / steps;
    const auto pim = make_integrator(c.structure, settings);
    c.set_start(*pim);
    Matrix tangent = Matrix::Identity(2 * n, 2 * n);
    pim->advance_with_tangent(c.t1, tangent);
    CHECK((state_of(*pim) - state_of(exact)).cwiseAbs().maxCoeff() < 1e2 / (double(steps) * steps));
    errors.push_back((tangent - reference).cwiseAbs().maxCoeff() / scale);
  }
  INFO("relative differences at T/4000 and T/32000: " << errors[0] << ", " << errors[1]);
  CHECK(errors[0] < 1e-3);
  CHECK(errors[1] < 1e-4);
}

TEST_CASE("exact solver: the tangent map costs nothing in the motion and is per column",
          "[event][tangent]") {
  // One tangent column is the first column of the full Jacobian; the state after
  // advance_with_tangent is the state after advance_to, bit for bit; a tangent with the wrong
  // number of rows is refused before any motion.
  const TangentCase c;
  const Index n = c.structure.dofs();
  for (const char* rep : {"auto", "exponential"}) {
    CAPTURE(rep);
    const auto start = [&](EventDrivenSolver& solver) {
      c.set_start(solver);
    };
    EventDrivenSolver full(c.structure, representation(rep)), one(c.structure, representation(rep)),
        plain(c.structure, representation(rep));
    start(full);
    start(one);
    start(plain);
    Matrix jacobian = Matrix::Identity(2 * n, 2 * n);
    Matrix column = Matrix::Identity(2 * n, 1);
    std::vector<double> plain_times, tangent_times;
    full.advance_with_tangent(c.t1, jacobian,
                              [&](double t, const Vector&, const Vector&) {
                                tangent_times.push_back(t);
                              });
    one.advance_with_tangent(c.t1, column);
    plain.advance_to(c.t1, [&](double t, const Vector&, const Vector&) {
      plain_times.push_back(t);
    });
    const double difference =
        (column.col(0) - jacobian.col(0)).cwiseAbs().maxCoeff() / jacobian.cwiseAbs().maxCoeff();
    INFO("one column against the full Jacobian: relative difference " << difference);
    CHECK(difference < 1e-14);
    CHECK((state_of(full) - state_of(plain)).cwiseAbs().maxCoeff() == 0.0);
    CHECK((state_of(one) - state_of(plain)).cwiseAbs().maxCoeff() == 0.0);
    CHECK(full.time() == plain.time());
    CHECK(tangent_times == plain_times);
    CHECK(full.diagnostics().events == plain.diagnostics().events);

    Matrix wrong = Matrix::Identity(2 * n - 1, 2);
    const double t_before = plain.time();
    CHECK_THROWS_AS(plain.advance_with_tangent(t_before + 1.0, wrong), InputError);
    CHECK(plain.time() == t_before);
  }
}
