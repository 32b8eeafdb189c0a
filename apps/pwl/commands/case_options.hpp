#pragma once
// The flags that describe one case of the nondimensional chain and how to integrate it, shared by
// the subcommands that run a single case (simulate, analyze, orbit, continue), and the flags of
// the initial state and of the Poincaré section, which sweep and map take too.
#include <CLI/CLI.hpp>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/analysis/poincare_section.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

// --x0 and --v0: the initial displacements and velocities of every job that integrates a case.
// Each takes one value per mass, or one value for every mass (as --alpha and --loads do); either
// left out is zero, so that by default a run starts at rest. The loads start at phase 0 (t = 0).
struct InitialStateFlags {
  std::vector<double> x0;
  std::vector<double> v0;

  bool at_rest() const { return x0.empty() && v0.empty(); }
  // [x0; v0] for a structure of `dofs` degrees of freedom. Throws InputError naming the flag and
  // its value for a count that is neither 1 nor dofs, or a value that is not finite.
  Vector state(Index dofs) const;
  // For messages: "rest", or the flags given ("x0 = (0.1), v0 = (0,1,0,0,0)").
  std::string text() const;
  // "" at rest, else " from " + text(): what a description of the case adds.
  std::string description() const { return at_rest() ? std::string() : " from " + text(); }
};
void add_initial_state_flags(CLI::App& command, InitialStateFlags& flags);

// --section and --phase: which Poincaré section a job records (see PoincareSection in
// pwl/analysis/poincare_section.hpp). `strobe` (the default) takes the stroboscopic points at
// t = (k + phase) T; a hyperplane, written like `v3=0,down` or `x2=0.1,up` (x<i> or v<i>, a level,
// up|down|both), takes every crossing. The regime, λ1 and K stay classified on the stroboscopic
// map at --phase whatever the section: they are properties of the motion; the section changes
// which points are recorded, written and drawn.
struct SectionFlags {
  std::string section = "strobe";
  double phase = 0.0;

  // The section for a structure of `dofs` degrees of freedom. Throws InputError naming --section
  // or --phase and the value: malformed text, a component out of range, a level or phase that is
  // not finite, a phase outside [0, 1).
  analysis::PoincareSection poincare_section(Index dofs) const;
};
// `what` completes --section's help: what the job does with the recorded points.
void add_section_flags(CLI::App& command, SectionFlags& flags, const std::string& what);

struct CaseOptions {
  std::string figure;  // a paper preset ("4a", "4b", "5", "6"); flags override it
  int masses = 5;
  std::vector<double> alpha;  // one value or one per mass
  // NaN: not given (the preset or the default applies).
  double zeta = std::numeric_limits<double>::quiet_NaN();
  double gap = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> gaps;  // per mass, overrides gap
  double theta = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> loads;  // Q per mass (or one value)
  int periods = 1000;
  int skip_periods = 0;  // periods left out of the written output
  int steps_per_period = 200;
  double dt = 0.0;             // overrides steps_per_period; must divide the period
  // > 0: the PIM family's accuracy request (accuracy_step.hpp), instead of steps_per_period and
  // dt: the largest step T/N whose estimated error over the first periods meets it.
  double rtol = 0.0;
  std::string method = "pim";  // a name of the method table (method_names())
  // The switching PIM's force degree d (order d + 3), 0 .. 8; -1: not given (2, or with --rtol
  // chosen from 2, 4 and 6 with the step: accuracy_step.hpp).
  int force_degree = -1;
  double tolerance = 1e-10;
  bool locate_kinks = false;
  std::string lcp_solver = "block-pivoting";
  // An explicit structure from a scene file's [structure] table (scene_structure.hpp) instead of
  // the chain; the chain's flags do not apply then.
  std::string structure_scene;
  InitialStateFlags start;  // --x0, --v0
  bool force = false;       // --force: run a step the step guard refuses
  mutable long rtol_steps = 0;  // what --rtol chose (0: not yet)
  mutable int rtol_degree = -1;  // and the switching PIM's degree it chose (-1: none)
  mutable std::string rtol_method;  // the method they were chosen for

  // The chain these flags describe (the preset, then each given flag).
  NondimensionalChain chain() const;
  bool explicit_structure() const { return !structure_scene.empty(); }
  // The structure: the chain's, or the scene file's explicit one.
  GapStructure structure() const;
  // The point model these flags describe (study/point_model.hpp): the chain, or the explicit
  // structure of --structure-scene; what sweeps, maps and orbits vary. Throws InputError for flags
  // that do not make a valid model.
  analysis::PointModel model() const;
  // The forcing period: the chain's, or the common period of the explicit structure's loads.
  double period() const;
  // A short description for titles and messages.
  std::string description() const;
  // The step the PIM uses: period / steps_per_period, or dt when it divides the period, or the
  // step --rtol asks for (found once, on the first periods of this case from its start, and
  // noted on stderr).
  double step(double period) const;
  // Steps per forcing period: steps_per_period, or the number --rtol chose.
  int grid_steps(double period) const;
  // The switching PIM's force degree: --force-degree, or what --rtol chose, or 2. Throws
  // InputError when --force-degree is given to a method that takes none.
  int switching_degree(double period) const;
  // The method table's settings these flags give (the step only for fixed-grid methods; for the
  // exact solver, its progress on stderr during a long advance: step_guard_report.hpp).
  MethodSettings method_settings(double period) const;
  // The integrator the flags name, with its state at t = 0 that of --x0 and --v0 (rest when they
  // are not given), its step judged by the step guard first (step_guard_report.hpp). Throws
  // InputError naming --x0 or --v0 for a wrong value, or the guard's refusal without --force.
  std::unique_ptr<Integrator> integrator(const GapStructure& structure, double period) const;
};

// The case flags, --x0, --v0 and --force among them.
void add_case_options(CLI::App& command, CaseOptions& options);

// --method's help: one line per row of the method table.
std::string method_help();

// The chain's own flags (--figure, --n, --alpha, --zeta, --gap, --theta, --loads), shared with
// the sweep and map jobs.
void add_chain_options(CLI::App& command, std::string& figure, int& masses,
                       std::vector<double>& alpha, double& zeta, double& gap, double& theta,
                       std::vector<double>& loads);

}  // namespace pwl::app
