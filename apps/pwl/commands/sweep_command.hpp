#pragma once
// The sweep job as a function, for the commands that run a sweep of their own (pwl continue
// --over-sweep draws the brute-force bifurcation diagram of its range this way).
#include <string>

#include "commands/study_runner.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::app {

// Runs the sweep `options` into run.out as `pwl sweep` does (config.txt, journals, poincare.csv,
// classification.csv, bifurcation_points.csv and the bifurcation diagram). With `branches` (a
// folder of `pwl continue`), the diagram also draws that folder's branch_section.csv: the orbit
// branches' Poincaré points over the brute-force ones. Throws InputError when that file is missing
// or has no column of the sweep's first recorded component.
void run_sweep(const analysis::SweepOptions& options, const RunFlags& run,
               const std::string& branches = "");

}  // namespace pwl::app
