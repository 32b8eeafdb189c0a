#pragma once
// What a job does with the step guard's verdict (pwl/integrators/step_guard.hpp) and with the
// exact solver's progress.
//
// The guard judges a fixed step against the stiffest contact of the structure (η ω_max against
// the limits the method table carries from `pwl bench stability`). A refusal ends the job before
// anything is integrated: InputError (exit code 2) with the guard's message, which names the step
// and the steps per period that would do. --force runs the step anyway for those who know what
// they are asking for (a stability study of the method itself, say); the refusal is then printed
// on standard error as a warning. A warning (a step that resolves the contact poorly but does not
// miss it, or an adaptive method's tolerance looser than 1e-5) is printed on standard error and
// the job goes on.
//
// A study (sweep, map) is judged on every point before its first point is computed, so that a
// refusal costs nothing; the message counts the points and names the first, with the steps per
// period that satisfy every point.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "pwl/integrators/method_table.hpp"
#include "pwl/model/gap_structure.hpp"
#include "pwl/study/parameter_grid.hpp"

namespace pwl::app {

// --force: run a step the guard refuses.
void add_force_flag(CLI::App& command, bool& force);

// Judges one case. Throws InputError for a refusal unless `force`; prints warnings on stderr.
void guard_step(const GapStructure& structure, const MethodSettings& settings, double period,
                bool force);

// Judges every point of a study (independent of the number of threads or processes: call it on
// every rank, it prints on rank 0 only when `print` is true).
void guard_study_steps(const std::vector<analysis::GridTask>& tasks,
                       const analysis::PointCaseOf& case_of,
                       const analysis::PointSettings& settings, bool force, bool print = true);

// For the exact event-driven solver: a progress hook that prints one line on stderr for each
// progress_interval of a long advance (time reached, switches, gap samples, wall time), so that
// a run with very stiff contacts shows what it is doing before its budget ends it. Does nothing
// for other methods. Thread-safe (one lock around the print).
void report_exact_progress(MethodSettings& settings);

}  // namespace pwl::app
