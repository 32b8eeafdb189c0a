#pragma once
// `pwl bench scaling`: time per step and peak memory of the banded PIM on the paper's chain as n
// grows (1000 to 256000 masses), beside the time of the bare banded products of one step, the
// floor of the stepper's own arithmetic. Each size runs in a child process of its own, so that
// its peak resident memory is its own (getrusage of the child). Besides the single-thread CPU
// time, each size is timed by the wall clock on one thread and on all of OpenMP's threads: the
// banded products spread their rows over the threads from 10^5 rows on (banded_matrix.hpp).
#include <string>
#include <vector>

namespace pwl::app {

struct ScalingBenchOptions {
  std::vector<long> sizes{1000, 4000, 16000, 64000, 256000, 1000000};
  double step = 0.02;       // s, the paper's step
  int steps = 1000;         // timed steps per repeat (after 20 steps from rest)
  int repeats = 5;          // at least; small chains repeat more (same work per size)
  double work = 5e7;        // mass-steps each size repeats to at least, up to 200 repeats
  bool share_rows = true;   // false: every operator row stored (shows the memory-bound case)
  std::string out = "out/bench";
  bool quiet = false;
};

struct ScalingRow {
  long masses = 0;
  long band = 0;
  double setup_seconds = 0.0;   // operators and propagator
  double step_us = 0.0;         // median time of one step (x, x' and the LCP), microseconds
  double transition_us = 0.0;   // the bare product T v alone
  double step_per_product = 0.0;  // median over repeats of (step) / (T v), each within a repeat
  double products_us = 0.0;     // T v + Ψ P + Φ P: the products one step makes
  double operator_mb = 0.0;     // memory held by the stepper's operators and vectors
  long stored_rows = 0;         // distinct rows of T stored
  int repeats = 0;
  double peak_rss_mb = 0.0;     // peak resident memory of the process that ran this size
  int threads = 1;              // OpenMP threads of the threaded timing
  double wall_one_us = 0.0;     // wall time per step on one thread
  double wall_threads_us = 0.0; // ... on `threads` threads
};

// Runs the sizes (each in a child process running `self_exe bench scaling --single n ...`),
// prints the table and writes <out>/bench_scaling.csv.
std::vector<ScalingRow> run_scaling_bench(const ScalingBenchOptions& options,
                                          const std::string& self_exe);

// One size in this process: prints a single line the parent reads.
void run_scaling_single(long masses, const ScalingBenchOptions& options);

std::string format_scaling_table(const std::vector<ScalingRow>& rows,
                                 const ScalingBenchOptions& options);

}  // namespace pwl::app
