#pragma once
// pwl continue as functions, for the command and for an embedding (the Python module): its flags,
// and the continuation they describe, checked and ready to run. The command then takes the
// starting guess, runs continue_periodic_orbit with an observer that writes branch.csv,
// branch_section.csv and bifurcations.csv as the branch grows, and draws its figures; the Python
// module runs the same continuation and keeps the points in memory.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands/orbit_options.hpp"
#include "pwl/orbits/bifurcation_curves.hpp"
#include "pwl/orbits/continuation.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

// The orbit flags' defaults in pwl continue: the multipliers' margin continuation asks
// (orbits::kContinuationMargin, the band's least width matrix-free) and the folder.
inline OrbitFlags continue_orbit_flags() {
  OrbitFlags f;
  f.multiplier_margin = orbits::kContinuationMargin;
  f.out = "continuation";
  return f;
}

struct ContinueFlags {
  OrbitFlags orbit = continue_orbit_flags();
  std::string parameter;
  std::string range;
  bool switch_branches = false;
  int max_branches = 4;
  int max_points = 2000;
  double step = 0.0;
  double min_step = 0.0;
  double max_step = 0.0;
  std::vector<std::string> record;
  bool no_grazing = false;
  double band = 0.05;  // ContinuationOptions::band
  std::string corrector = "automatic";
  int over_sweep = 0;
  int over_periods = 100;
  bool no_plot = false;
  int threads = 0;
  // Bifurcation curves in two parameters (bifurcation_curves.hpp): Q=FROM:TO, the types, one row
  // of bifurcations.csv to start from (0: every row of those types), points per direction.
  std::string curves;
  std::vector<std::string> curve_types;
  int start_bifurcation = 0;
  int curve_points = 1000;
};

// Every flag of pwl continue (add_orbit_flags without --dt, --parameter, --range, ...), with
// --out's default "continuation". After parsing, call read_method_given(command, flags.orbit).
void add_continue_flags(CLI::App& command, ContinueFlags& flags);

// The continuation the flags describe.
struct ContinuationProblem {
  analysis::PointModel base;           // the model at the flags' values
  analysis::SweepParameter parameter;  // --parameter
  double from = 0.0;                   // --range FROM:TO, as given
  double to = 0.0;
  std::vector<int> dofs;               // --record, 0-based (every mass up to 10 by default)
  analysis::PointCase first_case;      // the case at FROM, where the guess is taken
  OrbitMethod method;
  orbits::ContinuationOptions options;
  // With --curves: the curves' options (P the branch's parameter and range), and the row of
  // bifurcations.csv they start from (0: every located row of their types).
  std::optional<orbits::CurvesOptions> curves;
  int start_bifurcation = 0;
};

// The bifurcations the curves start from: every located one of the curves' types, or the row
// --start-bifurcation names (1-based, in bifurcations.csv's order). Throws InputError naming
// --start-bifurcation when that row does not exist, was not located, or is of a type
// --curve-types leaves out.
std::vector<orbits::Bifurcation> curve_starts(const ContinuationProblem& problem,
                                              const std::vector<orbits::Bifurcation>& found);

// Checks the flags (InputError naming the flag and its value) and sets up the continuation. The
// guess is starting_guess(flags.orbit, map) on the map of problem.first_case.
ContinuationProblem continuation_problem(const ContinueFlags& flags);

// The detail column of bifurcations.csv: "largest gap" or "smallest gap" for a grazing, "starts
// branch j", "ends branch j", "not located (...)", joined by "; ".
std::string bifurcation_detail(const orbits::Bifurcation& bifurcation);

}  // namespace pwl::app
