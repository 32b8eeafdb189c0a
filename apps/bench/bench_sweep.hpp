#pragma once
// pwl bench sweep: how fast a parameter sweep of the paper's 5-DOF chain runs.
//
//  1. Throughput of the fixed-size 5-DOF PIM stepper on one core, in steps per second.
//  2. Parallel efficiency of a sweep on all the machine's cores: the wall time of the same points
//     on one thread over (threads x the wall time on all of them).
//  3. The wall time of a θ sweep (by default the 1000-point sweep θ in [0.5, 3], α = 5, ζ = 0.2,
//     Δ̃ = 0, 500 transient + 500 recorded periods, η = T/200, with λ1 and K for every point), and
//     the same points driven by the kink-located dopri5 at the largest tolerance whose Poincaré
//     points are as accurate as the PIM's (calibrated in the same run against dopri5 at 1e-12).
//     dopri5 is timed on every k-th point of the sweep and scaled to the whole sweep; the ratio
//     compares the same points on both. dopri5 computes no λ1 (it has no tangent map), so it does
//     less work per point than the PIM: the ratio is conservative.
//
// Times are medians of repeated runs. Prints a table and writes bench_sweep.csv.
#include <CLI/CLI.hpp>

namespace pwl::app {

// Adds `pwl bench sweep` to the bench command.
void add_sweep_bench(CLI::App& bench);

}  // namespace pwl::app
