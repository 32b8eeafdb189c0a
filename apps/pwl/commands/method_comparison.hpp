#pragma once
// `pwl simulate --compare-with METHOD`: the same case integrated by a second method, both landing
// on the same time grid (the first method's steps), so that they compare point by point. This is
// how the paper's figures 4a and 4b are checked: the PIM against a kink-located Runge-Kutta
// reference at a tight tolerance.
#include <string>
#include <utility>
#include <vector>

#include "commands/case_options.hpp"

namespace pwl::app {

// What `pwl simulate` writes.
struct RecordingOptions {
  std::vector<int> record;     // masses (1-based) whose trajectory is written
  int trajectory_periods = 0;  // the trajectory of only the last ones (0: every kept period)
  std::string title;           // of the figure ("": one made from the method and mass)
  std::string out = "out";
  bool quiet = false;
};

struct ComparisonOptions {
  std::string method;  // "": no comparison; else any --method
  double tolerance = 1e-10;
  bool locate_kinks = false;
};

struct ComparisonResult {
  double largest_difference = 0.0;           // max |a - b| over x and x' of every mass, every step
  double largest_poincare_difference = 0.0;  // the same over the written Poincaré points
  int distinct_points = 0;                   // of the recorded mass's Poincaré points (x, x')
  int reference_distinct_points = 0;
  double cloud_size = 0.0;  // diameter of the first method's Poincaré cloud in (x, x')
};

// Integrates `run` and the same case by `with`, writes poincare.csv, trajectory.csv (the recorded
// masses at every grid point of the drawn periods) and the same with the prefix "reference_" into
// `out`, draws `out`/comparison.png and .svg for the first recorded mass, and prints a summary.
ComparisonResult simulate_with_comparison(const CaseOptions& run, const ComparisonOptions& with,
                                          const RecordingOptions& output);

// The diameter of a cloud of (x, x') points: the diagonal of its bounding box.
double cloud_diameter(const std::vector<std::pair<double, double>>& points);

// Distinct points of a cloud: greedy clustering with radius tolerance * (cloud diameter), with
// the diameter floored at 1 so that a fixed point counts as one.
int count_distinct_points(const std::vector<std::pair<double, double>>& points, double tolerance);

}  // namespace pwl::app
