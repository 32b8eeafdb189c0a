#pragma once
// The evidence ladder's flags, shared by analyze, sweep, map and basin (and their scene keys and
// Python keywords, which are these flags): the ladder is on by default, `--quick` gives the plain
// record, and each step's flag sets that step whatever the default
// (analysis/README.md, "How a verdict is reached").
#include <CLI/CLI.hpp>
#include <string>

#include "pwl/study/sweep_point.hpp"

namespace pwl::app {

struct LadderFlags {
  bool quick = false;
  int refine_orbits = -1;     // longest candidate period of orbit refinement; 0: none; -1: default
  int evidence_periods = -1;  // adaptive evidence budget; 0: none; -1: default
  std::string confirm;        // none, uncertain, aperiodic, regular, all; empty: default
  // Sets the ladder's fields of `settings` (evidence, refinement, period check, confirmation).
  void apply(analysis::PointSettings& settings) const;
};
void add_ladder_flags(CLI::App& command, LadderFlags& flags);

}  // namespace pwl::app
