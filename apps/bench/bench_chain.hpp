#pragma once
// `pwl bench chain`: the paper's section 4.2 problem (He, Gao & Zhong 2018, Table 1; SPEC.md §5)
// measured side by side: n = 1000 masses, t in [0, 200] s from rest, every pwl configuration that
// competes there (keys starting with "pim": the banded PIM at the paper's step and at the step its
// rule picks, the banded switching PIM at a few steps, the dense PIM), and dopri5 at 1e-5 and
// 1e-10, plain (like the paper's ode45) and kink-located. For each: the median wall and CPU time
// of several runs and the largest error of x1 and x1' against a kink-located reference at 1e-12;
// then, for each dopri5 row, the fastest pwl row at or below both its errors and how much faster.
//
// And the floor each banded row stands on: every banded PIM step (smooth steps; a switching step
// redoes its motion on the Taylor series instead) multiplies the state by T = exp(Hη) once, so
// steps x (one bare product T v) is the least a run at that step can cost, whatever else the
// step does. Measured for each banded row (its wall time over that floor is its cost in T v
// products per step) and for a range of steps (the floor's speed-up over each dopri5 row is the
// most any method of this family could reach at that step, before asking for its accuracy).
#include <optional>
#include <string>
#include <vector>

#include "bench/bench_reference.hpp"
#include "pwl/integrators/banded_step_rule.hpp"

namespace pwl::app {

struct ChainBenchOptions {
  int masses = 1000;
  double t_end = 200.0;        // s
  int runs = 5;                // timed runs per method (the median is reported)
  int dense_runs = 1;          // the dense PIM takes minutes per run at n = 1000
  double paper_step = 0.02;    // s, the step the paper reports
  double wished_step = 0.32;   // s, η1 given to the step rule
  std::vector<int> rule_bands{5, 8};  // q given to the step rule (the paper: 5, its 11-dof piece)
  // Steps of the banded switching PIM (switches located), one row each per degree. At 0.8 s
  // (η ω_max = 1.8) every step of the paper's chain has a spring near its kink and is redone on
  // the Taylor series to rounding, so those rows are exact whatever the degree.
  std::vector<double> switching_steps{0.8, 0.4, 0.2, 0.1, 0.08, 0.04, 0.02};
  // Force degrees d of those rows (order d + 3), one set of rows each.
  std::vector<int> switching_degrees{2, 4, 6};
  // Accuracy requests for the banded switching PIM (accuracy_step.hpp), one row each: the step
  // (dividing t_end) found on the first two periods of the loads (4π s) and the run at it, both
  // timed.
  std::vector<double> accuracy_requests{1e-6, 1e-9};
  // Steps of the floor table (one bare T v each, timed; the switching PIM refuses steps with
  // η ω_max > 2, 0.89 s on the paper's chain). Those longer than t_end are left out.
  std::vector<double> floor_steps{0.02, 0.05, 0.1, 0.2, 0.4, 0.5, 0.8};
  bool without_dense = false;         // leave the dense PIM out (minutes per run at n = 1000)
  double reference_tolerance = 1e-12;
  double reference_grid = 0.005;      // s, spacing of the reference's recorded points
  bool reference_check = true;        // a second reference (dopri5) to bound the first's error
  // Which methods to run (keys of chain_bench_methods()); empty: all.
  std::vector<std::string> methods;
  std::string out = "out/bench";      // CSV files and the cached reference
  bool figures = false;               // also draw the paper's figures 7-9 (chain_figures.hpp)
  bool quiet = false;
};

// Keys of the methods, in table order. A key may name several rows (pim-rule: one per band,
// pim-switching: one per step); their parameters tell them apart.
std::vector<std::string> chain_bench_methods();

struct ChainMethodResult {
  std::string key;
  std::string label;       // e.g. "banded PIM (paper step)"
  std::string parameters;  // e.g. "η = 0.02 s, q = 5"
  int runs = 0;
  bool base = false;        // the row the others are compared with (banded PIM, paper step)
  double wall = 0.0;        // median wall time of a run (set-up + integration), s
  double cpu = 0.0;         // median CPU time (all threads), s
  double setup = 0.0;       // median wall time of the set-up alone, s
  long steps = 0;
  long work = 0;            // right-hand-side evaluations (Runge-Kutta) or LCP pivots (PIM)
  double error_x = 0.0;     // largest |x1 - reference| over the run, m
  double error_v = 0.0;     // largest |x1' - reference|, m/s
  TrackRecord record;       // x1, x1' at every step of the first run
  // Banded fixed-step rows: the floor at the row's step and band (steps x one bare T v), s;
  // 0 for the other rows.
  double floor = 0.0;
};

// One bare product with the banded T = exp(Hη) at a step, and the least a run of t_end costs.
struct ChainFloorRow {
  double step = 0.0;               // η, s
  Index chosen_band = 0;           // q the construction chose (or the row forced)
  Index width = 0;                 // stored diagonals of T on the interleaved state
  double transition_product = 0.0; // median wall time of one T v, s
  long steps = 0;                  // steps of the run (t_end / η, rounded up)
  double floor() const { return static_cast<double>(steps) * transition_product; }
};

struct ChainBenchResult {
  ChainBenchOptions options;
  std::vector<ChainMethodResult> methods;
  ReferenceTrack reference;
  std::string reference_label;
  double reference_seconds = 0.0;
  std::optional<std::pair<double, double>> reference_check;  // |rkf78 - dopri5| in x1, x1'
  std::vector<BandedStepChoice> rule_choices;                 // per rule band
  std::vector<ChainFloorRow> floors;  // one per options.floor_steps (the rows': ChainMethodResult)
};

// Runs the benchmark (printing progress unless quiet) and writes <out>/bench_chain.csv and
// <out>/bench_chain_floor.csv.
ChainBenchResult run_chain_bench(const ChainBenchOptions& options);

// The table with the paper's beside it, and the targets met or missed.
std::string format_chain_table(const ChainBenchResult& result);

}  // namespace pwl::app
