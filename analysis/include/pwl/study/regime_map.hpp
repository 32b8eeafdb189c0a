#pragma once
// A two-parameter regime map of a point model (the paper's chain or an explicit structure, see
// point_model.hpp): a grid of N1 x N2 values of two of its parameters (for example θ x α, or a
// spring's gap x a load's amplitude), each cell classified (period-k, quasi-periodic, chaotic,
// unbounded) with its indicators (λ1, K, ...).
//
// Cells are independent (every one starts from the same initial state) or, in a continuation,
// each row (one value of the second parameter) is swept upward in the first parameter from the
// final state of the cell before. Rows are then the parallel tasks.
//
// Cell (i, j) has value from1 + (to1 - from1) i / (N1 - 1) of the first parameter and the same of
// the second with j; its id is i + N1 j. Only summaries are kept, never Poincaré points.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/parameter_sweep.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

struct MapAxis {
  SweepParameter parameter = SweepParameter::theta;
  double from = 0.5;
  double to = 3.0;
  int points = 20;  // >= 1; from < to when > 1
  double value(int index) const;
};

struct RegimeMapOptions {
  // The base case: the paper's chain, or, when `structure` is set, that explicit structure. The
  // two parameters override its values.
  NondimensionalChain chain;
  std::optional<ExplicitStructure> structure;
  MapAxis first;              // horizontal axis (x of the figure)
  MapAxis second;             // vertical axis (y)
  SweepMode mode = SweepMode::independent;
  // Components are ignored: a map keeps no Poincaré points. Its section must be the strobe (at
  // any phase, the points each cell is classified on): a hyperplane would change nothing a map
  // keeps, and is_valid refuses it.
  PointSettings point;
  Vector initial_state;       // empty: at rest

  PointModel model() const;
  // Ceres-style check: false with a message naming the field and the value.
  bool is_valid(std::string* why) const;
  std::vector<GridTask> tasks() const;
  PointCase case_of(long id) const;
  // The chain of cell id (a map of the chain only; InputError for an explicit structure).
  NondimensionalChain chain_of(long id) const;
  std::string describe() const;  // as SweepOptions::describe
  Vector start_state() const;
  long cells() const { return static_cast<long>(first.points) * second.points; }
};

// Writes <folder>/map.csv (i,j,<first>,<second>, then every indicator of indicators.hpp:
// regime,code,period,lambda1,lambda1_error,K,...), sorted by j then i. Throws pwl::Error when it cannot.
void write_map_file(const RegimeMapOptions& options, const std::map<long, PointResult>& records,
                    const std::string& folder);

}  // namespace pwl::analysis
