#pragma once
// `pwl sweep` as a library: its flags, the sweep options they describe, and the job that runs a
// sweep into a folder. An embedding (the Python module) parses the very same flags with the same
// checks and messages and runs the study in memory:
//
//     SweepFlags flags;
//     CLI::App app;
//     add_sweep_flags(app, flags);
//     app.parse("--figure 5 --parameter theta --range 0.5:3 --points 50", false);
//     const analysis::SweepOptions options = sweep_options(flags);
//     const std::map<long, analysis::PointResult> points = compute_study(study_of(options));
//     // point id i (upward) / N + i (downward) at options.value(i): regime, λ1, K, Poincaré
//     // points (options.point.components), their times for a hyperplane section
//
// Commands that run a sweep of their own use run_sweep (pwl continue --over-sweep draws the
// brute-force bifurcation diagram of its range this way).
#include <CLI/CLI.hpp>
#include <string>

#include "commands/case_options.hpp"
#include "commands/study_runner.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::app {

// Every flag of `pwl sweep`.
struct SweepFlags {
  ModelFlags model;         // the base model: --figure, chain flags, --structure-scene
  PointFlags point;         // each point: --transient, --periods, --record, --method, ...
  RunFlags run;             // --out, --resume, --quiet, --no-plot, --threads
  SectionFlags section;     // --section, --phase
  InitialStateFlags start;  // --x0, --v0
  std::string parameter = "theta";
  std::string range = "0.5:3";
  int points = 100;
  std::string mode = "independent";
  std::string directions = "both";
  std::string branches;  // a pwl continue folder whose branch_section.csv the figure draws
};

// Registers exactly the flags of `pwl sweep` on `command`, bound to `flags`.
void add_sweep_flags(CLI::App& command, SweepFlags& flags);

// The sweep the flags describe. Throws InputError naming the flag and the value for anything
// that does not make a valid sweep (a parameter the model lacks, a range, a component, a section,
// an initial state).
analysis::SweepOptions sweep_options(const SweepFlags& flags);

// Runs the sweep `options` into run.out as `pwl sweep` does (config.txt, journals, poincare.csv,
// classification.csv, bifurcation_points.csv and the bifurcation diagram). With `branches` (a
// folder of `pwl continue`), the diagram also draws that folder's branch_section.csv: the orbit
// branches' Poincaré points over the brute-force ones. Throws InputError when that file is missing
// or has no column of the sweep's first recorded component.
void run_sweep(const analysis::SweepOptions& options, const RunFlags& run,
               const std::string& branches = "");

}  // namespace pwl::app
