// The step for a requested accuracy (accuracy_step.hpp): the chosen step meets the request
// against a kink-located rkf78 reference at 1e-12 on a chain whose cells vary, without being
// needlessly short, for the switching PIM (banded, order 5), the switching PIM choosing its force
// degree among 2, 4 and 6 too (a step at least as long as degree 2's alone) and the paper's PIM;
// and bad requests are refused by name.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pwl/errors.hpp"
#include "pwl/integrators/accuracy_step.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"

using namespace pwl;

namespace {

// 60 masses (the switching PIM goes banded), three kinds of cell: masses, chain springs, contact
// springs and gaps (one preloaded) all vary along the chain; the paper's loads (period 2π).
GapStructure varying_chain() {
  ChainParameters p = paper_large_chain(60);
  p.mass.clear();
  p.k1.clear();
  p.k2.clear();
  p.gap.clear();
  for (int i = 0; i < p.masses; ++i) {
    p.mass.push_back(std::vector<double>{1.0, 1.3, 0.7}[static_cast<std::size_t>(i % 3)]);
    p.k1.push_back(std::vector<double>{1.0, 2.0}[static_cast<std::size_t>(i % 2)]);
    p.k2.push_back(std::vector<double>{1.0, 3.0, 0.5}[static_cast<std::size_t>(i % 3)]);
    p.gap.push_back(std::vector<double>{0.0, 0.05, -0.02, 0.1}[static_cast<std::size_t>(i % 4)]);
  }
  return make_chain(p);
}

// The states [x; x'] at the given times.
std::vector<Vector> states(Integrator& integrator, const std::vector<double>& times) {
  std::vector<Vector> out;
  const Index n = integrator.dofs();
  for (const double t : times) {
    integrator.advance_to(t);
    Vector y(2 * n);
    y << integrator.position(), integrator.velocity();
    out.push_back(y);
  }
  return out;
}

// The relative error of accuracy_step.hpp: the largest position error over the largest position,
// the same for the velocities, the larger of the two.
double relative_error(const std::vector<Vector>& a, const std::vector<Vector>& truth, Index n) {
  double dx = 0.0, dv = 0.0, sx = 0.0, sv = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    dx = std::max(dx, (a[k].head(n) - truth[k].head(n)).cwiseAbs().maxCoeff());
    dv = std::max(dv, (a[k].tail(n) - truth[k].tail(n)).cwiseAbs().maxCoeff());
    sx = std::max(sx, truth[k].head(n).cwiseAbs().maxCoeff());
    sv = std::max(sv, truth[k].tail(n).cwiseAbs().maxCoeff());
  }
  return std::max(dx / sx, dv / sv);
}

// A request for `tolerance` over one period of the paper's loads (2π), probed on that period.
AccuracyRequest one_period_request(double tolerance) {
  AccuracyRequest r;
  r.relative_tolerance = tolerance;
  r.period = 2 * M_PI;
  r.probe = 2 * M_PI;
  return r;
}

}  // namespace

