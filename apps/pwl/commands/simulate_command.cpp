// pwl simulate: integrate one case and write its Poincaré points (the stroboscopic ones, or the
// crossings of a hyperplane), the trajectory of the requested masses, and a phase portrait.
#include "commands/simulate_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/flag_relations.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/section_sampler.hpp"

namespace pwl::app {
namespace {

// The checks of --record and --skip-periods, before anything is integrated or written.
void check_recording(const SimulateOptions& options, Index n) {
  for (int r : options.output.record) {
    if (r < 1 || r > n) {
      throw InputError(fmt::format("--record {}: masses are numbered 1..{}", r, n));
    }
  }
  check_relation("simulate", "--skip-periods", options.run.skip_periods, "--periods",
                 options.run.periods);
}

// The command line's sink: poincare.csv and, with --record, trajectory.csv, opened once the flags
// have passed their checks.
class SimulateFiles : public SimulationSink {
 public:
  explicit SimulateFiles(const SimulateOptions& options) : options_(options) {}

  void started(const Integrator&, const GapStructure& structure) override {
    const RecordingOptions& output = options_.output;
    std::filesystem::create_directories(output.out);
    poincare_ = std::make_unique<CsvWriter>(output.out + "/poincare.csv",
                                            state_columns("t", structure.dofs()));
    if (!output.record.empty()) {
      std::vector<std::string> columns{"t"};
      for (int r : output.record) columns.push_back(fmt::format("x{}", r));
      for (int r : output.record) columns.push_back(fmt::format("v{}", r));
      trajectory_ = std::make_unique<CsvWriter>(output.out + "/trajectory.csv", columns);
    }
  }
  void section_point(double t, const Vector& x, const Vector& v) override {
    poincare_->row(t, x, v);
  }
  void trajectory_row(const std::vector<double>& row) override { trajectory_->row(row); }
  // Closes the files (before gnuplot reads them).
  void close() {
    poincare_.reset();
    trajectory_.reset();
  }

