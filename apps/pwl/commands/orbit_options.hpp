#pragma once
// What `pwl orbit` and `pwl continue` share (orbits/ in the analysis library does the work): the
// case flags of simulate and analyze with the flags of a periodic orbit's shooting, the point
// model they describe, the default method of an orbit, the starting guess (a transient from rest
// or a state file) and how a multiplier is printed.
#include <CLI/CLI.hpp>
#include <complex>
#include <string>
#include <vector>

#include "commands/case_options.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

struct OrbitFlags {
  CaseOptions run;             // the case and its integrator (--method etc.)
  bool method_given = false;   // --method typed (or set by a scene): else the orbit default
  int period = 1;              // k: forcing periods per orbit
  double newton_tolerance = 1e-10;
  int max_iterations = 40;
  int transient = 200;         // forcing periods from rest before the guess is taken
  double multiplier_margin = 0.0;  // Arnoldi reports every multiplier with |μ| > 1 − this
  std::string multiplier_method = "automatic";  // Krylov: "automatic" (Davidson where it can) or "arnoldi"
  int gmres_recycle = 10;      // Krylov: vectors GMRES recycles (ShootingOptions::gmres_recycled)
  bool gmres_reform = false;   // Krylov: carried to a new operator (ShootingOptions::gmres_reform)
  bool no_precondition = false;  // Krylov: GMRES without the open structure's preconditioner
  std::string guess_file;      // a state file instead of the transient
  std::string out = "orbit";
  bool quiet = false;
};

// The case flags (add_case_options, without --periods and --skip-periods, which an orbit does not
// use, and without --dt unless `with_dt`), --period, --newton-tol, --max-iterations, --transient,
// --guess-file, --multiplier-margin, --multiplier-method, --gmres-recycle, --gmres-reform,
// --no-precondition, --out and --quiet. --method's default becomes the orbit default
// (orbit_method).
void add_orbit_flags(CLI::App& command, OrbitFlags& flags, bool with_dt);
// To be called from the command's callback: records whether --method was given.
void read_method_given(const CLI::App& command, OrbitFlags& flags);

// The integrator of an orbit. Without --method: the exact event-driven solver for a structure of
// at most 20 degrees of freedom and 62 gap springs (exact multipliers, no step error), else the
// switching PIM (a fixed grid of --steps-per-period steps, high order, exact tangent map).
struct OrbitMethod {
  MethodSettings settings;   // as CaseOptions gives them (the step is set per period by the map)
  int steps_per_period = 200;
  bool chosen = false;       // the default, not --method
};
OrbitMethod orbit_method(const OrbitFlags& flags, const GapStructure& structure, double period);

// A state y = [x; v] read from a CSV file: a header naming x1..xn,v1..vn (a leading column
// such as t is skipped) and the last row (orbit.csv, or a simulate run's poincare.csv). Throws
// InputError naming `flag`, the file and what is wrong.
Vector read_state_file(const std::string& flag, const std::string& path, Index dofs);

// Prints a note when `map`'s method has no exact tangent map (its monodromy then comes from forward
// differences of the flow, one integration per column, and its multipliers are accurate to about
// eight digits).
void note_when_no_tangent_map(const orbits::StroboscopicMap& map);

// The starting guess: the state in --guess-file, or the state --transient forcing periods after
// the initial state of --x0/--v0 (rest by default), by `map` (its structure is the case the guess
// is for). InputError for --guess-file with --x0/--v0, or a bad --x0/--v0.
Vector starting_guess(const OrbitFlags& flags, orbits::StroboscopicMap& map);

// ShootingOptions from the flags (period, tolerance, iterations); `flag_prefix`-free checks.
orbits::ShootingOptions shooting_options(const OrbitFlags& flags);

// Checks the shared flags, naming them: InputError for --period < 1, --newton-tol <= 0, ...
void check_orbit_flags(const OrbitFlags& flags);

// "-1.2345+0.0123i".
std::string multiplier_text(const std::complex<double>& mu);

// "Arnoldi", "Davidson" or "the dense monodromy": how the multipliers were found.
std::string eigen_solver_name(orbits::FloquetMultipliers::Method method);

// The method's name for a line of text: "exact event-driven", "switching PIM, η = T/200".
std::string orbit_method_label(const OrbitMethod& method);

}  // namespace pwl::app
