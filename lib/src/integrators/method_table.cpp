#include "pwl/integrators/method_table.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "pwl/errors.hpp"
#include "pwl/integrators/banded_pim_integrator.hpp"
#include "pwl/integrators/banded_switching_pim.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/pim_integrator.hpp"
#include "pwl/integrators/reference_integrator.hpp"
#include "pwl/integrators/switching_pim.hpp"

namespace pwl {
namespace {

// The makers: each fills its method's options from the common settings.
PimOptions pim_options(const MethodSettings& s) {
  PimOptions p;
  p.step = s.step;
  p.lcp_solver = s.lcp;
  return p;
}

SwitchingPimOptions switching_options(const MethodSettings& s) {
  SwitchingPimOptions o;
  o.step = s.step;
  o.lcp_solver = s.lcp;
  o.force_degree = s.force_degree;
  return o;
}

std::unique_ptr<Integrator> make_pim(const GapStructure& g, const MethodSettings& s) {
  return make_pim_integrator_auto(g, pim_options(s), s.banded_above);
}

std::unique_ptr<Integrator> make_pim_dense(const GapStructure& g, const MethodSettings& s) {
  return make_pim_integrator(g, pim_options(s));
}

std::unique_ptr<Integrator> make_pim_banded(const GapStructure& g, const MethodSettings& s) {
  BandedPimOptions b;
  b.step = s.step;
  b.band.band = s.band;
  return make_banded_pim_integrator(g, b);
}

std::unique_ptr<Integrator> make_switching_dense(const GapStructure& g, const MethodSettings& s) {
  return make_switching_pim(g, switching_options(s));
}

std::unique_ptr<Integrator> make_switching_banded(const GapStructure& g, const MethodSettings& s) {
  BandedSwitchingPimOptions b;
  b.pim = switching_options(s);
  b.band.band = s.band;
  return make_banded_switching_pim(g, b);
}

std::unique_ptr<Integrator> make_switching(const GapStructure& g, const MethodSettings& s) {
  if (g.dofs() > s.banded_above && banded_layout(g).banded) return make_switching_banded(g, s);
  return make_switching_dense(g, s);
}

std::unique_ptr<Integrator> make_exact(const GapStructure& g, const MethodSettings& s) {
  return make_event_driven_solver(g, s.event_driven);
}

template <RungeKuttaMethod kMethod>
std::unique_ptr<Integrator> make_runge_kutta(const GapStructure& g, const MethodSettings& s) {
  ReferenceOptions r;
  r.method = kMethod;
  r.relative_tolerance = r.absolute_tolerance = s.tolerance;
  r.locate_kinks = s.locate_kinks;
  r.max_step = s.max_step;
  return make_reference_integrator(g, r);
}

// The step guard's limits on η ω_max (step_guard.hpp), measured on figure 4a's chain with the
// contact stiffness ratio α = k2/k1 varied (ω_max = √(α + 3.68), η ω_max = 2π ω_max / N at T/N).
//
// Failures, from `pwl bench stability --alpha 1,10,100,1000,10000,100000,1000000 --steps
// 10,15,20,25,35,50,70,100,140,200,280,400,560,800,1130,1600,2260,3200,4520,6400 --tol 1e-3`
// (200 periods from rest against the exact solver): the paper's PIM blows up (|x| ~ 1e11) in
// every cell with η ω_max >= 4.27 (the lowest: α = 100 at T/15), misses contacts (sees fewer
// than 95% of the exact switches) in every cell from 1.96 to 3.98 (93% at α = 1e6, T/3200,
// 1.96; 78% at α = 1e5, T/560, 3.55), and in no cell below 1.96 (95.4% at 1.42, 98% and more
// below 1.3); the one other failure is a wrong regime at α = 10, T/15 (1.55).
// Accuracy, over 3 periods from rest against the exact solver at α = 1e4, 1e6, 1e8, 1e9: the
// PIM's largest state error is 0.17 ... 0.76 at η ω_max = 2, 0.12 ... 0.45 at 1.5, 0.03 ... 0.11
// at 1, 0.011 ... 0.045 at 0.5, 0.002 ... 0.014 at 0.25; the switching PIM's 6e-3 ... 1.2e-2 at
// 2, 3e-3 ... 1.2e-2 at 1.5, 1.2e-4 ... 5.5e-4 at 1, 3e-6 or less at 0.5
// (tests/integrators/step_guard_test.cpp checks the suggested steps on α = 1e9).
//
// The PIM: refusal above π/2 (a step longer than a quarter of the contact's period: its half
// period spans fewer than two steps), 1.25 below the first missed contacts; warning above 0.5,
// where the error over a few periods passes the PIM's own second-order level of 1e-2 (4π steps
// per contact period). The paper's settings are at 0.074 (figure 4a, T/200) and 0.108 (figure
// 4b), every shipped scene at 0.28 or less.
constexpr double kPimWarning = 0.5;
constexpr double kPimLimit = std::numbers::pi / 2.0;
// The switching PIM refuses η ω_max > 2 itself (its force derivatives and Taylor pieces need
// η ||H_A|| moderate: SwitchingPimOptions::max_step_argument, with the guard's ω_max), and no
// cell of the bench it accepted missed a contact or blew up. Its error jumps 20-fold between 1
// and 1.5. So: refusal above 2 (its own limit), warning above 1.
constexpr double kSwitchingWarning = 1.0;
constexpr double kSwitchingLimit = 2.0;

// The one table. Columns: method, name, label, summary, fixed_grid, tangent_map, adaptive,
// kink_location, locates_switches, lcp, chooses_form, banded, exact, order, max_dofs, max_springs,
// step_warning, step_limit, make. A row that chooses its form states the capabilities of its
// dense form; the integrator it builds reports the form it took (Integrator::method()). Rows
// without a fixed step have no step guard (0, 0): step_guard.hpp says why.
constexpr std::array<MethodTraits, 9> kTable{{
    {Method::pim, "pim", "PIM", "the paper's PIM (dense or banded by size)",
     true, true, false, false, false, true, true, false, false, 2, 0, 0,
     kPimWarning, kPimLimit, make_pim},
    {Method::pim_dense, "pim-dense", "dense PIM", "the PIM with dense operators",
     true, true, false, false, false, true, false, false, false, 2, 0, 0,
     kPimWarning, kPimLimit, make_pim_dense},
    {Method::pim_banded, "pim-banded", "banded PIM", "the PIM with banded operators (long chains)",
     true, false, false, false, false, false, false, true, false, 2, 0, 0,
     kPimWarning, kPimLimit, make_pim_banded},
    {Method::pim_switching, "pim-switching", "switching PIM",
     "higher order, located switches (dense or banded by size)",
     true, true, false, false, true, true, true, false, false, 5, 0, 0,
     kSwitchingWarning, kSwitchingLimit, make_switching},
    {Method::pim_switching_dense, "pim-switching-dense", "switching PIM",
     "the switching PIM with dense operators",
     true, true, false, false, true, true, false, false, false, 5, 0, 0,
     kSwitchingWarning, kSwitchingLimit, make_switching_dense},
    {Method::pim_switching_banded, "pim-switching-banded", "banded switching PIM",
     "the switching PIM with banded operators",
     true, true, false, false, true, false, false, true, false, 5, 0, 0,
     kSwitchingWarning, kSwitchingLimit, make_switching_banded},
    {Method::exact, "exact", "exact event-driven", "event-driven, closed form per contact state",
     false, true, false, false, true, false, false, false, true, 0, 0, 62, 0.0, 0.0, make_exact},
    {Method::dopri5, "dopri5", "dopri5", "Dormand-Prince 5(4), with --tol and --locate-kinks",
     false, false, true, true, false, false, false, false, false, 5, 0, 0, 0.0, 0.0,
     make_runge_kutta<RungeKuttaMethod::dopri5>},
    {Method::rkf78, "rkf78", "rkf78", "Runge-Kutta-Fehlberg 7(8), with --tol and --locate-kinks",
     false, false, true, true, false, false, false, false, false, 8, 0, 0, 0.0, 0.0,
     make_runge_kutta<RungeKuttaMethod::rkf78>},
}};

static_assert([] {
  for (const MethodTraits& row : kTable) {
    if (row.fixed_grid != (row.step_limit > 0.0)) return false;
    if (row.step_limit > 0.0 && !(row.step_warning > 0.0 && row.step_warning < row.step_limit)) {
      return false;
    }
  }
  return true;
}(), "every fixed-grid row, and only those, has a step guard with its warning below its limit");

static_assert([] {
  for (std::size_t i = 0; i < kTable.size(); ++i) {
    if (static_cast<std::size_t>(kTable[i].method) != i) return false;
  }
  return true;
}(), "the method table's rows follow the order of enum Method");

}  // namespace

std::span<const MethodTraits> method_table() { return kTable; }

const MethodTraits& method_traits(Method method) {
  return kTable[static_cast<std::size_t>(method)];
}

std::vector<std::string> method_names() {
  std::vector<std::string> names;
  for (const MethodTraits& row : kTable) names.emplace_back(row.name);
  return names;
}

Method parse_method(std::string_view name) {
  for (const MethodTraits& row : kTable) {
    if (row.name == name) return row.method;
  }
  throw InputError(fmt::format("method = \"{}\" is not known; use one of {}", name,
                               fmt::join(method_names(), ", ")));
}

std::string method_label(const MethodSettings& s) {
  const MethodTraits& row = method_traits(s.method);
  if (takes_force_degree(row) && s.force_degree != MethodSettings{}.force_degree) {
    return fmt::format("{}, d = {}", row.label, s.force_degree);
  }
  if (!row.adaptive) return std::string(row.label);
  return fmt::format("{}{}, tol {:g}", row.name, s.locate_kinks ? ", kink-located" : "",
                     s.tolerance);
}

bool MethodSettings::is_valid(const GapStructure& structure, std::string* why) const {
  std::string scratch;
  if (why == nullptr) why = &scratch;
  const MethodTraits& row = method_traits(method);
  if (row.fixed_grid && (!std::isfinite(step) || step <= 0.0)) {
    *why = fmt::format("{}: step = {} must be positive and finite", row.name, step);
    return false;
  }
  if (row.adaptive && (!std::isfinite(tolerance) || tolerance <= 0.0)) {
    *why = fmt::format("{}: tolerance = {} must be positive and finite", row.name, tolerance);
    return false;
  }
  if (row.adaptive && (!std::isfinite(max_step) || max_step < 0.0)) {
    *why = fmt::format("{}: max_step = {} must be >= 0 and finite", row.name, max_step);
    return false;
  }
  if (row.max_dofs > 0 && structure.dofs() > row.max_dofs) {
    *why = fmt::format("{}: the structure has {} degrees of freedom, the method takes at most {}",
                       row.name, structure.dofs(), row.max_dofs);
    return false;
  }
  if (row.max_springs > 0 && structure.spring_count() > row.max_springs) {
    *why = fmt::format("{}: the structure has {} gap springs, the method takes at most {}",
                       row.name, structure.spring_count(), row.max_springs);
    return false;
  }
  if (banded_above < 0) {
    *why = fmt::format("banded_above = {} must be >= 0", banded_above);
    return false;
  }
  if (band < 0) {
    *why = fmt::format("band = {} must be >= 0", band);
    return false;
  }
  if (method == Method::exact) {
    std::string inner;
    if (!event_driven.is_valid(&inner)) {
      *why = fmt::format("{}: event_driven.{}", row.name, inner);
      return false;
    }
  }
  return true;
}

bool locates_switches(const MethodSettings& s) {
  const MethodTraits& row = method_traits(s.method);
  return row.locates_switches || (row.kink_location && s.locate_kinks);
}

std::unique_ptr<Integrator> make_integrator(const GapStructure& structure,
                                            const MethodSettings& s) {
  std::string why;
  if (!s.is_valid(structure, &why)) throw InputError(why);
  std::unique_ptr<Integrator> result = method_traits(s.method).make(structure, s);
  result->set_state(0.0, Vector::Zero(structure.dofs()), Vector::Zero(structure.dofs()));
  return result;
}

MethodSettings MethodSettings::for_period(double period, int steps_per_period) const {
  MethodSettings m = *this;
  const MethodTraits& row = method_traits(m.method);
  if (row.fixed_grid) m.step = period / steps_per_period;
  if (row.adaptive) m.max_step = period / 8;
  return m;
}

}  // namespace pwl
