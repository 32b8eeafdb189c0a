#include "pwl/study/parameter_grid.hpp"

#include <omp.h>

#include <atomic>
#include <exception>

namespace pwl::analysis {

namespace {

// Thrown out of a point's evaluation when the grid stops; caught by the grid alone.
struct Abandoned {};

// Looks at the stop request at every checkpoint of a point's ladder (before every forcing period
// of its records, before every integration of its Newton stages, also in a confirming run by the
// accurate method). It sees no step and changes nothing in the evaluation: a point that is not
// abandoned comes out bit for bit as without it.
class StopCheck : public PointObserver {
 public:
  explicit StopCheck(const std::function<bool()>& should_stop) : should_stop_(should_stop) {}
  void checkpoint() override {
    if (should_stop_()) throw Abandoned{};
  }

 private:
  const std::function<bool()>& should_stop_;
};

}  // namespace

GridEnd run_grid(const std::vector<GridTask>& tasks, const PointCaseOf& case_of,
                 const Vector& initial_state, const PointSettings& settings,
                 const std::map<long, PointResult>& done, const PointSink& sink,
                 const GridRun& run) {
  std::exception_ptr failure;
  std::atomic<bool> failed{false};
  std::atomic<bool> stopped{false};
  // Every thread stops at its next check once a point failed or a stop was asked for; the request
  // is remembered, so that a stop seen by one thread is seen by all.
  const std::function<bool()> should_stop = [&] {
    if (failed.load(std::memory_order_relaxed) || stopped.load(std::memory_order_relaxed)) {
      return true;
    }
    if (run.stop && run.stop()) {
      stopped.store(true, std::memory_order_relaxed);
      return true;
    }
    return false;
  };
  const int count = static_cast<int>(tasks.size());
  const int threads = run.threads > 0 ? run.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int t = 0; t < count; ++t) {
    try {
      const GridTask& task = tasks[static_cast<std::size_t>(t)];
      StopCheck check(should_stop);
      const Vector& start = task.start.size() != 0 ? task.start : initial_state;
      Vector state = start;
      for (long id : task.ids) {
        if (should_stop()) break;
        const auto found = done.find(id);
        PointResult computed;
        const PointResult* result = nullptr;
        if (found != done.end()) {
          result = &found->second;
        } else {
          computed = evaluate_point(case_of(id), task.continuation ? state : start,
                                    settings, &check);
          result = &computed;
          // An exception must not leave a critical construct: catch it inside, throw outside.
          std::exception_ptr sink_failure;
#pragma omp critical(pwl_grid_sink)
          {
            try {
              sink(id, computed);
            } catch (...) {
              sink_failure = std::current_exception();
            }
          }
          if (sink_failure) std::rethrow_exception(sink_failure);
        }
        if (task.continuation) {
          state = result->final_state.size() == start.size() ? result->final_state : start;
        }
      }
    } catch (const Abandoned&) {
      // The point in progress is dropped; the loop's other tasks see the same request.
    } catch (...) {
#pragma omp critical(pwl_grid_failure)
      if (!failure) failure = std::current_exception();
      failed.store(true, std::memory_order_relaxed);
    }
  }
  if (failure) std::rethrow_exception(failure);
  return stopped.load() ? GridEnd::stopped : GridEnd::finished;
}

}  // namespace pwl::analysis
