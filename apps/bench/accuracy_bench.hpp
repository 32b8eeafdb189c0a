#pragma once
// pwl bench accuracy and pwl bench stability: which method reaches which accuracy at what cost,
// and where each one breaks.
//
//  - accuracy: work-precision diagrams (error against CPU time, log-log). For the figure 4a case
//    the error is the largest difference of the Poincaré points (the state x, x' once per
//    forcing period, from rest over the run) from the exact event-driven solver; for the
//    n = 1000 chain, where the exact solver does not apply (2^1000 modes), from the tightest
//    kink-located rkf78, at every whole second. Curves: the paper's PIM over η, the switching
//    (higher-order) PIM over η, dopri5 and rkf78 over tolerances, plain and kink-located, and
//    the exact solver. One CSV per curve, a PNG per case, a table with the measured order, and a
//    table of the cost to reach each decade of error (pwl's cheapest point against the
//    Runge-Kutta methods' cheapest) with the verdict over 1e-3 to 1e-10 (compare_cost_to_reach).
//  - stability: the contact stiffness ratio α = k2/k1 from 1 to 10^6 against the step (or the
//    tolerance) on the 5-DOF chain of figure 4a: for each method, where it blows up, is refused
//    (a step its own checks reject), misses contacts (sees fewer than 95% of the exact solver's
//    spring switches) or gets the regime wrong (the period of the last Poincaré points), judged
//    over a long run; and the CPU time it needs to reach an error of 1e-6 over the first few
//    periods (pointwise errors of a chaotic motion grow without bound over a long run, so the
//    cost of an accuracy is measured on a window where that growth is mild).
//
// Times are CPU seconds of the process (construction of the integrator included: the PIM's
// exponential is part of its cost), medians of repeated runs.
#include <CLI/CLI.hpp>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pwl/model/gap_structure.hpp"
#include "pwl/integrators/integrator.hpp"

namespace pwl::app {

// Adds the subcommands `accuracy` and `stability` to `pwl bench`.
void add_accuracy_benches(CLI::App& bench);

namespace accuracy_detail {

// A method under test: builds a fresh integrator at rest at t = 0.
using Factory = std::function<std::unique_ptr<Integrator>()>;

// One method, one parameter, run to every sample time.
struct Run {
  bool ok = true;
  std::string failure;             // what went wrong (not ok)
  std::string failure_kind;        // "blow-up" | "refused" | "error"
  double error = 0.0;              // max |state - truth| over the samples
  double median_seconds = 0.0;
  double min_seconds = 0.0;
  int repeats = 0;
  IntegratorStats stats;           // of the first run
  std::vector<Vector> states;      // [x; x'] at the sample times (first run)
};

// Runs `make` to each of `times` in turn, comparing with `truth` (empty: no comparison) and
// timing `repeats` runs (fewer when a run is slow: at most `budget` seconds in all, at least one
// run). Exceptions from the integrator are caught and reported in the Run.
Run measure(const Factory& make, const std::vector<double>& times,
            const std::vector<Vector>& truth, int repeats, double budget);

// Least-squares slope of log y against log x over the pairs with both positive and finite.
// NaN with fewer than two such pairs.
double log_slope(const std::vector<double>& x, const std::vector<double>& y);

// Cost to reach an error, from a work-precision diagram. A curve's cost to reach an error e is
// the CPU time of its cheapest point whose error is at or below e: nothing is interpolated
// between points, so nothing is claimed that was not measured. The cost of a family of curves
// (pwl's methods, or the Runge-Kutta ones) is the least over its curves. It is a step function of
// e that changes only at the points' errors, so two families compared at e = lo and at every
// point's error inside [lo, hi] are compared at every e in [lo, hi], not only at the decades.
struct WorkPoint {
  double seconds = 0.0;
  double error = 0.0;
};
using WorkCurve = std::vector<WorkPoint>;  // the points that ran (a failed point is left out)

struct CheapestPoint {
  int curve = -1;  // -1: no point of the family is at or below the error
  int point = -1;
  double seconds = std::numeric_limits<double>::infinity();
  bool found() const { return curve >= 0; }
};
CheapestPoint cheapest_reaching(const std::vector<WorkCurve>& family, double error);

struct CostComparison {
  bool ours_cheaper_everywhere = false;  // strictly, at every error in [lo, hi]
  // Where theirs / ours is least over [lo, hi] (the first such error from hi down), and that
  // ratio: infinity where theirs reaches no point, 0 where ours reaches none.
  double narrowest_error = std::numeric_limits<double>::quiet_NaN();
  double narrowest_ratio = std::numeric_limits<double>::quiet_NaN();
};
// Throws InputError unless 0 < lo <= hi.
CostComparison compare_cost_to_reach(const std::vector<WorkCurve>& ours,
                                     const std::vector<WorkCurve>& theirs, double lo, double hi);

// The stability bench (accuracy_stability.cpp).
void add_stability_bench(CLI::App& bench);

}  // namespace accuracy_detail
}  // namespace pwl::app
