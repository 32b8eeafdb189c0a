#include "commands/step_guard_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <mutex>

#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/step_guard.hpp"

namespace pwl::app {

void add_force_flag(CLI::App& c, bool& force) {
  c.add_flag("--force", force,
             "Run a fixed step the step guard refuses (η ω_max beyond the method's limit, where\n"
             "pwl bench stability finds it missing contacts or blowing up); warned on stderr");
}

void guard_step(const GapStructure& structure, const MethodSettings& settings, double period,
                bool force) {
  const StepCheck check = check_step(structure, settings, period);
  if (check.ok()) return;
  if (check.refused() && !force) {
    throw InputError(check.message + "; --force runs it anyway");
  }
  fmt::print(stderr, "pwl: warning: {}{}\n", check.message,
             check.refused() ? " (run anyway: --force)" : "");
}

void guard_study_steps(const std::vector<analysis::GridTask>& tasks,
                       const analysis::PointCaseOf& case_of,
                       const analysis::PointSettings& settings, bool force, bool print) {
  long points = 0, warned = 0, refused = 0;
  long first_id = -1, first_refused_id = -1;
  std::string first_message, first_refused_message;
  long steps_per_period = 0;  // enough for every point
  for (const analysis::GridTask& task : tasks) {
    for (const long id : task.ids) {
      const analysis::PointCase point = case_of(id);
      const StepCheck check =
          check_step(point.structure, settings.method_for(point.period), point.period);
      ++points;
      steps_per_period = std::max(steps_per_period, check.steps_per_period);
      if (check.ok()) continue;
      ++warned;
      if (first_id < 0) {
        first_id = id;
        first_message = check.message;
      }
      if (check.refused()) {
        ++refused;
        if (first_refused_id < 0) {
          first_refused_id = id;
          first_refused_message = check.message;
        }
      }
    }
  }
  if (warned == 0) return;
  const std::string every =
      steps_per_period > 0
          ? fmt::format("--steps-per-period {} or more satisfies every point", steps_per_period)
          : std::string("the same for every point");
  if (refused > 0 && !force) {
    throw InputError(fmt::format(
        "the step guard refuses {} of the {} points of this study ({}); the first, point {}: "
        "{}; --force runs them anyway",
        refused, points, every, first_refused_id, first_refused_message));
  }
  if (!print) return;
  if (refused > 0) {
    fmt::print(stderr,
               "pwl: warning: the step guard refuses {} of the {} points of this study, run "
               "anyway (--force); {}; the first, point {}: {}\n",
               refused, points, every, first_refused_id, first_refused_message);
  } else {
    fmt::print(stderr,
               "pwl: warning: {} of the {} points of this study draw a warning from the step "
               "guard ({}); the first, point {}: {}\n",
               warned, points, every, first_id, first_message);
  }
}

void report_exact_progress(MethodSettings& settings) {
  if (settings.method != Method::exact) return;
  const long events = settings.event_driven.max_events;
  const long samples = settings.event_driven.max_gap_samples;
  settings.event_driven.progress = [events, samples](const EventDrivenProgress& p) {
    static std::mutex lock;
    const std::lock_guard<std::mutex> guard(lock);
    fmt::print(stderr,
               "pwl: exact solver: t = {:.6g} of [{:.6g}, {:.6g}], {} switches and {} gap "
               "samples in {:.0f} s (budget: {} and {})\n",
               p.t, p.t_start, p.t_end, p.events, p.gap_samples, p.seconds, events, samples);
  };
}

}  // namespace pwl::app
