#include "pwl/study/parameter_grid.hpp"

#include <omp.h>

#include <exception>

namespace pwl::analysis {

void run_grid(const std::vector<GridTask>& tasks, const PointCaseOf& case_of,
              const Vector& initial_state, const PointSettings& settings,
              const std::map<long, PointResult>& done, const PointSink& sink, const GridRun& run) {
  std::exception_ptr failure;
  const int count = static_cast<int>(tasks.size());
  const int threads = run.threads > 0 ? run.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int t = 0; t < count; ++t) {
    try {
      const GridTask& task = tasks[static_cast<std::size_t>(t)];
      Vector state = initial_state;
      for (long id : task.ids) {
        bool stop = false;
#pragma omp critical(pwl_grid_failure)
        stop = static_cast<bool>(failure);
        if (stop) break;
        const auto found = done.find(id);
        PointResult computed;
        const PointResult* result = nullptr;
        if (found != done.end()) {
          result = &found->second;
        } else {
          computed = evaluate_point(case_of(id), task.continuation ? state : initial_state,
                                    settings);
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
          state = result->final_state.size() == initial_state.size() ? result->final_state
                                                                    : initial_state;
        }
      }
    } catch (...) {
#pragma omp critical(pwl_grid_failure)
      if (!failure) failure = std::current_exception();
    }
  }
  if (failure) std::rethrow_exception(failure);
}

}  // namespace pwl::analysis
