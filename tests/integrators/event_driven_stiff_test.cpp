// The exact event-driven solver with stiff contacts (issue 15): figure 4a's chain with the contact
// stiffness ratio α = k2/k1 up to 1e10. Against independent truth (kink-located rkf78 converging
// onto it as its tolerance tightens; the lift-off time of the rigid limit α → ∞ in closed form),
// its work against its events, and its work budget and progress hook.
#include <catch2/catch.hpp>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "pwl/model/chain_builders.hpp"
#include "test_structures.hpp"

using namespace pwl;
using pwl::test::largest_difference;

namespace {

// Figure 4a's chain (5 masses, ζ = 0.2, θ = 1, Q = (1, -1, 1, -1, 1), Δ̃ = 0) with α = k2/k1.
NondimensionalChain stiff_chain(double alpha) {
  NondimensionalChain chain = paper_five_dof_case("4a");
  chain.alpha = {alpha};
  return chain;
}

struct Event {
  double t;
  Index spring;
  bool touching;
};

// The rigid limit α → ∞ of the chain from rest: masses 1, 3 and 5 are pushed into their stops
// (Q = +1) and held at x = 0; masses 2 and 4, each between two held masses, obey
// x'' + 0.4 x' + 2 x = -sin t from rest (x2 = x4). The stop of mass 3 pushes back with
// R3 = 2 (x2 + 0.2 x2') + sin t, and mass 3 lifts off where R3 first reaches zero.
struct RigidLimit {
  static constexpr double A = -1.0 / 1.16, B = 0.4 / 1.16;  // x_p = A sin t + B cos t
  static constexpr double C = -B;                             // e^{-0.2t}(C cos 1.4t + D sin 1.4t)
  static constexpr double D = (0.2 * C - A) / 1.4;
  static double x(double t) {
    return A * std::sin(t) + B * std::cos(t) +
           std::exp(-0.2 * t) * (C * std::cos(1.4 * t) + D * std::sin(1.4 * t));
  }
  static double v(double t) {
    const double e = std::exp(-0.2 * t), c = std::cos(1.4 * t), s = std::sin(1.4 * t);
    return A * std::cos(t) - B * std::sin(t) +
           e * (-0.2 * (C * c + D * s) + 1.4 * (D * c - C * s));
  }
  static double reaction(double t) { return 2.0 * (x(t) + 0.2 * v(t)) + std::sin(t); }
  // The first zero of R3 (R3 > 0 on (0, 1], < 0 at 2), by bisection to rounding.
  static double lift_off() {
    double lo = 1.0, hi = 2.0;
    REQUIRE(reaction(lo) > 0.0);
    REQUIRE(reaction(hi) < 0.0);
    for (int k = 0; k < 200 && hi - lo > 1e-15; ++k) {
      const double mid = 0.5 * (lo + hi);
      (reaction(mid) > 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

}  // namespace

TEST_CASE("exact solver at α = 1e9: kink-located rkf78 converges onto it", "[event][stiff]") {
  // Before balancing, the contact modes at α = 1e9 had cond(V) > 1e5, fell back to the
  // augmented exponential sampled 5e-10 apart, and 20 periods did not end in 10 minutes. Here
  // 3 periods from rest (three stops held for about half a period, then lift-offs and
  // impacts of 1e-4 duration), against rkf78 at tolerances 1e-12, 1e-13, 1e-14: the difference
  // must shrink with rkf78's tolerance (measured 2.3e-8, 6.7e-9, 2.7e-9: rkf78's own error)
  // and end below 1e-8. A solver error of 1e-8 or more would stop the shrinking.
  const NondimensionalChain chain = stiff_chain(1e9);
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  EventDrivenSolver exact(s);
  std::vector<Vector> states;
  long events_after_first = 0;
  for (int k = 1; k <= 3; ++k) {
    exact.advance_to(k * T);
    if (k == 1) events_after_first = -exact.diagnostics().events;
    Vector y(10);
    y << exact.position(), exact.velocity();
    states.push_back(y);
  }
  events_after_first += exact.diagnostics().events;
  std::vector<double> differences;
  for (double tol : {1e-12, 1e-13, 1e-14}) {
    ReferenceOptions ro;
    ro.method = RungeKuttaMethod::rkf78;
    ro.relative_tolerance = ro.absolute_tolerance = tol;
    ro.locate_kinks = true;
    auto reference = make_reference_integrator(s, ro);
    double worst = 0.0;
    long kinks_after_first = 0;
    for (int k = 1; k <= 3; ++k) {
      reference->advance_to(k * T);
      if (k == 1) kinks_after_first = -reference->stats().kink_events;
      Vector y(10);
      y << reference->position(), reference->velocity();
      worst = std::max(worst, (y - states[static_cast<std::size_t>(k - 1)]).cwiseAbs().maxCoeff());
    }
    kinks_after_first += reference->stats().kink_events;
    INFO("rkf78 at " << tol << ": largest difference " << worst << ", switches in (T, 3T] "
                     << kinks_after_first << " against " << events_after_first);
    // From rest the stops start closed on their kinks: rkf78 counts no switch there, so the
    // counts are compared after the first period.
    CHECK(kinks_after_first == events_after_first);
    differences.push_back(worst);
  }
  INFO("differences " << differences[0] << ", " << differences[1] << ", " << differences[2]);
  CHECK(differences[2] < 1e-8);
  CHECK(differences[2] < differences[0] / 3.0);
  CHECK(exact.diagnostics().exponential_modes == 0);
  CHECK(exact.diagnostics().worst_condition < 100.0);
}

TEST_CASE("exact solver: a stiff stop lets go where the rigid limit says, within 1/√α",
          "[event][stiff]") {
  // From rest the contact force of mass 3 follows the rigid limit's R3(t) plus a vibration at
  // the contact frequency √α, excited because the force starts rising at R3'(0) = 1 while the
  // mass is at rest: velocity 1/α, amplitude 1/α^{3/2}, force amplitude α · that = 1/√α
  // (damped afterwards). Mass 3 lets go once R3 falls below that, so within
  // (1/√α) / |R3'(t*)| = 0.96/√α of the rigid lift-off t*. Measured |t - t*|·√α: 0.70 (α = 1e6),
  // 0.35 (1e8), 0.19 (1e9), 0.63 (1e10). The first switch of the run must be that lift-off:
  // the stops start closed on their kinks without a switch, and nothing chatters before.
  const double t_star = RigidLimit::lift_off();
  for (double alpha : {1e6, 1e8, 1e9, 1e10}) {
    const GapStructure s = make_chain(stiff_chain(alpha));
    EventDrivenSolver solver(s);
    std::vector<Event> events;
    solver.set_event_observer(
        [&](double t, Index spring, bool touching) { events.push_back({t, spring, touching}); });
    solver.advance_to(2.0);
    INFO("α = " << alpha << ": " << events.size() << " switches before t = 2, t* = " << t_star);
    REQUIRE(events.size() == 1);
    CHECK(events[0].spring == 2);
    CHECK(!events[0].touching);
    INFO("lift-off at " << events[0].t << ", |t - t*| √α = "
                        << std::abs(events[0].t - t_star) * std::sqrt(alpha));
    CHECK(std::abs(events[0].t - t_star) <= 1.0 / std::sqrt(alpha));
  }
}

TEST_CASE("exact solver: work in proportion to the events for α up to 1e10", "[event][stiff]") {
  // 200 periods from rest, advanced a period at a time. Measured: 5.0 to 5.8 switches per
  // period and 9.2 to 11.3 gap evaluations per switch for every α here; every mode modal with
  // cond(V) = 13 (balanced). Before: 2e9 evaluations per unit time at α = 1e9.
  for (double alpha : {2.0, 1e6, 1e9, 1e10}) {
    const NondimensionalChain chain = stiff_chain(alpha);
    EventDrivenSolver solver(make_chain(chain));
    const int periods = 200;
    for (int k = 1; k <= periods; ++k) solver.advance_to(k * chain.period());
    const EventDrivenDiagnostics d = solver.diagnostics();
    INFO("α = " << alpha << ": " << d.events << " switches, " << d.crossings << " crossings, "
                << d.gap_samples << " gap evaluations, cond " << d.worst_condition);
    CHECK(d.events >= 4 * periods);
    CHECK(d.events <= 8 * periods);
    CHECK(d.crossings <= d.events + 10);
    CHECK(d.gap_samples <= 15 * d.events);
    CHECK(d.exponential_modes == 0);
    CHECK(d.worst_condition < 100.0);
  }
}

TEST_CASE("exact solver: the augmented exponential at α = 1e9 samples at the contact's own period",
          "[event][stiff]") {
  // Forced to the augmented-exponential representation, whose bounds come from norms: one
  // period at α = 1e9 (the stops held for about half of it) takes about 1.1e6 gap evaluations,
  // 5 T√α, in 0.3 s; unbalanced its spacing was 0.5/||H|| ≈ 0.5/α (2.5e9 per period). It must
  // agree with the modal form (measured 4e-10), and the progress hook, called every 1024
  // evaluations once its interval (0 here) has passed, sees the time advance inside that long
  // search.
  const double alpha = 1e9;
  const NondimensionalChain chain = stiff_chain(alpha);
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  EventDrivenOptions o;
  o.representation = "exponential";
  o.progress_interval = 0.0;
  std::vector<EventDrivenProgress> reports;
  o.progress = [&](const EventDrivenProgress& p) { reports.push_back(p); };
  EventDrivenSolver exponential(s, o);
  exponential.advance_to(T);
  EventDrivenSolver modal(s);
  modal.advance_to(T);
  const EventDrivenDiagnostics d = exponential.diagnostics();
  INFO(d.gap_samples << " gap evaluations, " << d.events << " switches, "
                     << reports.size() << " progress reports; difference "
                     << largest_difference(exponential, modal));
  CHECK(d.modal_modes == 0);
  CHECK(d.events == modal.diagnostics().events);
  CHECK(largest_difference(exponential, modal) < 1e-9);
  CHECK(d.gap_samples <= static_cast<long>(10 * T * std::sqrt(alpha)));
  // Reports every 1024 evaluations, in order, inside [0, T], with the call's counts.
  CHECK(static_cast<long>(reports.size()) >= d.gap_samples / 1024 - 1);
  bool ordered = true;
  for (std::size_t k = 1; k < reports.size(); ++k) {
    ordered = ordered && reports[k].t >= reports[k - 1].t &&
              reports[k].gap_samples >= reports[k - 1].gap_samples &&
              reports[k].events >= reports[k - 1].events;
  }
  CHECK(ordered);
  REQUIRE(!reports.empty());
  CHECK(reports.front().t_start == 0.0);
  CHECK(reports.front().t_end == T);
  CHECK(reports.back().t <= T);
  CHECK(reports.back().gap_samples <= d.gap_samples);
  CHECK(reports.back().events <= d.events);
}

TEST_CASE("exact solver: a spent budget names itself, the time reached and the work",
          "[event][budget]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double t_end = 20 * chain.period();
  // The state a solver with no budget trouble has at time t.
  const auto state_at = [&](double t) {
    EventDrivenSolver fresh(s);
    fresh.advance_to(t);
    Vector y(10);
    y << fresh.position(), fresh.velocity();
    return y;
  };

  SECTION("switches") {
    EventDrivenOptions o;
    o.max_events = 5;
    EventDrivenSolver solver(s, o);
    std::string message;
    try {
      solver.advance_to(t_end);
    } catch (const BudgetError& e) {
      message = e.what();
    }
    INFO(message);
    REQUIRE(!message.empty());
    CHECK(message.find("max_events = 5") != std::string::npos);
    CHECK(message.find(fmt::format("t = {:.10g}", solver.time())) != std::string::npos);
    CHECK(message.find("6 switches located") != std::string::npos);
    CHECK(message.find("pim-switching") != std::string::npos);
    CHECK(message.find("raise max_events") != std::string::npos);
    // Left at the sixth switch, consistently: the motion there is the motion.
    CHECK(solver.time() > 0.0);
    CHECK(solver.time() < t_end);
    CHECK(solver.diagnostics().crossings == 6);
    Vector y(10);
    y << solver.position(), solver.velocity();
    CHECK((y - state_at(solver.time())).cwiseAbs().maxCoeff() < 1e-12);
  }
  SECTION("gap evaluations") {
    EventDrivenOptions o;
    o.max_gap_samples = 200;
    EventDrivenSolver solver(s, o);
    std::string message;
    try {
      solver.advance_to(t_end);
    } catch (const BudgetError& e) {
      message = e.what();
    }
    INFO(message);
    REQUIRE(!message.empty());
    CHECK(message.find("max_gap_samples = 200") != std::string::npos);
    CHECK(message.find(fmt::format("t = {:.10g}", solver.time())) != std::string::npos);
    CHECK(message.find("gap evaluations") != std::string::npos);
    CHECK(message.find("too stiff") != std::string::npos);
    // Stopped where no switch was left unaccounted, in a consistent state; each call has its
    // own budget, so the run can go on in shorter calls.
    CHECK(solver.time() > 0.0);
    CHECK(solver.time() < t_end);
    Vector y(10);
    y << solver.position(), solver.velocity();
    CHECK((y - state_at(solver.time())).cwiseAbs().maxCoeff() < 1e-12);
    const double stop = solver.time();
    solver.advance_to(stop + 0.5);
    y << solver.position(), solver.velocity();
    CHECK((y - state_at(stop + 0.5)).cwiseAbs().maxCoeff() < 1e-12);
  }
  SECTION("through the method table, with a bad budget refused by name") {
    MethodSettings m;
    m.method = Method::exact;
    m.event_driven.max_events = 3;
    auto integrator = make_integrator(s, m);
    CHECK_THROWS_AS(integrator->advance_to(t_end), BudgetError);
    m.event_driven.max_gap_samples = 0;
    std::string why;
    CHECK(!m.is_valid(s, &why));
    CHECK(why.find("event_driven.max_gap_samples = 0") != std::string::npos);
    EventDrivenOptions o;
    o.progress_interval = std::nan("");
    CHECK(!o.is_valid(&why));
    CHECK(why.find("progress_interval") != std::string::npos);
    o = EventDrivenOptions();
    o.max_events = 0;
    CHECK(!o.is_valid(&why));
    CHECK(why.find("max_events = 0") != std::string::npos);
  }
}

TEST_CASE("exact solver: the progress hook reports each call and may stop it", "[event][budget]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();

  SECTION("an interval of 0 reports at every switch, in order") {
    EventDrivenOptions o;
    o.progress_interval = 0.0;
    std::vector<EventDrivenProgress> reports;
    o.progress = [&](const EventDrivenProgress& p) { reports.push_back(p); };
    EventDrivenSolver solver(s, o);
    solver.advance_to(3 * T);
    const long events = solver.diagnostics().events;
    INFO(reports.size() << " reports, " << events << " switches");
    CHECK(static_cast<long>(reports.size()) >= solver.diagnostics().crossings);
    for (std::size_t k = 0; k < reports.size(); ++k) {
      CHECK(reports[k].t_start == 0.0);
      CHECK(reports[k].t_end == 3 * T);
      CHECK(reports[k].t >= 0.0);
      CHECK(reports[k].t <= 3 * T);
      CHECK(reports[k].seconds >= 0.0);
      if (k > 0) CHECK(reports[k].t >= reports[k - 1].t);
    }
    CHECK(reports.back().events == events);
  }
  SECTION("a long interval never reports a short call") {
    EventDrivenOptions o;
    o.progress_interval = 3600.0;
    long calls = 0;
    o.progress = [&](const EventDrivenProgress&) { ++calls; };
    EventDrivenSolver solver(s, o);
    solver.advance_to(3 * T);
    CHECK(calls == 0);
  }
  SECTION("a hook that throws stops the call at a switch") {
    EventDrivenOptions o;
    o.progress_interval = 0.0;
    int calls = 0;
    o.progress = [&](const EventDrivenProgress&) {
      if (++calls == 4) throw std::runtime_error("interrupted");
    };
    EventDrivenSolver solver(s, o);
    CHECK_THROWS_WITH(solver.advance_to(20 * T), "interrupted");
    CHECK(solver.time() < 20 * T);
    EventDrivenSolver fresh(s);
    fresh.advance_to(solver.time());
    CHECK(largest_difference(solver, fresh) < 1e-12);
  }
}
