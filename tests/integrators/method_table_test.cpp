// The method table (method_table.hpp) against the integrators it builds: every row builds on a
// short and on a long chain, reports the form it took, and does what its capabilities say (an
// exact tangent map, a fixed step grid); the names round-trip, the settings are checked with
// messages that name the value, and every method integrates the same case of the paper to the
// same state within its accuracy.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"

using namespace pwl;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The form a row's integrator must take: its own method, or, for a row that chooses its form, the
// dense one on a short chain and the banded one on a long banded chain (written out here, not
// read from the table, so that the test is independent of it).
Method expected_form(Method method, bool long_banded_chain) {
  switch (method) {
    case Method::pim: return long_banded_chain ? Method::pim_banded : Method::pim_dense;
    case Method::pim_switching:
      return long_banded_chain ? Method::pim_switching_banded : Method::pim_switching_dense;
    default: return method;
  }
}

// Settings every row accepts: a step for the fixed-grid rows, a tolerance for the adaptive ones.
MethodSettings settings_of(Method method, double step) {
  MethodSettings s;
  s.method = method;
  s.step = step;
  s.tolerance = 1e-8;
  return s;
}

// The state [x; x'] of an integrator.
Vector state_of(const Integrator& integrator) {
  Vector y(2 * integrator.dofs());
  y << integrator.position(), integrator.velocity();
  return y;
}

}  // namespace

TEST_CASE("Every row builds on a short and a long chain and reports the form it took",
          "[method_table]") {
  const GapStructure short_chain = make_chain(paper_five_dof_case("4a"));
  const GapStructure long_chain = make_chain(paper_large_chain(60));
  REQUIRE(long_chain.dofs() > MethodSettings{}.banded_above);
  REQUIRE(method_table().size() == 9);
  for (const MethodTraits& row : method_table()) {
    CAPTURE(row.name);
    CHECK(&method_traits(row.method) == &row);
    for (const bool is_long : {false, true}) {
      CAPTURE(is_long);
      const GapStructure& s = is_long ? long_chain : short_chain;
      const auto integrator = make_integrator(s, settings_of(row.method, 0.01));
      const Method form = expected_form(row.method, is_long);
      CHECK(integrator->method() == form);
      CHECK(integrator->dofs() == s.dofs());
      // Built at rest at t = 0.
      CHECK(integrator->time() == 0.0);
      CHECK(state_of(*integrator).cwiseAbs().maxCoeff() == 0.0);
      // The form taken is a row of its own that does not choose again, and it is banded exactly
      // when it was taken for the long chain.
      CHECK_FALSE(method_traits(form).chooses_form);
      if (row.chooses_form) {
        CHECK(method_traits(form).banded == is_long);
      } else {
        CHECK(method_traits(form).banded == row.banded);
      }
      CHECK(integrator->has_tangent_map() == method_traits(form).tangent_map);
    }
  }
}

TEST_CASE("advance_with_tangent works exactly for the rows with a tangent map", "[method_table]") {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure short_chain = make_chain(chain);
  const GapStructure long_chain = make_chain(paper_large_chain(60));
  const double period = chain.period();
  for (const MethodTraits& row : method_table()) {
    CAPTURE(row.name);
    for (const bool is_long : {false, true}) {
      CAPTURE(is_long);
      const GapStructure& s = is_long ? long_chain : short_chain;
      const double step = is_long ? 0.01 : period / 200;
      const auto integrator = make_integrator(s, settings_of(row.method, step));
      const Index n = s.dofs();
      Matrix tangent = Matrix::Identity(2 * n, 2 * n);
      const double t_end = 10 * step;
      if (method_traits(integrator->method()).tangent_map) {
        CHECK_NOTHROW(integrator->advance_with_tangent(t_end, tangent));
        CHECK(integrator->time() == Approx(t_end).epsilon(1e-14));
        // From rest the map is not the identity any more.
        CHECK((tangent - Matrix::Identity(2 * n, 2 * n)).cwiseAbs().maxCoeff() > 1e-3);
      } else {
        CHECK_THROWS_AS(integrator->advance_with_tangent(t_end, tangent), InputError);
        CHECK(tangent == Matrix::Identity(2 * n, 2 * n));
      }
    }
  }
}

