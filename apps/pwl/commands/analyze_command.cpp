// pwl analyze: integrate one case past its transient, then classify the motion from its
// stroboscopic Poincaré points with the evidence used: the period search, the Lyapunov spectrum
// (exact tangent map for the PIM; two nearby trajectories for dopri5/rkf78) and the 0-1 test.
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <span>

#include "commands/cli_checks.hpp"
#include "commands/case_options.hpp"
#include "commands/commands.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/analysis/lyapunov.hpp"
#include "pwl/analysis/motion_classifier.hpp"
#include "pwl/analysis/zero_one_test.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

struct AnalyzeOptions {
  CaseOptions run;
  int transient = 500;  // periods discarded
  int mass = 0;         // 1-based mass for the figure; 0: the last one
  std::string out = "out";
};

void analyze(AnalyzeOptions o) {
  const GapStructure structure = o.run.structure();
  const Index n = structure.dofs();
  const int mass = o.mass == 0 ? static_cast<int>(n) : o.mass;
  if (mass < 1 || mass > n) {
    throw InputError(fmt::format("--mass {}: masses are numbered 1..{}", mass, n));
  }
  const int recorded = o.run.periods - o.transient;
  if (recorded < 100) {
    throw InputError(fmt::format(
        "--periods = {} with --transient = {} records {} periods; the analysis needs at least 100",
        o.run.periods, o.transient, recorded));
  }
  const double period = o.run.period();
  auto integrator = o.run.integrator(structure, period);
  const bool exact_tangent = integrator->has_tangent_map();
  integrator->advance_to(o.transient * period);

  std::filesystem::create_directories(o.out);
  std::vector<Vector> points;
  std::vector<Matrix> jacobians;
  {
    CsvWriter poincare(o.out + "/poincare.csv", state_columns("t", n));
    CsvWriter trajectory(o.out + "/trajectory.csv",
                         {"t", fmt::format("x{}", mass), fmt::format("v{}", mass)});
    const int drawn_from = o.run.periods - 20;
    for (int k = o.transient + 1; k <= o.run.periods; ++k) {
      const StepObserver draw = [&](double t, const Vector& x, const Vector& v) {
        trajectory.row({t, x[mass - 1], v[mass - 1]});
      };
      const StepObserver& observer = k > drawn_from ? draw : StepObserver();
      if (exact_tangent) {
        Matrix tangent = Matrix::Identity(2 * n, 2 * n);
        integrator->advance_with_tangent(k * period, tangent, observer);
        jacobians.push_back(std::move(tangent));
      } else {
        integrator->advance_to(k * period, observer);
      }
      Vector state(2 * n);
      state << integrator->position(), integrator->velocity();
      poincare.row(integrator->time(), integrator->position(), integrator->velocity());
      points.push_back(std::move(state));
    }
  }

  // λ1 per forcing period and per unit (nondimensional) time.
  analysis::LyapunovResult lyapunov;
  std::string lyapunov_method;
  if (exact_tangent) {
    analysis::LyapunovOptions l;
    l.transient = std::min<long>(50, recorded / 5);
    l.iterations = static_cast<long>(jacobians.size()) - l.transient;
    l.time_per_iteration = period;
    lyapunov = analysis::lyapunov_spectrum(jacobians, l);
    lyapunov_method = "exact tangent map of the PIM step, QR method";
  } else {
    auto shadow = o.run.integrator(structure, period);
    const analysis::StateMap map = [&](const Vector& s) {
      shadow->set_state(0.0, s.head(n), s.tail(n));  // the loads are T-periodic
      shadow->advance_to(period);
      Vector image(2 * n);
      image << shadow->position(), shadow->velocity();
      return image;
    };
    analysis::TwoTrajectoryOptions l;
    l.transient = std::min<long>(50, recorded / 5);
    l.iterations = recorded - l.transient;
    l.time_per_iteration = period;
    l.separation = 1e-7;
    lyapunov = analysis::largest_lyapunov_two_trajectories(map, points.front(), l);
    lyapunov_method = "two nearby trajectories";
  }
  std::vector<double> observable;
  for (const Vector& p : points) observable.push_back(p[mass - 1]);
  const analysis::ZeroOneResult zero_one = analysis::zero_one_test(observable);
  analysis::MotionEvidence evidence;
  evidence.lyapunov = lyapunov.largest();
  evidence.lyapunov_error = lyapunov.error[0];
  evidence.zero_one_K = zero_one.K;
  analysis::ClassifierOptions classifier;
  classifier.fixed_point_is_equilibrium = false;  // stroboscopic points: a fixed point is period-1
  const analysis::Classification c = analysis::classify_motion(points, evidence, classifier);

  fmt::print("case: n = {}, {}; {} Poincaré points after {} transient periods, by {}\n", n,
             o.run.description(), recorded, o.transient, integrator->name());
  fmt::print("regime: {}\n", c.name());
  fmt::print("  period search: {} (best k = {}, mismatch {:.2e}, {} distinct points)\n",
             c.period_search.period > 0 ? fmt::format("period {}", c.period_search.period)
                                        : std::string("no period"),
             c.period_search.best_k, c.period_search.mismatch, c.period_search.distinct_points);
  fmt::print("  lambda1: {:.5f} ± {:.1e} per period, {:.5f} per unit time ({})\n",
             lyapunov.largest(), lyapunov.error[0], lyapunov.largest_per_unit_time(),
             lyapunov_method);
  fmt::print("  0-1 test: K = {:.3f}\n", zero_one.K);
  fmt::print("  rule: {}\n", c.reason);
  if (std::FILE* f = std::fopen((o.out + "/classification.csv").c_str(), "w")) {
    fmt::print(f, "regime,period,lambda1_per_period,lambda1_error,K\n{},{},{:.10g},{:.3g},{:.6g}\n",
               c.name(), c.period, lyapunov.largest(), lyapunov.error[0], zero_one.K);
    std::fclose(f);
  }
  std::string why;
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/analysis.{6}'; "
        "pxcol={1}; pvcol={2}; mass={3}; label='{4}: {5}'",
        o.out, 1 + mass, 1 + n + mass, mass, o.run.description(), c.name(), format);
  };
  if (draw_figure(scripts_directory() + "/analysis_panels.gp", definitions, &why)) {
    fmt::print("wrote {0}/poincare.csv, {0}/classification.csv, {0}/analysis.png and .svg\n",
               o.out);
  } else {
    fmt::print(stderr, "pwl analyze: no figure: {}\n", why);
  }
}

}  // namespace

void add_analyze_command(CLI::App& app) {
  auto options = std::make_shared<AnalyzeOptions>();
  CLI::App* c = app.add_subcommand(
      "analyze",
      "Classify the motion of one case (period-k, quasi-periodic, chaotic) with its evidence\n"
      "Example: pwl analyze --figure 5 --periods 1000 --transient 500 --out fig5");
  add_case_options(*c, options->run);
  c->add_option("--transient", options->transient, "Periods discarded before the analysis")
      ->check(non_negative_number());
  c->add_option("--mass", options->mass, "Mass (1-based) drawn in the figure (default: last)");
  c->add_option("--out", options->out, "Output folder");
  c->callback([options] { analyze(*options); });
}

}  // namespace pwl::app
