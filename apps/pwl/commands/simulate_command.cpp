// pwl simulate: integrate one case and write its stroboscopic Poincaré points, the trajectory of
// the requested masses, and a phase portrait.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "commands/case_options.hpp"
#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "commands/method_comparison.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

struct SimulateOptions {
  CaseOptions run;
  RecordingOptions output;
  ComparisonOptions compare;
};

void simulate(const SimulateOptions& options) {
  const GapStructure structure = options.run.structure();
  const Index n = structure.dofs();
  for (int r : options.output.record) {
    if (r < 1 || r > n) {
      throw InputError(fmt::format("--record {}: masses are numbered 1..{}", r, n));
    }
  }
  if (options.run.skip_periods >= options.run.periods) {
    throw InputError(fmt::format("--skip-periods = {} leaves nothing of --periods = {}",
                                 options.run.skip_periods, options.run.periods));
  }
  if (!options.compare.method.empty()) {
    simulate_with_comparison(options.run, options.compare, options.output);
    return;
  }
  const CaseOptions& run = options.run;
  const RecordingOptions& output = options.output;
  const double period = run.period();
  auto integrator = run.integrator(structure, period);
  std::filesystem::create_directories(output.out);

  CsvWriter poincare(output.out + "/poincare.csv", state_columns("t", n));
  std::unique_ptr<CsvWriter> trajectory;
  if (!output.record.empty()) {
    std::vector<std::string> columns{"t"};
    for (int r : output.record) columns.push_back(fmt::format("x{}", r));
    for (int r : output.record) columns.push_back(fmt::format("v{}", r));
    trajectory = std::make_unique<CsvWriter>(output.out + "/trajectory.csv", columns);
  }
  std::vector<double> row(1 + 2 * output.record.size());
  const StepObserver record = [&](double t, const Vector& x, const Vector& v) {
    row[0] = t;
    for (std::size_t j = 0; j < output.record.size(); ++j) {
      row[1 + j] = x[output.record[j] - 1];
      row[1 + output.record.size() + j] = v[output.record[j] - 1];
    }
    trajectory->row(row);
  };
  if (run.skip_periods == 0) poincare.row(0.0, integrator->position(), integrator->velocity());
  const int drawn_from =
      output.trajectory_periods > 0
          ? std::max(run.skip_periods, run.periods - output.trajectory_periods)
          : run.skip_periods;
  for (int k = 1; k <= run.periods; ++k) {
    const bool keep = k > run.skip_periods;
    integrator->advance_to(k * period, k > drawn_from && trajectory ? record : StepObserver());
    if (keep) poincare.row(integrator->time(), integrator->position(), integrator->velocity());
  }
  const IntegratorStats s = integrator->stats();
  if (!output.quiet) {
    fmt::print("{}: {} periods, {} steps, {} rejected, {} kink events, {} LCP pivots\n",
               integrator->name(), run.periods, s.steps, s.rejected_steps, s.kink_events,
               s.lcp_pivots);
    fmt::print("wrote {}/poincare.csv{}\n", output.out, trajectory ? " and trajectory.csv" : "");
  }
  if (trajectory) {
    trajectory.reset();
    const int mass = output.record.front();
    const auto definitions = [&](const std::string& format) {
      return fmt::format(
          "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/phase.{10}'; "
          "xcol={1}; vcol={2}; pxcol={3}; pvcol={4}; mass={5}; title={11}; "
          "label='{6}, {7}, {8} periods after {9}'",
          output.out, 2, 2 + output.record.size(), 1 + mass, 1 + n + mass, mass,
          integrator->name(), run.description(), run.periods - run.skip_periods, run.skip_periods,
          format, gnuplot_quoted(output.title));
    };
    draw_figure_and_report(scripts_directory() + "/phase_portrait.gp", definitions,
                           output.out + "/phase", "pwl simulate", output.quiet);
  }
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand(
      "simulate",
      "Integrate one case of the nondimensional chain and write its Poincaré points\n"
      "Example: pwl simulate --figure 4a --periods 1000 --skip-periods 500 --record 5 --out fig4a\n"
      "         pwl simulate --figure 4a --record 5 --compare-with dopri5 --compare-tol 1e-10\n"
      "                      --compare-locate-kinks --out fig4a_checked");
  add_case_options(*c, options->run);
  RecordingOptions& output = options->output;
  c->add_option("--record", output.record, "Masses (1-based) whose trajectory to write")
      ->delimiter(',');
  c->add_option("--trajectory-periods", output.trajectory_periods,
                "Write the trajectory of only the last N periods (0: every kept period)")
      ->check(non_negative_number());
  c->add_option("--title", output.title, "Title of the figure");
  c->add_option("--compare-with", options->compare.method,
                "Integrate the case again by this method, on the same time grid, and compare")
      ->check(CLI::IsMember(method_names()));
  c->add_option("--compare-tol", options->compare.tolerance,
                "Tolerance of the compared method (dopri5/rkf78)")
      ->check(positive_number());
  c->add_flag("--compare-locate-kinks", options->compare.locate_kinks,
              "The compared dopri5/rkf78 ends a step at every spring switch");
  c->add_option("--out", output.out, "Output folder");
  c->add_flag("--quiet", output.quiet, "Print nothing on success");
  c->callback([options] { simulate(*options); });
}

}  // namespace pwl::app
