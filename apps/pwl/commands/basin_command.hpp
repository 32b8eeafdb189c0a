#pragma once
// `pwl basin` as a library: its flags and the basin map they describe (see
// analysis/include/pwl/study/basin_map.hpp), so that an embedding parses the very same flags with
// the same checks and messages:
//
//     BasinFlags flags;
//     CLI::App app;
//     add_basin_flags(app, flags);
//     app.parse("--n 1 --alpha 3 --zeta 0.1 --gap 1.5 --loads 0.5 --theta 1.2", false);
//     const analysis::BasinMapOptions options = basin_options(flags);
//     const auto cells = compute_study(basin_study(options));
//     const analysis::BasinMap basins = analysis::match_basins(options, cells);
#include <CLI/CLI.hpp>
#include <string>

#include "commands/case_options.hpp"
#include "commands/study_runner.hpp"
#include "pwl/study/basin_map.hpp"

namespace pwl::app {

// Every flag of `pwl basin`.
struct BasinFlags {
  ModelFlags model;         // the case: --figure, chain flags, --structure-scene
  PointFlags point;         // each cell: --transient, --periods, --method, ...
  RunFlags run;             // --out, --resume, --quiet, --no-plot, --threads
  InitialStateFlags start;  // --x0, --v0: the components the axes do not set
  std::string x = "x1";
  std::string x_range = "-2:2";
  int x_points = 41;
  std::string y = "v1";
  std::string y_range = "-2:2";
  int y_points = 41;
  int kept_points = 64;
  double periodic_tolerance = 1e-3;
  double cloud_factor = 3.0;
  BasinFlags() {
    run.out = "basin";
    point.periods = 200;
  }
};

void add_basin_flags(CLI::App& command, BasinFlags& flags);

// The basin map the flags describe. Throws InputError naming the flag and the value for anything
// that does not make a valid basin map.
analysis::BasinMapOptions basin_options(const BasinFlags& flags);

// The study of a basin map: its cells as tasks, each with its own initial state.
Study basin_study(const analysis::BasinMapOptions& options);

}  // namespace pwl::app
