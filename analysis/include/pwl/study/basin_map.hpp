#pragma once
// A basin map: one case (the paper's chain or an explicit structure, at fixed parameters) started
// from every initial state of a grid over two state components, each motion classified and matched
// to the attractor it ends on (analysis/attractor_catalogue.hpp), so that coexisting attractors
// with the same name (two period-1 orbits) are told apart and their basins of attraction drawn.
//
// Cell (i, j) starts from the base state with component first.component set to
// first.value(i) and second.component to second.value(j), at t = 0 (the loads at phase 0); its id
// is i + N1 j, as a regime map's. Every cell is its own task, so cells run in parallel, journal and
// resume like the points of any study (study_runner). Each keeps its indicators and only the last
// point.kept_points stroboscopic points of the full state, which is what the matching compares.
//
// The matching is done once every cell is done, in id order, so the attractors and their numbers
// do not depend on the number of threads or processes, or on a resume.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pwl/analysis/attractor_catalogue.hpp"
#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/point_model.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

// One axis of initial states: a state component (0..n-1 are x1..xn, n..2n-1 are v1..vn) and its
// values from..to at `points` evenly spaced values.
struct StateAxis {
  int component = 0;
  double from = -1.0;
  double to = 1.0;
  int points = 20;  // >= 1; from < to when > 1
  double value(int index) const;
};

struct BasinMapOptions {
  // The case: the paper's chain, or, when `structure` is set, that explicit structure.
  NondimensionalChain chain;
  std::optional<ExplicitStructure> structure;
  StateAxis first;   // horizontal axis of the figure
  StateAxis second;  // vertical axis
  Vector base_state;  // the other components of every initial state; empty: zero (rest)
  // Each cell's integration and classification. Its components are set to the whole state and its
  // section must be the strobe at phase 0 (is_valid refuses others): the attractors are matched on
  // stroboscopic points, and every cell starts at the loads' phase 0. kept_points (>= 2 and at
  // least the longest period to be told apart) is how much of each tail is matched.
  PointSettings point;
  AttractorMatchOptions matching;

  BasinMapOptions();  // point.kept_points = 64
  PointModel model() const;
  // Ceres-style check: false with a message naming the field and the value.
  bool is_valid(std::string* why) const;
  std::vector<GridTask> tasks() const;  // one a cell, each with its initial state
  PointCase case_of(long id) const;     // the same case for every cell
  Vector initial_state(long id) const;
  PointSettings settings() const;       // point, with every component recorded
  std::string describe() const;         // every setting, for config.txt
  long cells() const { return static_cast<long>(first.points) * second.points; }
};

struct BasinMap {
  // The attractor of every cell, by id (0: the motion failed), and the attractors found.
  std::map<long, int> attractor_of;
  std::vector<Attractor> attractors;
};

// Matches every record (by id, in id order) to an attractor. Throws InputError for records that
// do not fit the options (a tail shorter than its period, of another width).
BasinMap match_basins(const BasinMapOptions& options, const std::map<long, PointResult>& records);

// Writes <folder>/basin.csv (i,j,<first component>,<second component>,attractor, then every
// indicator of indicators.hpp) sorted by j then i, and <folder>/attractors.csv (attractor,regime,
// period,cells,fraction,first_i,first_j, then the last point of its representative tail,
// x1..xn,v1..vn; empty for the attractor at infinity), and <folder>/attractor_points.csv
// (attractor,x1..xn,v1..vn: the k points of a period-k attractor, the whole representative tail of
// a non-periodic one). Throws pwl::Error when a file cannot be written.
void write_basin_files(const BasinMapOptions& options, const std::map<long, PointResult>& records,
                       const BasinMap& basins, const std::string& folder);

}  // namespace pwl::analysis
