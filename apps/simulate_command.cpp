// pwl simulate: integrate one case and write its stroboscopic Poincaré points, the trajectory of
// the requested masses, and a phase portrait.
#include <fmt/format.h>

#include <filesystem>
#include <memory>

#include "case_options.hpp"
#include "commands.hpp"
#include "csv_writer.hpp"
#include "gnuplot.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

struct SimulateOptions {
  CaseOptions run;
  std::vector<int> record{};
  std::string out = "out";
  bool quiet = false;
};

void simulate(const SimulateOptions& o) {
  const GapStructure structure = o.run.structure();
  const Index n = structure.dofs();
  for (int r : o.record) {
    if (r < 1 || r > n) {
      throw InputError(fmt::format("--record {}: masses are numbered 1..{}", r, n));
    }
  }
  if (o.run.skip_periods >= o.run.periods) {
    throw InputError(fmt::format("--skip-periods = {} leaves nothing of --periods = {}",
                                 o.run.skip_periods, o.run.periods));
  }
  const double period = o.run.period();
  auto integrator = o.run.integrator(structure, period);
  std::filesystem::create_directories(o.out);

  CsvWriter poincare(o.out + "/poincare.csv", state_columns("t", n));
  std::unique_ptr<CsvWriter> trajectory;
  if (!o.record.empty()) {
    std::vector<std::string> columns{"t"};
    for (int r : o.record) columns.push_back(fmt::format("x{}", r));
    for (int r : o.record) columns.push_back(fmt::format("v{}", r));
    trajectory = std::make_unique<CsvWriter>(o.out + "/trajectory.csv", columns);
  }
  std::vector<double> row(1 + 2 * o.record.size());
  const StepObserver record = [&](double t, const Vector& x, const Vector& v) {
    row[0] = t;
    for (std::size_t j = 0; j < o.record.size(); ++j) {
      row[1 + j] = x[o.record[j] - 1];
      row[1 + o.record.size() + j] = v[o.record[j] - 1];
    }
    trajectory->row(row);
  };
  if (o.run.skip_periods == 0) poincare.row(0.0, integrator->position(), integrator->velocity());
  for (int k = 1; k <= o.run.periods; ++k) {
    const bool keep = k > o.run.skip_periods;
    integrator->advance_to(k * period, keep && trajectory ? record : StepObserver());
    if (keep) poincare.row(integrator->time(), integrator->position(), integrator->velocity());
  }
  const IntegratorStats s = integrator->stats();
  if (!o.quiet) {
    fmt::print("{}: {} periods, {} steps, {} rejected, {} kink events, {} LCP pivots\n",
               integrator->name(), o.run.periods, s.steps, s.rejected_steps, s.kink_events,
               s.lcp_pivots);
    fmt::print("wrote {}/poincare.csv{}\n", o.out, trajectory ? " and trajectory.csv" : "");
  }
  if (trajectory) {
    trajectory.reset();
    const int mass = o.record.front();
    std::string why;
    const std::string definitions = fmt::format(
        "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/phase.png'; "
        "xcol={1}; vcol={2}; pxcol={3}; pvcol={4}; mass={5}; "
        "label='{6}, {7}, {8} periods after {9}'",
        o.out, 2, 2 + o.record.size(), 1 + mass, 1 + n + mass, mass, integrator->name(),
        o.run.description(), o.run.periods - o.run.skip_periods, o.run.skip_periods);
    if (run_gnuplot(plots_directory() + "/phase_portrait.gp", definitions, &why)) {
      if (!o.quiet) fmt::print("wrote {}/phase.png\n", o.out);
    } else {
      fmt::print(stderr, "pwl simulate: no figure: {}\n", why);
    }
  }
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto options = std::make_shared<SimulateOptions>();
  CLI::App* c = app.add_subcommand(
      "simulate",
      "Integrate one case of the nondimensional chain and write its Poincaré points\n"
      "Example: pwl simulate --figure 4a --periods 1000 --skip-periods 500 --record 5 --out fig4a");
  add_case_options(*c, options->run);
  c->add_option("--record", options->record, "Masses (1-based) whose trajectory to write")
      ->delimiter(',');
  c->add_option("--out", options->out, "Output folder");
  c->add_flag("--quiet", options->quiet, "Print nothing on success");
  c->callback([options] { simulate(*options); });
}

}  // namespace pwl::app