TEST_CASE("accuracy request: the chosen step meets it against kink-located rkf78",
          "[accuracy]") {
  const GapStructure s = varying_chain();
  const Index n = s.dofs();
  const double period = 2 * M_PI, horizon = 2 * period;
  MethodSettings reference;
  reference.method = Method::rkf78;
  reference.tolerance = 1e-12;
  reference.locate_kinks = true;
  const Vector zero = Vector::Zero(n);

  struct Case {
    Method method;
    double tolerance;
    std::vector<int> degrees;
    AccuracyStep chosen;
  };
  const std::vector<int> degrees{2, 4, 6};
  std::vector<Case> cases{{Method::pim_switching, 1e-5, {}, {}},
                          {Method::pim_switching, 1e-8, {}, {}},
                          {Method::pim_switching, 1e-5, degrees, {}},
                          {Method::pim_switching, 1e-8, degrees, {}},
                          {Method::pim_switching, 1e-3, degrees, {}},
                          {Method::pim, 1e-3, {}, {}}};
  // The steps first, then one reference run through every step end of every case.
  std::vector<double> all_times;
  for (Case& c : cases) {
    MethodSettings m;
    m.method = c.method;
    AccuracyRequest request;
    request.relative_tolerance = c.tolerance;
    request.period = period;
    request.probe = horizon;
    request.force_degrees = c.degrees;
    c.chosen = step_for_accuracy(s, m, 0.0, zero, zero, request);
    for (long k = 1; k <= 2 * c.chosen.steps_per_period; ++k) all_times.push_back(k * c.chosen.step);
  }
  std::sort(all_times.begin(), all_times.end());
  auto truth_integrator = make_integrator(s, reference);
  const std::vector<Vector> all_truth = states(*truth_integrator, all_times);
  for (const Case& c : cases) {
    const AccuracyStep& chosen = c.chosen;
    MethodSettings m;
    m.method = c.method;
    m.step = chosen.step;
    if (takes_force_degree(method_traits(c.method))) m.force_degree = chosen.force_degree;
    // Every step's end over the horizon, against the reference at the same times.
    std::vector<double> times;
    std::vector<Vector> truth;
    for (long k = 1; k <= 2 * chosen.steps_per_period; ++k) {
      times.push_back(k * chosen.step);
      const auto at = std::lower_bound(all_times.begin(), all_times.end(), times.back());
      truth.push_back(all_truth[static_cast<std::size_t>(at - all_times.begin())]);
    }
    auto integrator = make_integrator(s, m);
    const double error = relative_error(states(*integrator, times), truth, n);
    INFO(method_traits(c.method).name << " at rtol " << c.tolerance << ": T/"
                                      << chosen.steps_per_period << " (d = " << chosen.force_degree
                                      << ") after " << chosen.candidates
                                      << " candidates, estimate " << chosen.estimated_error
                                      << ", measured " << error << ", guard's largest step "
                                      << chosen.largest_step);
    CHECK(chosen.step == Approx(period / static_cast<double>(chosen.steps_per_period)));
    CHECK(chosen.estimated_error <= c.tolerance);
    CHECK(error <= c.tolerance);
    // Not needlessly short: within 1e-3 of the tolerance, or the longest step the guard lets
    // through (a high degree can be far more accurate than asked there).
    const bool longest = chosen.steps_per_period ==
                         static_cast<long>(std::ceil(period / chosen.largest_step - 1e-9));
    CHECK((error >= 1e-3 * c.tolerance || (!c.degrees.empty() && longest)));
    CHECK(chosen.step <= chosen.largest_step * (1 + 1e-12));
    if (c.method == Method::pim) CHECK(chosen.force_degree == -1);
    if (c.method == Method::pim_switching && c.degrees.empty()) CHECK(chosen.force_degree == 2);
  }
  // With the degrees to choose from, a step at least as long as degree 2's alone, and (checked by
  // hand on this chain) the highest degree where accuracy is asked, the lowest where it is not.
  for (std::size_t k = 0; k < 2; ++k) {
    const AccuracyStep& alone = cases[k].chosen;
    const AccuracyStep& chosen = cases[k + 2].chosen;
    INFO("rtol " << cases[k].tolerance << ": d = 2 alone T/" << alone.steps_per_period
                 << ", chosen d = " << chosen.force_degree << " T/" << chosen.steps_per_period);
    CHECK(chosen.steps_per_period <= alone.steps_per_period);
  }
  CHECK(cases[2].chosen.force_degree == 4);  // d = 2 missed at d = 6's step, d = 4 met it
  CHECK(cases[2].chosen.degree_checks == 2);
  CHECK(cases[3].chosen.force_degree == 6);
  CHECK(cases[3].chosen.steps_per_period * 2 <= cases[1].chosen.steps_per_period);
  CHECK(cases[4].chosen.force_degree == 2);
}

