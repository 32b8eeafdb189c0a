// pwl.simulate, pwl.analyze, pwl.sweep and pwl.map: the jobs of `pwl simulate`, `pwl analyze`,
// `pwl sweep` and `pwl map`, parsed by their own flags (simulate_command.hpp, analyze_command.hpp,
// sweep_command.hpp, map_command.hpp) and run in memory by the same functions the CLI runs.
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "arguments.hpp"
#include "arrays.hpp"
#include "interrupt.hpp"
#include "jobs.hpp"
#include "structure.hpp"
#include "commands/analyze_command.hpp"
#include "commands/map_command.hpp"
#include "commands/simulate_command.hpp"
#include "commands/step_guard_report.hpp"
#include "commands/study_runner.hpp"
#include "commands/sweep_command.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/indicators.hpp"
#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::python {
namespace {

const LeftOut kSimulateLeftOut{
    {"--out", "pwl.simulate returns the arrays instead of writing poincare.csv"},
    {"--quiet", "pwl.simulate prints nothing"},
    {"--title", "pwl.simulate draws no figure"},
};
const LeftOut kAnalyzeLeftOut{
    {"--out", "pwl.analyze returns the verdict and its evidence instead of writing files"},
};
const LeftOut kSweepLeftOut{
    {"--out",
     "pwl.sweep returns the arrays instead of writing poincare.csv and classification.csv"},
    {"--resume", "pwl.sweep keeps no journal to resume from"},
    {"--quiet", "pwl.sweep shows no progress bar"},
    {"--no-plot", "pwl.sweep draws nothing"},
    {"--branches", "pwl.sweep draws no diagram to draw branches over"},
};
const LeftOut kMapLeftOut{
    {"--out", "pwl.map returns the arrays instead of writing map.csv"},
    {"--resume", "pwl.map keeps no journal to resume from"},
    {"--quiet", "pwl.map shows no progress bar"},
    {"--no-plot", "pwl.map draws nothing"},
    {"--curves", "pwl.map draws nothing (pwl.continue_(curves=...) returns the curves)"},
};

// The flags pwl.simulate takes: pwl simulate's, less those it leaves out.
void simulate_app(CLI::App& app, app::SimulateOptions& options) {
  app::add_simulate_flags(app, options);
  leave_out(app, kSimulateLeftOut);
}
std::vector<KeywordDoc> simulate_keywords() {
  CLI::App app{"pwl.simulate"};
  app.option_defaults()->always_capture_default();
  app::SimulateOptions options;
  simulate_app(app, options);
  return keyword_docs(app);
}

// The flags pwl.analyze takes: pwl analyze's, less those it leaves out.
void analyze_app(CLI::App& app, app::AnalyzeOptions& options) {
  app::add_analyze_flags(app, options);
  leave_out(app, kAnalyzeLeftOut);
}
std::vector<KeywordDoc> analyze_keywords() {
  CLI::App app{"pwl.analyze"};
  app.option_defaults()->always_capture_default();
  app::AnalyzeOptions options;
  analyze_app(app, options);
  return keyword_docs(app);
}

// The flags pwl.sweep takes: pwl sweep's, less those it leaves out.
void sweep_app(CLI::App& app, app::SweepFlags& flags) {
  app::add_sweep_flags(app, flags);
  leave_out(app, kSweepLeftOut);
}
std::vector<KeywordDoc> sweep_keywords() {
  CLI::App app{"pwl.sweep"};
  app.option_defaults()->always_capture_default();
  app::SweepFlags flags;
  sweep_app(app, flags);
  return keyword_docs(app);
}

// The flags pwl.map takes: pwl map's, less those it leaves out.
void map_app(CLI::App& app, app::MapFlags& flags) {
  app::add_map_flags(app, flags);
  leave_out(app, kMapLeftOut);
}
std::vector<KeywordDoc> map_keywords() {
  CLI::App app{"pwl.map"};
  app.option_defaults()->always_capture_default();
  app::MapFlags flags;
  map_app(app, flags);
  return keyword_docs(app);
}

std::vector<std::string> state_names(Index n) {
  std::vector<std::string> names;
  for (const char kind : {'x', 'v'}) {
    for (Index i = 1; i <= n; ++i) names.push_back(fmt::format("{}{}", kind, i));
  }
  return names;
}

py::list string_list(const std::vector<std::string>& values) {
  py::list list;
  for (const std::string& v : values) list.append(v);
  return list;
}

// The simulation's arrays, with Ctrl-C looked at once per section point and trajectory row.
class SimulationCollector : public app::SimulationArrays {
 public:
  void section_point(double t, const Vector& x, const Vector& v) override {
    SimulationArrays::section_point(t, x, v);
    interrupt_.poll();
  }
  void trajectory_row(const std::vector<double>& row) override {
    SimulationArrays::trajectory_row(row);
    interrupt_.poll();
  }

