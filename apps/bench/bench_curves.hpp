#pragma once
// `pwl bench curves`: what the bifurcation curves in two parameters (pwl continue --curves,
// analysis/include/pwl/orbits/bifurcation_curves.hpp) cost, against the two ways of getting the
// same picture without them.
//
//  1. Points per second of curve following against one-parameter continuation: figure 5's chain
//     (α = 5, ζ = 0.2, Δ̃ = 0), its period-1 branch in θ over [0.5, 3], then the curves of every
//     bifurcation on it in (θ, α) over α in [1, 15] (apps/scenes/theta_alpha_curves.toml): the
//     branch's points and time and the curves' points and time, each from `pwl continue`'s own
//     counts, in one run.
//  2. The whole (θ, α) curve set against the brute-force regime map of the same range with the
//     shipped map's settings (apps/scenes/theta_alpha_map.toml: 40 x 29 cells, 500 + 500 periods,
//     every help to the verdict, both cores): the wall time of each, run one after the other as
//     `pwl run SCENE`. The map's boundaries are the cells' pixels; the curves' are exact.
//
// Every time is the median of --repeats runs. --quick runs smaller cases (α in [4.5, 5.5], a
// 10 x 8 map of shorter records) as a smoke test. Prints the tables and writes
// <out>/bench_curves.csv and <out>/bench_curves.md.
#include <CLI/CLI.hpp>

namespace pwl::app {

// Adds `pwl bench curves` to the bench command.
void add_curves_bench(CLI::App& bench);

}  // namespace pwl::app