TEST_CASE("accuracy request: the degrees' order and repeats do not matter, one degree is the "
          "base's",
          "[accuracy]") {
  const GapStructure s = varying_chain();
  const Vector zero = Vector::Zero(s.dofs());
  MethodSettings m;
  m.method = Method::pim_switching;
  AccuracyRequest request = one_period_request(1e-5);
  request.force_degrees = {2, 4, 6};
  const AccuracyStep sorted = step_for_accuracy(s, m, 0.0, zero, zero, request);
  request.force_degrees = {6, 2, 6, 4};
  const AccuracyStep shuffled = step_for_accuracy(s, m, 0.0, zero, zero, request);
  CHECK(shuffled.steps_per_period == sorted.steps_per_period);
  CHECK(shuffled.force_degree == sorted.force_degree);
  CHECK(shuffled.estimated_error == sorted.estimated_error);
  CHECK(shuffled.degree_checks == sorted.degree_checks);
  // One degree asked is the base settings at that degree, step for step.
  request.force_degrees = {4};
  const AccuracyStep one = step_for_accuracy(s, m, 0.0, zero, zero, request);
  request.force_degrees.clear();
  m.force_degree = 4;
  const AccuracyStep base = step_for_accuracy(s, m, 0.0, zero, zero, request);
  CHECK(one.steps_per_period == base.steps_per_period);
  CHECK(one.estimated_error == base.estimated_error);
  CHECK(one.force_degree == 4);
  CHECK(base.force_degree == 4);
  CHECK(one.degree_checks == 0);
}

TEST_CASE("accuracy request: bad requests are refused by name", "[accuracy]") {
  const GapStructure s = varying_chain();
  const Vector zero = Vector::Zero(s.dofs());
  MethodSettings m;
  m.method = Method::pim_switching;
  const AccuracyRequest r = one_period_request(1e-6);
  const auto message = [&](const MethodSettings& settings, const AccuracyRequest& request) {
    try {
      step_for_accuracy(s, settings, 0.0, zero, zero, request);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no InputError");
  };
  AccuracyRequest bad = r;
  bad.relative_tolerance = 0.0;
  CHECK_THAT(message(m, bad), Catch::Contains("relative_tolerance = 0"));
  bad.relative_tolerance = std::nan("");
  CHECK_THAT(message(m, bad), Catch::Contains("relative_tolerance = nan"));
  bad = r;
  bad.period = -1.0;
  CHECK_THAT(message(m, bad), Catch::Contains("period = -1"));
  bad = r;
  bad.probe = 0.0;
  CHECK_THAT(message(m, bad), Catch::Contains("probe = 0"));
  MethodSettings adaptive;
  adaptive.method = Method::dopri5;
  CHECK_THAT(message(adaptive, r), Catch::Contains("dopri5 chooses its own steps"));
  bad = r;
  bad.relative_tolerance = 1e-13;
  CHECK_THAT(message(m, bad), Catch::Contains("relative_tolerance = 1e-13 is below 1e-12"));
  bad = r;
  bad.relative_tolerance = 1e-10;
  bad.max_steps_per_period = 20;
  CHECK_THAT(message(m, bad), Catch::Contains("relative tolerance = 1e-10: pim-switching does not "
                                              "reach it on this structure within 20 steps"));
  bad = r;
  bad.relative_tolerance = 1e-10;
  bad.max_steps_per_period = 20;
  bad.force_degrees = {2, 4};
  CHECK_THAT(message(m, bad), Catch::Contains("force degree 4 (the highest asked): relative "
                                              "tolerance = 1e-10: pim-switching does not reach"));
  bad = r;
  bad.force_degrees = {2, 9};
  CHECK_THAT(message(m, bad), Catch::Contains("force_degrees: degree 9 is not in 0 .. 8"));
  bad.force_degrees = {-1};
  CHECK_THAT(message(m, bad), Catch::Contains("force_degrees: degree -1 is not in 0 .. 8"));
  MethodSettings plain;
  plain.method = Method::pim;
  bad = r;
  bad.force_degrees = {2, 4};
  CHECK_THAT(message(plain, bad),
             Catch::Contains("force_degrees = [2, 4]: pim takes no force degree"));
}