 private:
  Interrupt interrupt_;
};

py::dict simulate(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.simulate"};
  app::SimulateOptions options;
  simulate_app(app, options);
  parse_keywords(app, "simulate", args, kSimulateLeftOut);

  SimulationCollector arrays;
  app::SimulationSummary summary;
  without_gil([&] { summary = app::simulate_case(options, arrays); });
  const Index n = summary.dofs;
  const auto points = static_cast<py::ssize_t>(arrays.section_times.size());
  py::dict d;
  d["poincare"] = rows_array(arrays.section_states, points, 2 * n);
  d["t"] = vector_array(arrays.section_times);
  d["columns"] = string_list(state_names(n));
  const std::vector<int>& record = options.output.record;
  if (!record.empty()) {
    const auto columns = static_cast<py::ssize_t>(arrays.trajectory_columns);
    const py::ssize_t rows =
        columns == 0 ? 0 : static_cast<py::ssize_t>(arrays.trajectory.size()) / columns;
    std::vector<double> t, states;
    for (py::ssize_t r = 0; r < rows; ++r) {
      const auto* row = arrays.trajectory.data() + r * columns;
      t.push_back(row[0]);
      states.insert(states.end(), row + 1, row + columns);
    }
    d["trajectory"] = rows_array(states, rows, 2 * static_cast<py::ssize_t>(record.size()));
    d["trajectory_t"] = vector_array(t);
    std::vector<std::string> names;
    for (const char kind : {'x', 'v'}) {
      for (int r : record) names.push_back(fmt::format("{}{}", kind, r));
    }
    d["trajectory_columns"] = string_list(names);
  } else {
    d["trajectory"] = py::none();
    d["trajectory_t"] = py::none();
    d["trajectory_columns"] = py::list();
  }
  d["record"] = int_array(record);
  d["integrator"] = summary.integrator;
  d["method"] = std::string(method_traits(summary.method).name);
  py::dict stats;
  stats["steps"] = summary.stats.steps;
  stats["rejected_steps"] = summary.stats.rejected_steps;
  stats["rhs_evaluations"] = summary.stats.rhs_evaluations;
  stats["kink_events"] = summary.stats.kink_events;
  stats["lcp_pivots"] = summary.stats.lcp_pivots;
  d["stats"] = stats;
  d["dofs"] = n;
  d["forcing_period"] = summary.period;
  d["section"] = summary.section.label(n);
  d["description"] = name_given_structure(options.run.description(), file.get());
  return d;
}

// Ctrl-C looked at at every checkpoint of the analysed motion's ladder (before every period of
// its records and every integration of its Newton stages, the confirming run's included).
class AnalyzeCheckpoints : public analysis::PointObserver {
 public:
  void checkpoint() override { interrupt_.poll(); }

