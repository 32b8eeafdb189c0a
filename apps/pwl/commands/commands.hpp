#pragma once
// Every subcommand of the pwl program adds itself to the CLI11 app through one of these.
// Exit codes: 0 ok, 1 a run that failed (LCP, divergence, I/O), 2 bad input.
#include <CLI/CLI.hpp>

namespace pwl::app {

void add_simulate_command(CLI::App& app);
void add_analyze_command(CLI::App& app);
void add_reproduce_command(CLI::App& app);
void add_bench_command(CLI::App& app);
void add_sweep_command(CLI::App& app);
void add_map_command(CLI::App& app);
void add_basin_command(CLI::App& app);
void add_orbit_command(CLI::App& app);
void add_continue_command(CLI::App& app);

}  // namespace pwl::app
