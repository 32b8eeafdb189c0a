#pragma once
// `pwl simulate` as a library: its flags, and the integration of one case into a sink, so that an
// embedding (the Python module) parses the very same flags with the same checks and messages and
// gets the motion as arrays, through the one integration loop the command line uses.
//
//     SimulateOptions options;
//     CLI::App app;
//     add_simulate_flags(app, options);
//     app.parse("--figure 4a --periods 20 --record 5", false);
//     SimulationArrays arrays;
//     const SimulationSummary summary = simulate_case(options, arrays);
//
// The command line's sink streams the same rows into poincare.csv and trajectory.csv.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "commands/case_options.hpp"
#include "commands/method_comparison.hpp"
#include "pwl/analysis/poincare_section.hpp"
#include "pwl/integrators/integrator.hpp"

namespace pwl::app {

// Every flag of `pwl simulate`.
struct SimulateOptions {
  CaseOptions run;            // the case, its integration, --periods, --skip-periods, --x0, --v0
  SectionFlags section;       // --section, --phase
  RecordingOptions output;    // --record, --trajectory-periods, --title, --out, --quiet
  ComparisonOptions compare;  // --compare-with, --compare-tol, --compare-locate-kinks
};

// Registers exactly the flags of `pwl simulate` on `command`, bound to `options`.
void add_simulate_flags(CLI::App& command, SimulateOptions& options);

// What simulate_case tells as it integrates. Every hook is optional.
class SimulationSink {
 public:
  virtual ~SimulationSink() = default;
  // Once, after the flags are checked, with the integrator at the initial state (t = 0) and the
  // structure it integrates, before any point or row.
  virtual void started(const Integrator& /*integrator*/, const GapStructure& /*structure*/) {}
  // Every point of the section in the kept periods, in the order of time: its time and full
  // state. A stroboscopic section's points are at t = (k + phase) T within (skip·T, periods·T],
  // and the initial state too when nothing is skipped and the phase is 0 (as poincare.csv has
  // always had it); a hyperplane's are its crossings in (skip·T, periods·T]. x and v are valid
  // only during the call.
  virtual void section_point(double /*t*/, const Vector& /*x*/, const Vector& /*v*/) {}
  // Every step of the drawn periods (--trajectory-periods, else every kept one) when masses are
  // recorded: t, then x of each recorded mass, then v of each (trajectory.csv's row).
  virtual void trajectory_row(const std::vector<double>& /*row*/) {}
};

struct SimulationSummary {
  std::string integrator;  // Integrator::name()
  Method method = Method::pim;
  IntegratorStats stats;
  Index dofs = 0;
  double period = 0.0;                // T
  analysis::PoincareSection section;  // what was recorded
};

// A sink that keeps everything in memory, for embeddings: the section points (their times, and
// their states row by row, 2n values each) and the trajectory rows (1 + 2 r values each, r the
// recorded masses).
class SimulationArrays : public SimulationSink {
 public:
  void started(const Integrator& integrator, const GapStructure& structure) override;
  void section_point(double t, const Vector& x, const Vector& v) override;
  void trajectory_row(const std::vector<double>& row) override;

  Index dofs = 0;
  std::vector<double> section_times;
  std::vector<double> section_states;  // row-major: point i is [2n i, 2n (i + 1))
  std::size_t trajectory_columns = 0;  // 1 + 2 r
  std::vector<double> trajectory;      // row-major
};

// Integrates the case of `options` from its initial state over --periods forcing periods and
// tells `sink` every kept section point and every drawn trajectory row: the loop `pwl simulate`
// runs. Throws InputError naming the flag for invalid flags (--record out of range,
// --skip-periods >= --periods, a bad --section, --phase, --x0 or --v0); --compare-with is the
// command line's own comparison (simulate_with_comparison) and is refused here.
SimulationSummary simulate_case(const SimulateOptions& options, SimulationSink& sink);

// The command line's job: simulate_case into poincare.csv and trajectory.csv in --out, the
// printout and the phase portrait (or, with --compare-with, simulate_with_comparison).
void simulate(const SimulateOptions& options);

}  // namespace pwl::app
