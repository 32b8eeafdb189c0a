#pragma once
// What `pwl sweep` and `pwl map` share: the flags of the base model (the paper's chain or an
// explicit structure) and of each point, and the driver that runs a study's points into an output
// folder so that a long run loses nothing.
//
// The folder holds config.txt (every setting that changes a result), one journal-<rank>.log per
// process (a line per finished point, see sweep_journal.hpp) and, once every point is done, the
// sorted result files. With --resume, a run whose config.txt matches skips the points already
// in the journals; a different configuration is refused. Without it the folder is started over.
//
// Faults lose nothing that was finished (every message names the path and the system's reason):
//  - damaged journal lines are warned about by file and line number and their points computed
//    again; records that cannot belong to the study are refused (sweep_journal.hpp says which);
//  - a folder in which no file can be created is refused before any point is computed;
//  - a journal that stops taking lines (a full disk, a file size limit) keeps whole lines only, and
//    the run ends with an error saying how many points are kept; result files that do not fit
//    end it the same way with every point kept, for --resume to write them;
//  - SIGINT and SIGTERM stop the points on every thread within a forcing period
//    (parallel/stop_signals.hpp, GridRun::stop), keep the journals whole and end the run with
//    Stopped (exit code 130 or 143) saying how many points are done and how to go on. Under
//    mpirun the stopped rank ends them all (MPI_Abort with that code).
//
// Distributed runs (mpirun -np R): task t goes to rank t mod R, each rank spreads its tasks over
// its OpenMP threads and journals them, and rank 0 gathers every record and writes the files, the
// same bytes a single process writes. --resume needs the folder on a filesystem every rank sees.
#include <CLI/CLI.hpp>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "commands/ladder_flags.hpp"
#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::app {

// The base model: a paper preset and flags that override it, or an explicit structure from a
// scene file (--structure-scene; the chain's flags do not apply then).
struct ModelFlags {
  std::string figure;
  int masses = 5;
  std::vector<double> alpha;
  double zeta = std::numeric_limits<double>::quiet_NaN();
  double gap = std::numeric_limits<double>::quiet_NaN();
  double theta = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> loads;
  std::string structure_scene;
  // Throws InputError for chain flags given with a structure scene, or a scene that is not valid.
  analysis::PointModel model() const;
};
void add_model_flags(CLI::App& command, ModelFlags& flags);

// The parameter `name` of `model`, for the flag `flag`: InputError naming the flag, the value and
// the model's parameters otherwise.
analysis::SweepParameter parse_model_parameter(const analysis::PointModel& model,
                                               const std::string& flag, const std::string& name);

// How each point is integrated and what it keeps.
struct PointFlags {
  int transient = 500;
  int periods = 500;
  int steps_per_period = 200;
  std::vector<std::string> record;  // component names: x1..xn, v1..vn
  bool no_lyapunov = false;
  std::string lyapunov;  // empty: default_lyapunov_estimate of the method
  std::string method = "pim";
  double tolerance = 1e-10;
  bool locate_kinks = false;
  std::string lcp_solver = "block-pivoting";
  // The evidence ladder (PointSettings::use_ladder) is on unless `quick`; each of its flags given
  // explicitly wins over both (-1 and empty: not given).
  LadderFlags ladder;
  int starts = 1;  // initial states per point, for counting coexisting attractors
  // Throws InputError for a bad name or value.
  analysis::PointSettings settings(int dofs) const;
};
void add_point_flags(CLI::App& command, PointFlags& flags, bool with_record);

// How the study runs.
struct RunFlags {
  std::string out = "sweep";
  bool resume = false;
  bool quiet = false;
  bool no_plot = false;
  int threads = 0;
  bool force = false;  // run points the step guard refuses (step_guard_report.hpp)
};
void add_run_flags(CLI::App& command, RunFlags& flags);

struct Study {
  std::string description;  // config.txt
  std::vector<analysis::GridTask> tasks;
  analysis::PointCaseOf case_of;
  Vector initial_state;
  analysis::PointSettings settings;
  // Called on rank 0 with every record, in id order, once all are done.
  std::function<void(const std::map<long, analysis::PointResult>&)> finish;
};

// The study of a sweep or a map: both option types give its description, tasks, cases, start
// state and point settings the same way.
template <class GridOptions>
Study study_of(const GridOptions& o) {
  Study study;
  study.description = o.describe();
  study.tasks = o.tasks();
  study.case_of = [o](long id) { return o.case_of(id); };
  study.initial_state = o.start_state();
  study.settings = o.point;
  return study;
}

// Runs the study into flags.out. Throws InputError for a resume that does not match or journals
// that cannot be trusted, Stopped (stop_signals.hpp) on SIGINT or SIGTERM, Error for a folder or
// a file that cannot be written.
void run_study(const Study& study, const RunFlags& flags);

// Computes every point of `study` in this process and returns the records by id (what `finish`
// would get), with no folder, journal, progress bar or MPI: how an embedding runs a sweep or a
// map in memory. `threads` as --threads (0: the OpenMP default), `force` as --force. Throws the
// step guard's refusal (step_guard_report.hpp) and what evaluate_point throws (InputError for
// invalid settings).
std::map<long, analysis::PointResult> compute_study(const Study& study, int threads = 0,
                                                    bool force = false);

// The 0-based state component named `name` (x1..xn, v1..vn) of a structure of `masses` degrees
// of freedom; InputError naming the flag and the value otherwise.
int parse_component(const std::string& flag, const std::string& name, int masses);

// Parses a range "a:b" into its ends; throws InputError naming the flag otherwise.
void parse_range(const std::string& flag, const std::string& text, double* from, double* to);

// Figure text: the axis label of a swept parameter ("θ = ω/ω0", "gap Δ of spring 1"), and a title
// line stating the base case and the integration ("base case: 5 masses, α = 5, ζ = 0.2, Δ̃ = 0,
// Q = (1,-1,1,-1,1); 300 + 200 periods per point, η = T/200", then the section when it is not the
// default: "; section v3 = 0 going down"). Single quotes are left out (gnuplot strings).
std::string parameter_label(const analysis::SweepParameter& parameter);
std::string study_title(const analysis::PointModel& model, const analysis::PointSettings& point);

}  // namespace pwl::app
