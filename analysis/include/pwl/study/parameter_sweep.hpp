#pragma once
// A one-parameter sweep of the nondimensional chain: the data of a bifurcation diagram.
//
// N values of one parameter (θ, α, ζ, Δ̃ or the load scale), evenly spaced over [from, to]. In an
// independent sweep every point starts from the same initial state; in a continuation the sweep
// runs upward (from `from` to `to`) and downward, each point starting from the final state of the
// one before, so that the two directions follow different attractors where they coexist
// (hysteresis). Each point keeps its Poincaré points of the chosen components and one
// classification (sweep_point.hpp).
//
// Point ids: index i (0-based, value from + (to - from) i / (N - 1)) upward is id i, downward is
// id N + i. Files are written sorted by direction (up first) and index, whatever order the
// points were computed in.
#include <map>
#include <string>
#include <vector>

#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

enum class SweepMode { independent, continuation };

struct SweepOptions {
  NondimensionalChain chain;  // the base case; the swept parameter overrides its value
  SweepParameter parameter = SweepParameter::theta;
  double from = 0.5;
  double to = 3.0;
  int points = 100;  // N >= 1 (from == to only for N == 1)
  SweepMode mode = SweepMode::independent;
  bool upward = true;    // continuation: run the upward branch
  bool downward = true;  // continuation: run the downward branch
  PointSettings point;
  Vector initial_state;  // [x; v]; empty: at rest

  // Ceres-style check: false with a message naming the field and the value.
  bool is_valid(std::string* why) const;
  // The parameter value of index i: from + (to - from) * i / (N - 1).
  double value(int index) const;
  // The tasks: independent, one per point (upward ids only); continuation, one per branch.
  std::vector<GridTask> tasks() const;
  // The chain of point id.
  NondimensionalChain chain_of(long id) const;
  // Every setting that changes a result, one "key = value" per line in a fixed order, with
  // doubles at 17 significant digits: recorded with the output and compared on resume.
  std::string describe() const;
  Vector start_state() const;  // initial_state, or rest
};

// Writes <folder>/poincare.csv (parameter,direction,index,period_index,<component names>) and
// <folder>/classification.csv (index,parameter,direction,regime,code,period,lambda1,
// lambda1_error,K), sorted, with doubles at 17 significant digits. Throws pwl::Error when a file
// cannot be written.
void write_sweep_files(const SweepOptions& options, const std::map<long, PointResult>& records,
                       const std::string& folder);

// "x1".."xn", "v1".."vn" for state component c of an n-mass chain.
std::string component_name(int component, int masses);

}  // namespace pwl::analysis