TEST_CASE("The PIM's tangent map is the derivative of its flow", "[method_table]") {
  // Figure 4a from a state reached after three periods (the springs open and close within the
  // period that follows), one period on: the Jacobian against central differences of the flow.
  // The PIM's map of a period is piecewise affine in the start state, so the differences are
  // exact up to rounding while no spring changes its contact at a step end within ±h.
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double period = chain.period();
  for (const Method method : {Method::pim, Method::pim_dense}) {
    CAPTURE(method_traits(method).name);
    const MethodSettings settings = settings_of(method, period / 200);
    const auto start = make_integrator(s, settings);
    start->advance_to(3 * period);
    const Vector x0 = start->position(), v0 = start->velocity();
    const Index n = s.dofs();

    const auto flow = [&](const Vector& y) {
      const auto integrator = make_integrator(s, settings);
      integrator->set_state(3 * period, y.head(n), y.tail(n));
      integrator->advance_to(4 * period);
      return state_of(*integrator);
    };
    Vector y0(2 * n);
    y0 << x0, v0;
    const auto integrator = make_integrator(s, settings);
    integrator->set_state(3 * period, x0, v0);
    Matrix tangent = Matrix::Identity(2 * n, 2 * n);
    integrator->advance_with_tangent(4 * period, tangent);
    // The tangent run moves the state like the plain one.
    CHECK((state_of(*integrator) - flow(y0)).cwiseAbs().maxCoeff() == 0.0);

    const double h = 1e-7;
    Matrix differences(2 * n, 2 * n);
    for (Index j = 0; j < 2 * n; ++j) {
      Vector plus = y0, minus = y0;
      plus[j] += h;
      minus[j] -= h;
      differences.col(j) = (flow(plus) - flow(minus)) / (2 * h);
    }
    const double scale = tangent.cwiseAbs().maxCoeff();
    CAPTURE(scale);
    REQUIRE(scale > 1e-2);
    CHECK((tangent - differences).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, scale));
  }
}

TEST_CASE("Fixed-grid rows refuse an end off their grid, the others reach it", "[method_table]") {
  const GapStructure s = make_chain(paper_five_dof_case("4a"));
  for (const MethodTraits& row : method_table()) {
    CAPTURE(row.name);
    const auto integrator = make_integrator(s, settings_of(row.method, 0.1));
    if (row.fixed_grid) {
      CHECK_THROWS_AS(integrator->advance_to(0.25), InputError);
      // On the grid it goes.
      CHECK_NOTHROW(integrator->advance_to(0.3));
      CHECK(integrator->time() == Approx(0.3).epsilon(1e-14));
    } else {
      CHECK_NOTHROW(integrator->advance_to(0.25));
      CHECK(integrator->time() == 0.25);
    }
  }
}

TEST_CASE("parse_method round-trips every name and refuses others, listing them",
          "[method_table]") {
  const std::vector<std::string> names = method_names();
  REQUIRE(names.size() == method_table().size());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const MethodTraits& row = method_table()[i];
    CHECK(names[i] == row.name);
    CHECK(parse_method(names[i]) == row.method);
    CHECK(method_traits(parse_method(names[i])).name == names[i]);
  }
  std::string message;
  try {
    parse_method("pim-fast");
  } catch (const InputError& e) {
    message = e.what();
  }
  CAPTURE(message);
  CHECK(message.find("\"pim-fast\"") != std::string::npos);
  for (const std::string& name : names) {
    CAPTURE(name);
    CHECK(message.find(name) != std::string::npos);
  }
  CHECK_THROWS_AS(parse_method(""), InputError);
  CHECK_THROWS_AS(parse_method("PIM"), InputError);  // the label is not a name
}

TEST_CASE("MethodSettings::is_valid names the setting and value it refuses", "[method_table]") {
  const GapStructure s = make_chain(paper_five_dof_case("4a"));
  for (const MethodTraits& row : method_table()) {
    CAPTURE(row.name);
    std::string why;
    MethodSettings settings = settings_of(row.method, 0.1);
    CHECK(settings.is_valid(s, &why));
    CHECK(why.empty());

    settings.step = 0.0;
    CHECK(settings.is_valid(s, &why) == !row.fixed_grid);
    if (row.fixed_grid) {
      CHECK(why.find("step = 0") != std::string::npos);
      CHECK_THROWS_WITH(make_integrator(s, settings), why);
      settings.step = kNaN;
      CHECK_FALSE(settings.is_valid(s, &why));
      CHECK(why.find("step = nan") != std::string::npos);
      settings.step = -0.5;
      CHECK_FALSE(settings.is_valid(s, &why));
      CHECK(why.find("step = -0.5") != std::string::npos);
    }
    settings.step = 0.1;

    for (const auto& [tolerance, named] :
         {std::pair{0.0, "tolerance = 0"}, std::pair{-1e-3, "tolerance = -0.001"},
          std::pair{kNaN, "tolerance = nan"}}) {
      CAPTURE(tolerance);
      why.clear();
      settings.tolerance = tolerance;
      CHECK(settings.is_valid(s, &why) == !row.adaptive);
      if (row.adaptive) CHECK(why.find(named) != std::string::npos);
    }
  }
}

