#pragma once
// The paper's 5-DOF figures (SPEC.md §5): the PIM at η = T/200 against the kink-located dopri5
// reference at tolerance 1e-10, over [0, 1000T] from rest, the first 500 periods discarded.
#include <string>
#include <utility>
#include <vector>

namespace pwl::app {

struct FiveDofFigureResult {
  std::string figure;
  int distinct_points = 0;  // distinct stroboscopic points of the PIM over the kept periods
  int reference_distinct_points = 0;
  double largest_difference = 0.0;  // max |PIM - reference| over x and x' of every mass, every step
  double largest_poincare_difference = 0.0;  // the same over the kept Poincaré points
  double attractor_size = 0.0;               // diameter of the PIM's Poincaré cloud in (x5, x5')
  double pim_seconds = 0.0;
  double reference_seconds = 0.0;
};

// Computes the figure's data (mass 5's trajectory and Poincaré points from both integrators),
// writes it under plots_dir/data and draws plots_dir/fig<name>.png and .svg. quick: 300 periods
// with 200 discarded, for smoke tests.
FiveDofFigureResult reproduce_five_dof_figure(const std::string& figure,
                                              const std::string& plots_dir, bool quick);

// Distinct points of a cloud: greedy clustering with radius tolerance * (cloud diameter), with
// the diameter floored at 1 so that a fixed point counts as one.
int count_distinct_points(const std::vector<std::pair<double, double>>& points, double tolerance);

}  // namespace pwl::app
