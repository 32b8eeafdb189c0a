#pragma once
// The method table: one row per integrator pwl ships, and the one factory that builds any of them.
//
// A row says what a method is called (on the command line and in tables), what it can do and what
// it needs: a fixed step grid, an exact tangent map (Lyapunov exponents, Floquet multipliers),
// banded operators, an error tolerance, kink location, a size limit, its order of accuracy, the
// step guard's limits on a fixed step (step_guard.hpp). The command line's choices, the labels
// of tables and figures, the checks of a study's settings and the factory all read this table,
// so adding an integrator is one file that implements it (with a maker from MethodSettings), one
// enum value with its row here, and one test. Code that needs a capability asks the row
// (`method_traits(m)`) or the integrator (`Integrator::method()`), never a name.
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/numerics/lcp_solver.hpp"

namespace pwl {

struct MethodSettings;

// Builds a method's integrator from the common settings (the row's own maker: the method's options
// struct filled from the settings it reads).
using IntegratorMaker = std::unique_ptr<Integrator> (*)(const GapStructure& structure,
                                                         const MethodSettings& settings);

struct MethodTraits {
  Method method;
  std::string_view name;     // the command line's and the scene files' spelling: "pim-switching"
  std::string_view label;    // for tables and figures: "switching PIM"
  std::string_view summary;  // one line for --help
  // What the method can do.
  bool fixed_grid;    // steps of a fixed size η: needs a step, ends only on its grid
  bool tangent_map;   // exact tangent map of the motion (advance_with_tangent)
  bool adaptive;      // error-controlled step: takes a tolerance
  bool kink_location; // can end a step exactly at every spring switch (locate_kinks)
  bool locates_switches;  // always ends a step at every spring switch and counts the switches
                          // (IntegratorStats::kink_events): the switching PIM, the exact solver
  bool lcp;           // solves one LCP per step: takes an LCP algorithm
  bool chooses_form;  // picks its dense or banded form itself, by the structure
  bool banded;        // banded operators: work and memory per step grow like n
  bool exact;         // no discretisation error (the ground truth of small systems)
  int order;          // order of accuracy in the step (fixed grid) or of the embedded pair
                      // (adaptive); 0 for the exact solver. The switching PIM's is d + 3 with its
                      // default force degree d = 2.
  long max_dofs;      // the largest structure it accepts (degrees of freedom); 0: no limit
  long max_springs;   // the most gap springs it accepts; 0: no limit
  // The step guard (step_guard.hpp), fixed-grid rows only: limits on η ω_max (ω_max the highest
  // frequency with every gap spring touching) beyond which a step draws a warning (the contact
  // is under-resolved) and a refusal (the method misses contacts or blows up). 0: no step
  // guard. The values and the measurements behind them are in method_table.cpp.
  double step_warning;
  double step_limit;
  IntegratorMaker make;
};

// Every row, in the order the command line lists them.
std::span<const MethodTraits> method_table();
// The row of one method.
const MethodTraits& method_traits(Method method);
// The method named `name` ("pim-switching"). Throws InputError naming the value and every
// accepted name otherwise.
Method parse_method(std::string_view name);
// Every name, in table order (for the command line's choices and messages).
std::vector<std::string> method_names();

// How to build an integrator from the table: the settings of every method, each read only by the
// methods whose row asks for it.
struct MethodSettings {
  Method method = Method::pim;
  double step = 0.0;          // fixed_grid: η > 0
  double tolerance = 1e-10;   // adaptive: relative and absolute tolerance
  bool locate_kinks = false;  // kink_location: end a step at every spring switch
  double max_step = 0.0;      // adaptive: the largest step (0: no limit)
  LcpAlgorithm lcp = LcpAlgorithm::block_pivoting;  // lcp (dense forms; the banded ones have their own)
  long banded_above = 50;     // chooses_form: banded beyond this many degrees of freedom
  long band = 0;              // banded forms: a forced band q of the step operators, in degrees
                              // of freedom (0: the smallest q within the truncation tolerance)
  int force_degree = 2;       // switching forms: derivatives d of the load used (order d + 3)
  // exact: the event-driven solver's options, among them its work budget per advance_to call
  // (max_events, max_gap_samples) and the progress hook a program can print from.
  EventDrivenOptions event_driven{};

  // Ceres-style check against the structure it will integrate: false with a message naming the
  // setting and its value (a step that is not positive, a tolerance that is not, a structure
  // beyond the method's size limits).
  bool is_valid(const GapStructure& structure, std::string* why) const;
  // These settings for a case of forcing period T: the step T / steps_per_period on a fixed grid
  // (so that every forcing period ends on the grid), the largest step T/8 for an adaptive method.
  MethodSettings for_period(double period, int steps_per_period) const;
};

// The method's label with the settings a reader needs to repeat the run: "PIM", "switching PIM"
// ("switching PIM, d = 6" for a force degree other than 2), "dopri5, kink-located, tol 1e-10"
// (for tables, figure legends and study descriptions).
std::string method_label(const MethodSettings& settings);

// Whether the integrator the settings build ends a step at every spring switch and counts the
// switches in IntegratorStats::kink_events: a row that always does (locates_switches), or one
// that can (kink_location) asked to (locate_kinks).
bool locates_switches(const MethodSettings& settings);

// Whether the row's method takes a force degree d (MethodSettings::force_degree, order d + 3):
// the switching PIM's rows, the fixed-grid methods that locate every switch.
inline bool takes_force_degree(const MethodTraits& row) {
  return row.fixed_grid && row.locates_switches;
}

// The integrator the settings name, built for `structure`, its state at rest at t = 0. Throws
// InputError for invalid settings (the message of is_valid) or a structure the method refuses.
std::unique_ptr<Integrator> make_integrator(const GapStructure& structure,
                                            const MethodSettings& settings);

}  // namespace pwl