 private:
  const SimulateOptions& options_;
  std::unique_ptr<CsvWriter> poincare_;
  std::unique_ptr<CsvWriter> trajectory_;
};

}  // namespace

void SimulationArrays::started(const Integrator&, const GapStructure& structure) {
  dofs = structure.dofs();
  section_times.clear();
  section_states.clear();
  trajectory.clear();
  trajectory_columns = 0;
}

void SimulationArrays::section_point(double t, const Vector& x, const Vector& v) {
  section_times.push_back(t);
  section_states.insert(section_states.end(), x.data(), x.data() + x.size());
  section_states.insert(section_states.end(), v.data(), v.data() + v.size());
}

void SimulationArrays::trajectory_row(const std::vector<double>& row) {
  trajectory_columns = row.size();
  trajectory.insert(trajectory.end(), row.begin(), row.end());
}

SimulationSummary simulate_case(const SimulateOptions& options, SimulationSink& sink) {
  const CaseOptions& run = options.run;
  const RecordingOptions& output = options.output;
  const GapStructure structure = run.structure();
  const Index n = structure.dofs();
  check_recording(options, n);
  if (!options.compare.method.empty()) {
    throw InputError(fmt::format(
        "--compare-with {}: a comparison of two methods is pwl simulate's own output "
        "(reference_poincare.csv, comparison.png); integrate each method on its own here",
        options.compare.method));
  }
  const analysis::PoincareSection section = options.section.poincare_section(n);
  const double period = run.period();
  std::unique_ptr<Integrator> integrator = run.integrator(structure, period);
  analysis::SectionSampler sampler(*integrator, structure, period, section,
                                   run.method_settings(period), run.grid_steps(period));
  sink.started(*integrator, structure);

  std::vector<double> row(1 + 2 * output.record.size());
  const StepObserver record = [&](double t, const Vector& x, const Vector& v) {
    row[0] = t;
    for (std::size_t j = 0; j < output.record.size(); ++j) {
      row[1 + j] = x[output.record[j] - 1];
      row[1 + output.record.size() + j] = v[output.record[j] - 1];
    }
    sink.trajectory_row(row);
  };
  const bool strobe = section.stroboscopic();
  const double phase = section.phase;
  const analysis::SectionSampler::CrossingSink crossing = [&](const analysis::Crossing& c) {
    sink.section_point(c.t, c.state.head(n), c.state.tail(n));
  };
  // The kept periods are (skip·T, periods·T]; the initial state counts as the point at t = 0 when
  // nothing is skipped and the phase is 0.
  if (strobe && phase == 0.0 && run.skip_periods == 0) {
    sink.section_point(integrator->time(), integrator->position(), integrator->velocity());
  }
  if (!strobe && run.skip_periods == 0) sampler.record_crossings(crossing);
  const int drawn_from =
      output.trajectory_periods > 0
          ? std::max(run.skip_periods, run.periods - output.trajectory_periods)
          : run.skip_periods;
  for (int k = 1; k <= run.periods; ++k) {
    const StepObserver steps = k > drawn_from && !output.record.empty() ? record : StepObserver();
    if (strobe && phase > 0.0) {
      // The strobe time (k - 1 + P) T lies inside period k.
      const analysis::StrobePoint p = sampler.advance_to_strobe(k - 1, nullptr, steps);
      if (k - 1 >= run.skip_periods) sink.section_point(p.t, p.state.head(n), p.state.tail(n));
    }
    sampler.advance_to(k * period, nullptr, steps);
    if (strobe && phase == 0.0 && k > run.skip_periods) {
      sink.section_point(integrator->time(), integrator->position(), integrator->velocity());
    }
    if (!strobe && k == run.skip_periods) sampler.record_crossings(crossing);
  }
  SimulationSummary summary;
  summary.integrator = integrator->name();
  summary.method = integrator->method();
  summary.stats = integrator->stats();
  summary.dofs = n;
  summary.period = period;
  summary.section = section;
  return summary;
}

void simulate(const SimulateOptions& options) {
  const CaseOptions& run = options.run;
  const RecordingOptions& output = options.output;
  if (!options.compare.method.empty()) {
    const Index n = run.structure().dofs();
    check_recording(options, n);
    if (!options.section.poincare_section(n).is_default()) {
      throw InputError(fmt::format(
          "--section {} --phase {}: --compare-with compares the two methods at t = kT; leave "
          "--section and --phase at their defaults",
          options.section.section, options.section.phase));
    }
    simulate_with_comparison(run, options.compare, output);
    return;
  }
  SimulateFiles files(options);
  const SimulationSummary summary = simulate_case(options, files);
  files.close();
  const Index n = summary.dofs;
  const IntegratorStats& s = summary.stats;
  if (!output.quiet) {
    fmt::print("{}: {} periods, {} steps, {} rejected, {} kink events, {} LCP pivots\n",
               summary.integrator, run.periods, s.steps, s.rejected_steps, s.kink_events,
               s.lcp_pivots);
    fmt::print("wrote {}/poincare.csv{}\n", output.out,
               output.record.empty() ? "" : " and trajectory.csv");
  }
  if (output.record.empty()) return;
  const int mass = output.record.front();
  // Said only when it is not the default, so that the default figure keeps its bytes.
  std::string section_note;
  if (!summary.section.is_default()) {
    section_note = fmt::format(", Poincaré section {}", summary.section.label(n));
  }
  section_note += run.start.description();
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/phase.{10}'; "
        "xcol={1}; vcol={2}; pxcol={3}; pvcol={4}; mass={5}; title={11}; "
        "label='{6}, {7}, {8} periods after {9}{12}'",
        output.out, 2, 2 + output.record.size(), 1 + mass, 1 + n + mass, mass, summary.integrator,
        run.description(), run.periods - run.skip_periods, run.skip_periods, format,
        gnuplot_quoted(output.title), section_note);
  };
  draw_figure_and_report(scripts_directory() + "/phase_portrait.gp", definitions,
                         output.out + "/phase", "pwl simulate", output.quiet);
}

void add_simulate_flags(CLI::App& c, SimulateOptions& options) {
  add_case_options(c, options.run);
  add_section_flags(c, options.section,
                    "poincare.csv gets the section's points (for a hyperplane its\n"
                    "crossings, t the crossing time) and the phase portrait draws them");
  RecordingOptions& output = options.output;
  c.add_option("--record", output.record, "Masses (1-based) whose trajectory to write")
      ->delimiter(',')
      ->check(positive_number());
  c.add_option("--trajectory-periods", output.trajectory_periods,
               "Write the trajectory of only the last N periods (0: every kept period)")
      ->check(non_negative_number());
  c.add_option("--title", output.title, "Title of the figure");
  c.add_option("--compare-with", options.compare.method,
               "Integrate the case again by this method, on the same time grid, and compare")
      ->check(CLI::IsMember(method_names()));
  c.add_option("--compare-tol", options.compare.tolerance,
               "Tolerance of the compared method (dopri5/rkf78)")
      ->check(positive_number());
  c.add_flag("--compare-locate-kinks", options.compare.locate_kinks,
             "The compared dopri5/rkf78 ends a step at every spring switch");
  c.add_option("--out", output.out, "Output folder");
  c.add_flag("--quiet", output.quiet, "Print nothing on success");
}

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand(
      "simulate",
      "Integrate one case of the nondimensional chain and write its Poincaré points\n"
      "Example: pwl simulate --figure 4a --periods 1000 --skip-periods 500 --record 5 --out fig4a\n"
      "         pwl simulate --figure 4a --record 5 --compare-with dopri5 --compare-tol 1e-10\n"
      "                      --compare-locate-kinks --out fig4a_checked\n"
      "         pwl simulate --figure 4a --section v5=0,down --x0 0.1 --record 5 --out fig4a_v5");
  add_simulate_flags(*c, *options);
  c->callback([options] { simulate(*options); });
}

}  // namespace pwl::app
