#pragma once
// A one-parameter sweep of a point model (point_model.hpp): the data of a bifurcation diagram.
//
// N values of one parameter of the model (θ, α, ζ, Δ̃ or the load scale of the paper's chain; a
// spring's stiffness or gap, a load's amplitude or frequency, or the damping scale of an explicit
// structure), evenly spaced over [from, to]. In an
// independent sweep every point starts from the same initial state; in a continuation the sweep
// runs upward (from `from` to `to`) and downward, each point starting from the final state of the
// one before, so that the two directions follow different attractors where they coexist
// (hysteresis). Each point keeps its Poincaré points of the chosen components and one
// classification (sweep_point.hpp). The section of point.section decides which Poincaré points
// are kept; the classification is always that of the stroboscopic map at its phase.
//
// Point ids: index i (0-based, value from + (to - from) i / (N - 1)) upward is id i, downward is
// id N + i. Files are written sorted by direction (up first) and index, whatever order the
// points were computed in.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

enum class SweepMode { independent, continuation };

struct SweepOptions {
  // The base case: the paper's chain, or, when `structure` is set, that explicit structure (then
  // `chain` is not used). The swept parameter overrides its value.
  NondimensionalChain chain;
  std::optional<ExplicitStructure> structure;
  SweepParameter parameter = SweepParameter::theta;
  double from = 0.5;
  double to = 3.0;
  int points = 100;  // N >= 1 (from == to only for N == 1)
  SweepMode mode = SweepMode::independent;
  bool upward = true;    // continuation: run the upward branch
  bool downward = true;  // continuation: run the downward branch
  PointSettings point;
  // [x; v]; empty: at rest. Every point of an independent sweep starts from it, and the first
  // point of each branch of a continuation (and any point after one that blew up).
  Vector initial_state;

  // The model the sweep varies: the chain or the explicit structure.
  PointModel model() const;
  // Ceres-style check: false with a message naming the field and the value. Every value of the
  // sweep must give a valid case of the model.
  bool is_valid(std::string* why) const;
  // The parameter value of index i: from + (to - from) * i / (N - 1).
  double value(int index) const;
  // The tasks: independent, one per point (upward ids only); continuation, one per branch.
  std::vector<GridTask> tasks() const;
  // The case (structure and period) of point id.
  PointCase case_of(long id) const;
  // The chain of point id (a sweep of the chain only; InputError for an explicit structure).
  NondimensionalChain chain_of(long id) const;
  // Every setting that changes a result, one "key = value" per line in a fixed order, with
  // doubles at 17 significant digits: recorded with the output and compared on resume.
  std::string describe() const;
  Vector start_state() const;  // initial_state, or rest
};

// Writes <folder>/poincare.csv (parameter,direction,index,period_index,<component names>; for a
// hyperplane section t, the crossing's time, instead of period_index) and
// <folder>/classification.csv (index,parameter,direction, then every indicator of indicators.hpp:
// regime,code,period,lambda1,lambda1_error,K,...), sorted, with doubles at 17 significant digits. Throws pwl::Error when a file
// cannot be written.
void write_sweep_files(const SweepOptions& options, const std::map<long, PointResult>& records,
                       const std::string& folder);

// "x1".."xn", "v1".."vn" for state component c of a structure of n degrees of freedom.
std::string component_name(int component, int masses);

}  // namespace pwl::analysis
