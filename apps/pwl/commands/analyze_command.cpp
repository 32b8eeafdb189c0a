// pwl analyze: one case, integrated past its transient and classified from its stroboscopic
// Poincaré points, with the evidence used: the period search, λ1 and the 0-1 test.
//
// The motion is evaluated by the study pipeline (evaluate_point, pwl/study/sweep_point.hpp), the
// same that classifies every point of `pwl sweep` and `pwl map`; analyze only adds its outputs
// through the pipeline's observer: trajectory.csv (the steps of the last 20 periods of the chosen
// mass), poincare.csv (the full state at every recorded period), classification.csv, the figure
// and the printout. With the same settings a one-point sweep gives the same regime, period, λ1 and
// K.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands/case_options.hpp"
#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/sweep_point.hpp"

namespace pwl::app {
namespace {

struct AnalyzeOptions {
  CaseOptions run;
  int transient = 500;  // periods discarded
  int mass = 0;         // 1-based mass for the figure and the 0-1 test; 0: the last one
  // How λ1 is estimated; empty: from the whole tangent frame when the method has an exact tangent
  // map, else from two nearby trajectories.
  std::string lyapunov;
  std::string out = "out";
};

// What analyze writes beside the pipeline's numbers, fed by the pipeline as it integrates.
class AnalyzeOutputs : public analysis::PointObserver {
 public:
  AnalyzeOutputs(const std::string& folder, Index dofs, int mass, int drawn_from)
      : poincare_(folder + "/poincare.csv", state_columns("t", dofs)),
        trajectory_(folder + "/trajectory.csv",
                    {"t", fmt::format("x{}", mass), fmt::format("v{}", mass)}),
        dofs_(dofs),
        mass_(mass),
        drawn_from_(drawn_from) {}

  void started(const Integrator& integrator, const analysis::PointCase&) override {
    integrator_name_ = integrator.name();
  }
  StepObserver steps_of_period(int k) override {
    if (k <= drawn_from_) return {};
    return [this](double t, const Vector& x, const Vector& v) {
      trajectory_.row({t, x[mass_ - 1], v[mass_ - 1]});
    };
  }
  void poincare_point(int, double t, const Vector& state) override {
    poincare_.row(t, state.head(dofs_), state.tail(dofs_));
  }
  void classified(const analysis::Classification& c, const analysis::PointResult&) override {
    classification_ = c;
  }

  const std::string& integrator_name() const { return integrator_name_; }
  const std::optional<analysis::Classification>& classification() const {
    return classification_;
  }

 private:
  CsvWriter poincare_;
  CsvWriter trajectory_;
  Index dofs_;
  int mass_;
  int drawn_from_;
  std::string integrator_name_;
  std::optional<analysis::Classification> classification_;
};

std::string estimate_description(analysis::LyapunovEstimate estimate, const std::string& label) {
  switch (estimate) {
    case analysis::LyapunovEstimate::tangent_vector:
      return fmt::format("exact tangent map of the {} step, one renormalised tangent vector",
                         label);
    case analysis::LyapunovEstimate::tangent_frame:
      return fmt::format("exact tangent map of the {} step, QR method", label);
    case analysis::LyapunovEstimate::two_trajectories:
      return "two nearby trajectories";
  }
  return "";
}

void analyze(const AnalyzeOptions& o) {
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

  analysis::PointSettings s;
  s.transient_periods = o.transient;
  s.recorded_periods = recorded;
  s.method = o.run.method_settings(period);
  const MethodTraits& method = method_traits(s.method.method);
  if (method.fixed_grid) s.steps_per_period = static_cast<int>(std::lround(period / s.method.step));
  s.observable = mass - 1;  // the 0-1 test reads x of the drawn mass
  if (o.lyapunov.empty()) {
    s.lyapunov_estimate = analysis::default_lyapunov_estimate(s.method.method);
  } else {
    s.lyapunov_estimate = analysis::parse_lyapunov_estimate(o.lyapunov);
    if (s.lyapunov_estimate != analysis::LyapunovEstimate::two_trajectories &&
        !method.tangent_map) {
      throw InputError(fmt::format(
          "--lyapunov {}: {} has no exact tangent map; use two-trajectories", o.lyapunov,
          method.name));
    }
  }

  std::filesystem::create_directories(o.out);
  analysis::PointResult result;
  std::string integrator_name;
  std::optional<analysis::Classification> c;
  {
    AnalyzeOutputs outputs(o.out, n, mass, o.run.periods - 20);
    result = analysis::evaluate_point(analysis::PointCase(structure, period),
                                      Vector::Zero(2 * n), s, &outputs);
    integrator_name = outputs.integrator_name();
    c = outputs.classification();
  }

  fmt::print("case: n = {}, {}; {} Poincaré points after {} transient periods, by {}\n", n,
             o.run.description(), recorded, o.transient, integrator_name);
  fmt::print("regime: {}\n", result.regime);
  if (c) {
    fmt::print("  period search: {} (best k = {}, mismatch {:.2e}, {} distinct points)\n",
               c->period_search.period > 0 ? fmt::format("period {}", c->period_search.period)
                                           : std::string("no period"),
               c->period_search.best_k, c->period_search.mismatch,
               c->period_search.distinct_points);
  }
  fmt::print("  lambda1: {:.5f} ± {:.1e} per period, {:.5f} per unit time ({})\n", result.lambda1,
             result.lambda1_error, result.lambda1 / period,
             estimate_description(s.lyapunov_estimate, std::string(method.label)));
  fmt::print("  0-1 test: K = {:.3f}\n", result.K);
  fmt::print("  rule: {}\n",
             c ? c->reason
               : std::string(result.regime == "unbounded"
                                 ? "the motion left the divergence bound before the record ended"
                                 : "a contact problem (LCP) had no solution"));
  if (std::FILE* f = std::fopen((o.out + "/classification.csv").c_str(), "w")) {
    fmt::print(f, "regime,period,lambda1_per_period,lambda1_error,K\n{},{},{:.10g},{:.3g},{:.6g}\n",
               result.regime, c ? c->period : 0, result.lambda1, result.lambda1_error, result.K);
    std::fclose(f);
  }
  std::string why;
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/analysis.{6}'; "
        "pxcol={1}; pvcol={2}; mass={3}; label='{4}: {5}'",
        o.out, 1 + mass, 1 + n + mass, mass, o.run.description(), result.regime, format);
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
  c->add_option("--mass", options->mass,
                "Mass (1-based) drawn in the figure and read by the 0-1 test (default: last)");
  c->add_option("--lyapunov", options->lyapunov,
                "How λ1 is estimated: tangent-vector, tangent-frame or two-trajectories\n"
                "(default, as pwl sweep and map: tangent-vector when the method has an exact\n"
                "tangent map, else two-trajectories)")
      ->check(CLI::IsMember({"tangent-vector", "tangent-frame", "two-trajectories"}));
  c->add_option("--out", options->out, "Output folder");
  c->callback([options] { analyze(*options); });
}

}  // namespace pwl::app
