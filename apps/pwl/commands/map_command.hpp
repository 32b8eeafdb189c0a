#pragma once
// `pwl map` as a library: its flags and the regime map they describe, so that an embedding (the
// Python module) parses the very same flags with the same checks and messages and runs the map
// in memory:
//
//     MapFlags flags;
//     CLI::App app;
//     add_map_flags(app, flags);
//     app.parse("--figure 5 --x theta --x-points 10 --y alpha --y-points 5", false);
//     const analysis::RegimeMapOptions options = map_options(flags);
//     const std::map<long, analysis::PointResult> cells = compute_study(study_of(options));
//     // cell id i + N1 j at (options.first.value(i), options.second.value(j))
#include <CLI/CLI.hpp>
#include <string>

#include "commands/case_options.hpp"
#include "commands/study_runner.hpp"
#include "pwl/study/regime_map.hpp"

namespace pwl::app {

// Every flag of `pwl map`.
struct MapFlags {
  ModelFlags model;         // the base model: --figure, chain flags, --structure-scene
  PointFlags point;         // each cell: --transient, --periods, --method, ...
  RunFlags run;             // --out, --resume, --quiet, --no-plot, --threads
  SectionFlags section;     // --section (strobe only, see map_options), --phase
  InitialStateFlags start;  // --x0, --v0
  std::string x = "theta";
  std::string x_range = "0.5:3";
  int x_points = 20;
  std::string y = "alpha";
  std::string y_range = "1:15";
  int y_points = 15;
  std::string mode = "independent";
  std::string curves;  // a pwl continue --curves folder whose curves the figure draws
  MapFlags() { run.out = "map"; }
};

// Registers exactly the flags of `pwl map` on `command`, bound to `flags`.
void add_map_flags(CLI::App& command, MapFlags& flags);

// The map the flags describe. Throws InputError naming the flag and the value for anything that
// does not make a valid map. A hyperplane --section is refused: a map keeps only each cell's
// regime, λ1 and K, which are classified on the stroboscopic map (at --phase) whatever a section
// records, so a hyperplane would change nothing it keeps.
analysis::RegimeMapOptions map_options(const MapFlags& flags);

}  // namespace pwl::app
