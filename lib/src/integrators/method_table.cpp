#include "pwl/integrators/method_table.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <cmath>

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

std::unique_ptr<Integrator> make_exact(const GapStructure& g, const MethodSettings&) {
  return make_event_driven_solver(g);
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

// The one table. Columns: method, name, label, summary, fixed_grid, tangent_map, adaptive,
// kink_location, locates_switches, lcp, chooses_form, banded, exact, order, max_dofs, max_springs,
// make. A row that chooses its form states the capabilities of its dense form; the integrator it
// builds reports the form it took (Integrator::method()).
constexpr std::array<MethodTraits, 9> kTable{{
    {Method::pim, "pim", "PIM", "the paper's PIM (dense or banded by size)",
     true, true, false, false, false, true, true, false, false, 2, 0, 0, make_pim},
    {Method::pim_dense, "pim-dense", "dense PIM", "the PIM with dense operators",
     true, true, false, false, false, true, false, false, false, 2, 0, 0, make_pim_dense},
    {Method::pim_banded, "pim-banded", "banded PIM", "the PIM with banded operators (long chains)",
     true, false, false, false, false, false, false, true, false, 2, 0, 0, make_pim_banded},
    {Method::pim_switching, "pim-switching", "switching PIM",
     "higher order, located switches (dense or banded by size)",
     true, true, false, false, true, true, true, false, false, 5, 0, 0, make_switching},
    {Method::pim_switching_dense, "pim-switching-dense", "switching PIM",
     "the switching PIM with dense operators",
     true, true, false, false, true, true, false, false, false, 5, 0, 0, make_switching_dense},
    {Method::pim_switching_banded, "pim-switching-banded", "banded switching PIM",
     "the switching PIM with banded operators",
     true, true, false, false, true, false, false, true, false, 5, 0, 0, make_switching_banded},
    {Method::exact, "exact", "exact event-driven", "event-driven, closed form per contact state",
     false, true, false, false, true, false, false, false, true, 0, 0, 62, make_exact},
    {Method::dopri5, "dopri5", "dopri5", "Dormand-Prince 5(4), with --tol and --locate-kinks",
     false, false, true, true, false, false, false, false, false, 5, 0, 0,
     make_runge_kutta<RungeKuttaMethod::dopri5>},
    {Method::rkf78, "rkf78", "rkf78", "Runge-Kutta-Fehlberg 7(8), with --tol and --locate-kinks",
     false, false, true, true, false, false, false, false, false, 8, 0, 0,
     make_runge_kutta<RungeKuttaMethod::rkf78>},
}};

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
