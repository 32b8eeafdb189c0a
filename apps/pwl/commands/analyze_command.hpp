#pragma once
// `pwl analyze` as a library: its flags, and the evaluation of one case into its verdict with the
// evidence and the recorded section points, so that an embedding (the Python module) parses the
// same flags with the same checks and messages and gets the numbers in memory. The command line
// runs the same analyze_case and then writes its files and prints.
//
//     AnalyzeOptions options;
//     CLI::App app;
//     add_analyze_flags(app, options);
//     app.parse("--figure 5 --periods 1000 --transient 500", false);
//     const AnalyzeResult a = analyze_case(options);
//     // a.result.regime, a.result.lambda1, a.classification->period_search, a.section_times, ...
//
// The motion is evaluated by the study pipeline (evaluate_point, pwl/study/sweep_point.hpp), the
// same that classifies every point of `pwl sweep` and `pwl map`: with the same settings a
// one-point sweep gives the same regime, period, λ1 and K.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands/case_options.hpp"
#include "commands/ladder_flags.hpp"
#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::app {

// Every flag of `pwl analyze`.
struct AnalyzeOptions {
  CaseOptions run;       // the case, its integration, --periods, --x0, --v0
  SectionFlags section;  // --section, --phase
  int transient = 500;   // periods discarded
  int mass = 0;          // 1-based mass for the figure and the 0-1 test; 0: the last one
  // How λ1 is estimated; empty: one tangent vector when the method has an exact tangent map,
  // else two nearby trajectories.
  std::string lyapunov;
  LadderFlags ladder;    // the evidence ladder (on unless --quick), as sweep and map
  std::string out = "out";
};

// Registers exactly the flags of `pwl analyze` on `command`, bound to `options`.
void add_analyze_flags(CLI::App& command, AnalyzeOptions& options);

// The verdict on one case and its evidence.
struct AnalyzeResult {
  // The indicators: regime, period, λ1 (per forcing period) and its error, K; the final state.
  analysis::PointResult result;
  // The classifier's evidence (the period search, the rule that decided); none when the motion
  // blew up ("unbounded") or a contact problem had no solution ("failed").
  std::optional<analysis::Classification> classification;
  analysis::PointSettings settings;  // as evaluated: method, λ1 estimate, section, periods
  std::string integrator;            // Integrator::name()
  Index dofs = 0;
  int mass = 0;         // the mass the figure draws and the 0-1 test reads (1-based)
  double period = 0.0;  // T
  // Every recorded point of the section (the stroboscopic points of the recorded periods, or the
  // hyperplane's crossings in them): its time, its period (1-based from t = 0) and its full
  // state [x; v], 2n values per point, row-major: what poincare.csv holds.
  std::vector<double> section_times;
  std::vector<int> section_periods;
  std::vector<double> section_states;
  // What the evaluation cost, in wall seconds: each stage of the ladder in order (record, newton,
  // observation, confirmation, attractors) and the whole. Printed, never part of a result file.
  std::vector<std::pair<std::string, double>> stage_seconds;
  double seconds = 0.0;
};

// Checks the flags (InputError naming the flag: --mass out of range, fewer than 100 recorded
// periods, a --lyapunov the method cannot do, a bad --section, --phase, --x0 or --v0), then
// integrates and classifies the case. `also`, when given, sees the evaluation as it runs (every
// step of the periods it asks for, every section point, the classification): how the command line
// writes its trajectory and Poincaré files without a second integration.
AnalyzeResult analyze_case(const AnalyzeOptions& options, analysis::PointObserver* also = nullptr);

// The command line's job: analyze_case, then trajectory.csv (the last 20 periods of --mass),
// poincare.csv, classification.csv, the two-panel figure and the printout in --out.
void analyze(const AnalyzeOptions& options);

}  // namespace pwl::app
