#pragma once
// Where the program finds what ships with it (the gnuplot scripts, the scenes) and where the jobs
// that redraw the project's own figures write them.
//
// An installed pwl (`cmake --install`) looks beside its own executable: <prefix>/bin/pwl reads
// <prefix>/share/pwl/scripts and <prefix>/share/pwl/scenes. A pwl run from its build tree reads the
// source tree it was built from. $PWL_PLOTS_DIR (a plots folder: scripts/ inside it) and
// $PWL_SCENES_DIR override both.
#include <string>

namespace pwl::app {

// The folder of the shipped gnuplot scripts (plots/scripts of the source tree, or
// <prefix>/share/pwl/scripts).
std::string scripts_directory();

// The folder of the shipped scenes (apps/scenes of the source tree, or <prefix>/share/pwl/scenes).
std::string scenes_directory();

// The plots folder that `pwl reproduce` and the chart benchmarks write into by default: figures in
// <plots>/figures, the data behind them in <plots>/data, the report in <plots>/report.md. The
// source tree's plots/ for a build-tree pwl, ./plots for an installed one.
std::string plots_directory();

// Where the figures of a plots folder go.
std::string figures_directory(const std::string& plots);

}  // namespace pwl::app