 private:
  Interrupt interrupt_;
};

py::dict period_search_dict(const analysis::PeriodResult& p) {
  py::dict d;
  d["period"] = p.period;
  d["fixed_point"] = p.fixed_point;
  d["mismatch"] = p.mismatch;
  d["best_k"] = p.best_k;
  d["distinct_points"] = p.distinct_points;
  d["scale"] = p.scale;
  d["diameter"] = p.diameter;
  d["points_used"] = p.points_used;
  return d;
}

py::dict analyze(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.analyze"};
  app::AnalyzeOptions options;
  analyze_app(app, options);
  parse_keywords(app, "analyze", args, kAnalyzeLeftOut);

  app::AnalyzeResult a;
  AnalyzeCheckpoints checkpoints;
  without_gil([&] { a = app::analyze_case(options, &checkpoints); });
  const analysis::PointResult& r = a.result;
  const Index n = a.dofs;
  py::dict d;
  d["regime"] = r.regime;
  d["code"] = analysis::regime_code(r.regime, r.period);
  d["period"] = r.period;
  d["lambda1"] = r.lambda1;
  d["lambda1_error"] = r.lambda1_error;
  d["K"] = r.K;
  if (a.classification) {
    d["period_search"] = period_search_dict(a.classification->period_search);
    d["reason"] = a.classification->reason;
    d["zero_one_source"] = a.classification->zero_one_source;
  } else {
    d["period_search"] = py::none();
    // What `pwl analyze` prints as the rule when there is no classification.
    d["reason"] = r.regime == "unbounded"
                      ? "the motion left the divergence bound before the record ended"
                      : "a contact problem (LCP) had no solution";
    d["zero_one_source"] = "";
  }
  const auto points = static_cast<py::ssize_t>(a.section_times.size());
  d["poincare"] = rows_array(a.section_states, points, 2 * n);
  d["t"] = vector_array(a.section_times);
  d["period_index"] = int_array(a.section_periods);
  d["columns"] = string_list(state_names(n));
  d["final_state"] = vector_array(r.final_state);
  d["lyapunov"] = analysis::lyapunov_estimate_name(a.settings.lyapunov_estimate);
  d["transient"] = a.settings.transient_periods;
  d["recorded"] = a.settings.recorded_periods;
  d["mass"] = a.mass;
  d["dofs"] = n;
  d["forcing_period"] = a.period;
  d["integrator"] = a.integrator;
  d["method"] = std::string(method_traits(a.settings.method.method).name);
  d["section"] = a.settings.section.label(n);
  d["description"] = name_given_structure(options.run.description(), file.get());
  // Every other indicator of the pipeline (the evidence ladder's), as sweep and map give them.
  for (const analysis::Indicator& indicator : analysis::indicators()) {
    const std::string name(indicator.name);
    if (d.contains(name)) continue;
    const analysis::IndicatorValue v = indicator.get(r);
    if (const auto* text = std::get_if<std::string>(&v)) {
      d[name.c_str()] = *text;
    } else if (const auto* integer = std::get_if<long>(&v)) {
      d[name.c_str()] = *integer;
    } else {
      d[name.c_str()] = std::get<double>(v);
    }
  }
  d["seconds"] = a.seconds;
  return d;
}

// The indicators of the points `records` (in id order), one column per row of indicators.hpp:
// a list of str for text, int64 or float64 arrays for the numbers (NaN: not computed).
void add_indicator_columns(py::dict& table, const std::map<long, analysis::PointResult>& records) {
  for (const analysis::Indicator& indicator : analysis::indicators()) {
    const std::string name(indicator.name);
    if (indicator.type == analysis::IndicatorType::text) {
      py::list column;
      for (const auto& [id, r] : records) {
        std::string text = std::get<std::string>(indicator.get(r));
        column.append(text.empty() ? std::string(indicator.empty_text) : text);
      }
      table[name.c_str()] = column;
    } else if (indicator.type == analysis::IndicatorType::integer) {
      py::array_t<long long> column(static_cast<py::ssize_t>(records.size()));
      long long* out = column.mutable_data();
      for (const auto& [id, r] : records) *out++ = std::get<long>(indicator.get(r));
      table[name.c_str()] = column;
    } else {
      std::vector<double> column;
      for (const auto& [id, r] : records) column.push_back(std::get<double>(indicator.get(r)));
      table[name.c_str()] = vector_array(column);
    }
  }
}

// Runs the study's points in this process (analysis::run_grid, as compute_study does), looking at
// Ctrl-C after each finished point; the step guard first, as pwl sweep and pwl map do.
std::map<long, analysis::PointResult> run_points(const app::Study& study, int threads,
                                                 bool force) {
  app::guard_study_steps(study.tasks, study.case_of, study.settings, force);
  std::map<long, analysis::PointResult> records;
  without_gil([&] {
    Interrupt interrupt;
    analysis::run_grid(study.tasks, study.case_of, study.initial_state, study.settings, {},
                       [&](long id, const analysis::PointResult& r) {
                         records.emplace(id, r);
                         interrupt.poll();
                       },
                       {threads});
  });
  return records;
}

py::dict sweep(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.sweep"};
  app::SweepFlags flags;
  sweep_app(app, flags);
  parse_keywords(app, "sweep", args, kSweepLeftOut);

  const analysis::SweepOptions o = app::sweep_options(flags);
  const std::map<long, analysis::PointResult> records =
      run_points(app::study_of(o), flags.run.threads, flags.run.force);
  const int dofs = o.model().dofs();
  const bool crossings = !o.point.section.stroboscopic();
  const auto columns = static_cast<py::ssize_t>(o.point.components.size());

  // poincare.csv's rows: the points of each value and direction, up first, by index.
  std::vector<double> value, t, states;
  std::vector<int> index, period_index;
  std::vector<std::string> direction;
  // classification.csv's rows.
  std::vector<double> table_value;
  std::vector<int> table_index;
  std::vector<std::string> table_direction;
  for (const auto& [id, r] : records) {
    const int i = static_cast<int>(id % o.points);
    const char* dir = id < o.points ? "up" : "down";
    table_index.push_back(i);
    table_value.push_back(o.value(i));
    table_direction.emplace_back(dir);
    for (int k = 0; k < r.rows(); ++k) {
      value.push_back(o.value(i));
      direction.emplace_back(dir);
      index.push_back(i);
      const auto row = static_cast<std::size_t>(k);
      if (crossings) {
        t.push_back(row < r.section_times.size() ? r.section_times[row] : std::nan(""));
      } else {
        period_index.push_back(o.point.transient_periods + k + 1);
      }
      const auto* first = r.poincare.data() + row * static_cast<std::size_t>(r.columns);
      states.insert(states.end(), first, first + r.columns);
    }
  }
  py::dict d;
  const auto rows = static_cast<py::ssize_t>(value.size());
  d["poincare"] = rows_array(states, rows, columns);
  d["poincare_parameter"] = vector_array(value);
  d["poincare_direction"] = string_list(direction);
  d["poincare_index"] = int_array(index);
  if (crossings) {
    d["poincare_t"] = vector_array(t);
    d["poincare_period"] = py::none();
  } else {
    d["poincare_t"] = py::none();
    d["poincare_period"] = int_array(period_index);
  }
  std::vector<std::string> names;
  for (int c : o.point.components) names.push_back(analysis::component_name(c, dofs));
  d["components"] = string_list(names);
  py::dict table;
  // classification.csv's columns.
  table["index"] = int_array(table_index);
  table[analysis::parameter_name(o.parameter).c_str()] = vector_array(table_value);
  table["direction"] = string_list(table_direction);
  add_indicator_columns(table, records);
  d["table"] = table;
  std::vector<double> values;
  for (int i = 0; i < o.points; ++i) values.push_back(o.value(i));
  d["values"] = vector_array(values);
  d["parameter"] = analysis::parameter_name(o.parameter);
  d["points"] = o.points;
  d["mode"] = o.mode == analysis::SweepMode::continuation ? "continuation" : "independent";
  d["section"] = o.point.section.label(dofs);
  d["description"] = name_given_structure(o.describe(), file.get());
  return d;
}

py::dict map(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.map"};
  app::MapFlags flags;
  map_app(app, flags);
  parse_keywords(app, "map", args, kMapLeftOut);

  const analysis::RegimeMapOptions o = app::map_options(flags);
  const std::map<long, analysis::PointResult> records =
      run_points(app::study_of(o), flags.run.threads, flags.run.force);
  // map.csv's rows, by j then i (the id order).
  std::vector<int> i_column, j_column;
  std::vector<double> x_column, y_column;
  for (const auto& [id, r] : records) {
    const int i = static_cast<int>(id % o.first.points);
    const int j = static_cast<int>(id / o.first.points);
    i_column.push_back(i);
    j_column.push_back(j);
    x_column.push_back(o.first.value(i));
    y_column.push_back(o.second.value(j));
  }
  py::dict table;  // map.csv's columns
  table["i"] = int_array(i_column);
  table["j"] = int_array(j_column);
  table[analysis::parameter_name(o.first.parameter).c_str()] = vector_array(x_column);
  table[analysis::parameter_name(o.second.parameter).c_str()] = vector_array(y_column);
  add_indicator_columns(table, records);
  py::dict d;
  d["table"] = table;
  std::vector<double> xs, ys;
  for (int i = 0; i < o.first.points; ++i) xs.push_back(o.first.value(i));
  for (int j = 0; j < o.second.points; ++j) ys.push_back(o.second.value(j));
  d["x_values"] = vector_array(xs);
  d["y_values"] = vector_array(ys);
  d["x"] = analysis::parameter_name(o.first.parameter);
  d["y"] = analysis::parameter_name(o.second.parameter);
  d["mode"] = o.mode == analysis::SweepMode::continuation ? "continuation" : "independent";
  d["description"] = name_given_structure(o.describe(), file.get());
  return d;
}

}  // namespace

void bind_run_jobs(py::module_& m) {
  m.def("simulate", &simulate, "One case integrated: see pwl.simulate.");
  m.def("analyze", &analyze, "One case classified: see pwl.analyze.");
  m.def("sweep", &sweep, "A one-parameter sweep: see pwl.sweep.");
  m.def("map", &map, "A two-parameter regime map: see pwl.map.");
  register_keywords("simulate", &simulate_keywords);
  register_keywords("analyze", &analyze_keywords);
  register_keywords("sweep", &sweep_keywords);
  register_keywords("map", &map_keywords);
}

}  // namespace pwl::python
