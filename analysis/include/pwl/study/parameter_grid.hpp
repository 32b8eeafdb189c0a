#pragma once
// Runs the points of a parameter study, in parallel where the study allows it.
//
// A study is a list of tasks. A task is a list of point ids computed in order: in an independent
// study every task holds one point, started from the same initial state; in a continuation every
// task is a branch (a sweep upward or downward, a row of a regime map) whose points each start
// from the final state of the point before, which is what shows hysteresis and coexisting
// attractors. A branch is inherently sequential, so the parallelism of a continuation is across
// branches, not along them.
//
// Tasks are spread over OpenMP threads with a dynamic schedule (a chaotic point costs no more
// than a periodic one, but unbounded ones stop early, so the work per task varies). Each point
// depends only on its own case and its initial state, so the results do not depend on the number
// of threads or on the order in which tasks finish; callers that write files sort by id.
#include <functional>
#include <map>
#include <vector>

#include "pwl/study/sweep_point.hpp"

namespace pwl::analysis {

// Value `index` of `points` evenly spaced values from `from` to `to` (just `from` when points is
// 1): the grid of every sweep, map and basin axis, computed one way so that they agree to the bit.
inline double grid_value(double from, double to, int points, int index) {
  if (points == 1) return from;
  return from + (to - from) * static_cast<double>(index) / static_cast<double>(points - 1);
}

struct GridTask {
  std::vector<long> ids;      // in the order they are computed
  bool continuation = false;  // each point starts from the previous point's final state
  // The state the task's first point starts from ([x; v]); empty: the study's initial state. A
  // basin map gives every cell its own.
  Vector start;
};

// The case of point `id`: its structure and forcing period (a NondimensionalChain converts).
using PointCaseOf = std::function<PointCase(long id)>;
// Told about every point finished in this run. Called by one thread at a time.
using PointSink = std::function<void(long id, const PointResult& result)>;

struct GridRun {
  int threads = 0;  // OpenMP threads; 0: the OpenMP default
  // Asked, from any thread, before every point and between the forcing periods of every point
  // (through PointObserver::steps_of_period); once it answers true, every thread leaves the point
  // it is computing unfinished (the sink never sees it) and run_grid returns GridEnd::stopped.
  // How a run stops at once on a signal: it must be cheap and thread-safe (an atomic flag read).
  // Null: never stop.
  std::function<bool()> stop = nullptr;
};

enum class GridEnd {
  finished,  // every point of the tasks is in `done` or went to the sink
  stopped,   // run.stop said so; the points that went to the sink are the only ones finished
};

// Computes every point of `tasks` that is not in `done`. A continuation that meets a point in
// `done` takes its final state from there (a resumed run continues where the killed one stopped);
// after a point whose motion blew up (no final state) it restarts from `initial_state` (or the
// task's own start).
// Exceptions from a point (bad input) or from the sink (a journal that cannot be written) stop
// the other threads as run.stop does and are rethrown on the calling thread after the loop.
GridEnd run_grid(const std::vector<GridTask>& tasks, const PointCaseOf& case_of,
                 const Vector& initial_state, const PointSettings& settings,
                 const std::map<long, PointResult>& done, const PointSink& sink,
                 const GridRun& run = {});

}  // namespace pwl::analysis