TEST_CASE("The exact solver refuses more gap springs than it can enumerate", "[method_table]") {
  const long most = method_traits(Method::exact).max_springs;
  REQUIRE(most == 62);
  MethodSettings settings;
  settings.method = Method::exact;
  std::string why;
  CHECK(settings.is_valid(make_chain(paper_large_chain(62)), &why));
  const GapStructure too_many = make_chain(paper_large_chain(63));
  REQUIRE(too_many.spring_count() == 63);
  CHECK_FALSE(settings.is_valid(too_many, &why));
  CHECK(why.find("63 gap springs") != std::string::npos);
  CHECK(why.find("at most 62") != std::string::npos);
  CHECK_THROWS_AS(make_integrator(too_many, settings), InputError);
  // The other rows have no such limit.
  settings.method = Method::pim_banded;
  settings.step = 0.1;
  CHECK(settings.is_valid(too_many, &why));
}

TEST_CASE("method_label gives the label a reader needs to repeat the run", "[method_table]") {
  MethodSettings pim;
  pim.method = Method::pim;
  pim.step = 0.01;
  CHECK(method_label(pim) == "PIM");
  MethodSettings dopri5;
  dopri5.method = Method::dopri5;
  dopri5.tolerance = 1e-10;
  dopri5.locate_kinks = true;
  CHECK(method_label(dopri5) == "dopri5, kink-located, tol 1e-10");
  dopri5.locate_kinks = false;
  dopri5.method = Method::rkf78;
  dopri5.tolerance = 1e-6;
  CHECK(method_label(dopri5) == "rkf78, tol 1e-06");
  MethodSettings exact;
  exact.method = Method::exact;
  CHECK(method_label(exact) == "exact event-driven");
}

TEST_CASE("Every method integrates figure 4a to the same state within its accuracy",
          "[method_table][accuracy]") {
  // Five forcing periods of figure 4a from rest, by every row of the table; the truth is the
  // exact event-driven solver, itself checked against kink-located rkf78 at a tight tolerance.
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double period = chain.period();
  const double t_end = 5 * period;

  const auto run = [&](MethodSettings settings) {
    const auto integrator = make_integrator(s, settings);
    integrator->advance_to(t_end);
    CHECK(integrator->time() == Approx(t_end).epsilon(1e-14));
    // The springs open and close in these periods: a method that locates its switches counts
    // them, the others count none.
    const long switches = integrator->stats().kink_events;
    CAPTURE(switches);
    if (locates_switches(settings)) {
      CHECK(switches >= 10);
    } else {
      CHECK(switches == 0);
    }
    return state_of(*integrator);
  };
  MethodSettings exact;
  exact.method = Method::exact;
  const Vector truth = run(exact);
  REQUIRE(truth.cwiseAbs().maxCoeff() > 0.1);  // it moved

  for (const MethodTraits& row : method_table()) {
    CAPTURE(row.name);
    MethodSettings settings;
    settings.method = row.method;
    double tolerance = 0.0;
    if (row.exact) {
      // The truth against the tightest Runge-Kutta reference.
      settings.method = Method::rkf78;
      settings.tolerance = 1e-12;
      settings.locate_kinks = true;
      tolerance = 1e-8;
    } else if (row.fixed_grid && row.order == 2) {
      // The paper's step: second order, about 3e-4 here (the switches fall inside steps).
      settings.step = period / 200;
      tolerance = 1e-3;
    } else if (row.fixed_grid) {
      settings.step = period / 200;  // the switching PIM: order 5, switches located
      tolerance = 1e-8;
    } else {
      settings.tolerance = 1e-12;
      settings.locate_kinks = true;
      tolerance = 1e-8;
    }
    const double error = (run(settings) - truth).cwiseAbs().maxCoeff();
    CAPTURE(error, tolerance);
    CHECK(error <= tolerance);
  }
}
