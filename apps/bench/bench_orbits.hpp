#pragma once
// `pwl bench orbits`: how fast pwl finds periodic orbits and follows them in a parameter
// (analysis/include/pwl/orbits/).
//
//  1. Shooting against brute force. The figure 4a chain (α = 2, ζ = 0.2, Δ̃ = 0, Q = ±1 on
//     alternate masses) with n = 5 masses at θ = 1 (the paper's figure 4a, whose period-1 orbit
//     is unstable: the motion is period-2) and θ = 1.2 (stable), and with n = 100 and 1000 masses
//     at θ = 1.5: from one guess, the state after a short transient from rest, Newton shooting
//     finds the period-1 orbit and its Floquet multipliers (n = 5: the exact solver, dense;
//     n = 100: the switching PIM, dense and matrix-free Newton-Krylov; n = 1000: the banded
//     switching PIM, Newton-Krylov, the leading multipliers by Arnoldi). The competitor
//     integrates the same case from the same guess with the same integrator until two successive
//     Poincaré points differ by less than the shooting tolerance (or a budget of periods runs
//     out), and is then compared with the orbit shooting found: the same orbit, another one, or
//     how far it got (its distance to the orbit at the start, halfway and at the end). It cannot
//     find an unstable orbit at all; the table says so.
//  2. Pseudo-arclength continuation in θ of the period-1 orbit, 200 points: n = 5 from θ = 1.2
//     (exact solver) and n = 100 from θ = 1 (switching PIM), with the bifurcations found.
//
// Every time is the median of --repeats runs (wall clock; the integrator's construction is
// timed apart and left out of both competitors). Prints the tables and writes
// <out>/bench_orbits.csv and <out>/bench_orbits.md.
#include <CLI/CLI.hpp>

namespace pwl::app {

// Adds `pwl bench orbits` to the bench command.
void add_orbits_bench(CLI::App& bench);

}  // namespace pwl::app
