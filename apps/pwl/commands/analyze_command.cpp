// pwl analyze: one case, integrated past its transient and classified from its stroboscopic
// Poincaré points, with the evidence used: the period search, λ1 and the 0-1 test.
//
// The motion is evaluated by the study pipeline (evaluate_point, pwl/study/sweep_point.hpp), the
// same that classifies every point of `pwl sweep` and `pwl map`, in analyze_case
// (analyze_command.hpp); the command line only adds its outputs through the pipeline's observer:
// trajectory.csv (the steps of the last 20 periods of the chosen mass), poincare.csv (the full
// state at every recorded point of the section), classification.csv, the figure and the printout.
// With the same settings a one-point sweep gives the same regime, period, λ1 and K.
#include "commands/analyze_command.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/step_guard_report.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

// What analyze writes beside the pipeline's numbers, fed by the pipeline as it integrates. The
// files are opened when the evaluation starts, once the flags have passed their checks.
class AnalyzeFiles : public analysis::PointObserver {
 public:
  AnalyzeFiles(const std::string& folder, int mass, int drawn_from)
      : folder_(folder), mass_(mass), drawn_from_(drawn_from) {}

  void started(const Integrator&, const analysis::PointCase& point) override {
    dofs_ = point.structure.dofs();
    if (mass_ == 0) mass_ = static_cast<int>(dofs_);
    std::filesystem::create_directories(folder_);
    poincare_ = std::make_unique<CsvWriter>(folder_ + "/poincare.csv", state_columns("t", dofs_));
    trajectory_ = std::make_unique<CsvWriter>(
        folder_ + "/trajectory.csv",
        std::vector<std::string>{"t", fmt::format("x{}", mass_), fmt::format("v{}", mass_)});
  }
  StepObserver steps_of_period(int k) override {
    // The last 20 periods of the record as set; adaptive evidence records more, not drawn.
    if (k <= drawn_from_ || k > drawn_from_ + 20) return {};
    return [this](double t, const Vector& x, const Vector& v) {
      trajectory_->row({t, x[mass_ - 1], v[mass_ - 1]});
    };
  }
  void poincare_point(int, double t, const Vector& state) override {
    poincare_->row(t, state.head(dofs_), state.tail(dofs_));
  }

 private:
  std::string folder_;
  int mass_;
  int drawn_from_;
  Index dofs_ = 0;
  std::unique_ptr<CsvWriter> poincare_;
  std::unique_ptr<CsvWriter> trajectory_;
};

// What analyze_case keeps of the evaluation, passing every hook on to `also`.
class AnalyzeCollector : public analysis::PointObserver {
 public:
  AnalyzeCollector(AnalyzeResult& result, analysis::PointObserver* also)
      : result_(result), also_(also) {}

  void started(const Integrator& integrator, const analysis::PointCase& point) override {
    result_.integrator = integrator.name();
    if (also_ != nullptr) also_->started(integrator, point);
  }
  StepObserver steps_of_period(int k) override {
    return also_ != nullptr ? also_->steps_of_period(k) : StepObserver();
  }
  void poincare_point(int k, double t, const Vector& state) override {
    result_.section_times.push_back(t);
    result_.section_periods.push_back(k);
    result_.section_states.insert(result_.section_states.end(), state.data(),
                                  state.data() + state.size());
    if (also_ != nullptr) also_->poincare_point(k, t, state);
  }
  void classified(const analysis::Classification& c, const analysis::PointResult& r) override {
    result_.classification = c;
    if (also_ != nullptr) also_->classified(c, r);
  }
  void checkpoint() override {
    if (also_ != nullptr) also_->checkpoint();
  }
  void stage_finished(std::string_view stage) override {
    const auto now = std::chrono::steady_clock::now();
    result_.stage_seconds.emplace_back(std::string(stage),
                                       std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  AnalyzeResult& result_;
  analysis::PointObserver* also_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
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

}  // namespace

AnalyzeResult analyze_case(const AnalyzeOptions& o, analysis::PointObserver* also) {
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
  guard_step(structure, s.method, period, o.run.force);
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
  s.section = o.section.poincare_section(n);
  o.ladder.apply(s);
  const Vector start = o.run.start.state(n);

  AnalyzeResult a;
  a.settings = s;
  a.dofs = n;
  a.mass = mass;
  a.period = period;
  const auto begin = std::chrono::steady_clock::now();
  AnalyzeCollector collector(a, also);
  a.result = analysis::evaluate_point(analysis::PointCase(structure, period), start, s, &collector);
  a.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return a;
}

namespace {

// The ladder's steps beyond the record: Newton's check of the period, the accurate method's
// confirmation, what the verdict was seen over, and what each stage cost.
void print_ladder(const AnalyzeResult& a) {
  const analysis::PointResult& r = a.result;
  if (r.minimal_period > 0 && std::isfinite(r.multiplier)) {
    std::string where = "the motion is on it";
    if (std::isfinite(r.settle_periods) && r.settle_periods > 0.0) {
      where = fmt::format("the motion approaches it, about {:.0f} more periods to reach it",
                          std::ceil(r.settle_periods));
    }
    fmt::print("  Newton: minimal period {}{}, leading |μ| = {:.6g} at that period; {}\n",
               r.minimal_period,
               r.record_period > 0 && r.record_period != r.minimal_period
                   ? fmt::format(" (the record's search said {})", r.record_period)
                   : std::string(),
               r.multiplier, where);
  } else if (r.disagreement.find("newton:not-confirmed") != std::string::npos) {
    fmt::print("  Newton: the record's period is not confirmed ({})\n", r.disagreement);
  }
  if ((r.regime == "quasi-periodic" || r.regime == "uncertain") && a.settings.refine_max_period > 0 &&
      a.dofs > analysis::PointSettings::kRefinedMasses) {
    fmt::print("  orbit refinement: not run for n = {} > {} masses (`pwl orbit --period K` finds "
               "an orbit of a given period)\n",
               a.dofs, analysis::PointSettings::kRefinedMasses);
  }
  if (!r.confirmed_by.empty()) {
    fmt::print("  confirmed by the {} method ({}); the verdict rests on {}\n", r.confirmed_by,
               r.confirmation == "newton" ? "Newton on its map at the same period"
                                          : "its own motion from the same start",
               r.decided_by);
  } else if (!r.decided_by.empty()) {
    fmt::print("  the verdict rests on {}\n", r.decided_by);
  }
  if (r.observed_periods > 0) {
    fmt::print("  seen over {} periods{}{}{}\n", r.observed_periods,
               r.extra_periods > 0 ? fmt::format(" ({} of them adaptive evidence)", r.extra_periods)
                                   : std::string(),
               r.halves.empty() ? std::string()
                                : fmt::format("; the two halves of the record: {}", r.halves),
               r.rotation_pq.empty() ? std::string()
                                     : fmt::format("; rotation {}", r.rotation_pq));
  }
  if (!a.stage_seconds.empty()) {
    std::string stages;
    for (const auto& [stage, seconds] : a.stage_seconds) {
      if (seconds < 0.0005) continue;
      stages += fmt::format("{}{} {:.3g} s", stages.empty() ? "" : ", ", stage, seconds);
    }
    fmt::print("  cost: {:.3g} s ({}){}\n", a.seconds, stages,
               a.settings.ladder_on() ? "" : "; --quick: the plain record");
  }
}

}  // namespace

void analyze(const AnalyzeOptions& o) {
  AnalyzeResult a;
  {  // the files close at the end of this block, before gnuplot reads them
    AnalyzeFiles files(o.out, o.mass, o.run.periods - 20);
    a = analyze_case(o, &files);
  }
  const analysis::PointResult& result = a.result;
  const std::optional<analysis::Classification>& c = a.classification;
  const analysis::PointSettings& s = a.settings;
  const MethodTraits& method = method_traits(s.method.method);
  const Index n = a.dofs;
  const int mass = a.mass;
  const double period = a.period;
  const int recorded = s.recorded_periods;
  const std::string& integrator_name = a.integrator;
  // The section and the start are said only when they are not the defaults, so that a default
  // run prints and draws what it always has.
  const std::string start = o.run.start.description();
  if (s.section.is_default()) {
    fmt::print("case: n = {}, {}{}; {} Poincaré points after {} transient periods, by {}\n", n,
               o.run.description(), start, recorded, o.transient, integrator_name);
  } else {
    analysis::PoincareSection strobe;  // the stroboscopic points classified, at the phase
    strobe.phase = s.section.phase;
    fmt::print("case: n = {}, {}{}; {} stroboscopic points at {} after {} transient periods, by "
               "{}\n",
               n, o.run.description(), start, recorded, strobe.label(n), o.transient,
               integrator_name);
    if (!s.section.stroboscopic()) {
      fmt::print("section: {} crossings of {} in the recorded periods (poincare.csv and the "
                 "figure); the regime is that of the stroboscopic points\n",
                 a.section_times.size(), s.section.label(n));
    }
  }
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
             estimate_description(s.lyapunov_estimate,
                                  result.confirmation == "motion"
                                      ? std::string(method_traits(parse_method(result.decided_by)).label)
                                      : std::string(method.label)));
  fmt::print("  0-1 test: K = {:.3f}\n", result.K);
  if (std::isfinite(result.torus_digits)) {
    fmt::print("  torus test: {:.2f} digits (weighted Birkhoff averages of the record's halves; a "
               "smooth invariant curve scores 5 or more), rotation number {:.6f} turns per period\n",
               result.torus_digits, result.rotation);
  }
  fmt::print("  rule: {}\n",
             c ? c->reason
               : std::string(result.regime == "unbounded"
                                 ? "the motion left the divergence bound before the record ended"
                                 : "a contact problem (LCP) had no solution"));
  if (result.chaotic_transient > 0) {
    fmt::print("  transient chaos: the motion wandered chaotically for its first {} periods (finite-"
               "time λ1 > 0 along them), then settled on its period-{} orbit\n",
               result.chaotic_transient, result.period);
  }
  print_ladder(a);
  if (std::FILE* f = std::fopen((o.out + "/classification.csv").c_str(), "w")) {
    // The record's five columns, then the ladder's (sweep_point.hpp says what each is).
    const auto real = [](double x) { return std::isnan(x) ? std::string() : fmt::format("{:.10g}", x); };
    fmt::print(f,
               "regime,period,lambda1_per_period,lambda1_error,K,minimal_period,multiplier,"
               "settle_periods,record_period,decided_by,confirmation,observed_periods,halves,"
               "rotation_pq,chaotic_transient\n"
               "{},{},{:.10g},{:.3g},{:.6g},{},{},{},{},{},{},{},{},{},{}\n",
               result.regime, result.period, result.lambda1, result.lambda1_error, result.K,
               result.minimal_period, real(result.multiplier), real(result.settle_periods),
               result.record_period, result.decided_by, result.confirmation,
               result.observed_periods, result.halves, result.rotation_pq,
               result.chaotic_transient);
    std::fclose(f);
  }
  std::string why;
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "trajectory='{0}/trajectory.csv'; poincare='{0}/poincare.csv'; out='{0}/analysis.{6}'; "
        "pxcol={1}; pvcol={2}; mass={3}; label='{4}: {5}'",
        o.out, 1 + mass, 1 + n + mass, mass,
        o.run.description() + start +
            (s.section.is_default() ? std::string()
                                    : fmt::format(", Poincaré section {}", s.section.label(n))),
        result.regime, format) +
           (s.section.is_default()
                ? std::string()
                : fmt::format("; ptitle={}",
                              gnuplot_quoted(fmt::format(
                                  "Poincaré section ({}, {})", s.section.label(n),
                                  s.section.stroboscopic() ? "every recorded period"
                                                           : "every crossing recorded"))));
  };
  if (draw_figure(scripts_directory() + "/analysis_panels.gp", definitions, &why)) {
    fmt::print("wrote {0}/poincare.csv, {0}/classification.csv, {0}/analysis.png and .svg\n",
               o.out);
  } else {
    fmt::print(stderr, "pwl analyze: no figure: {}\n", why);
  }
}

void add_analyze_flags(CLI::App& c, AnalyzeOptions& options) {
  add_case_options(c, options.run);
  // The analysis leaves out --transient periods, not --skip-periods: one flag for one thing.
  c.remove_option(c.get_option("--skip-periods"));
  add_section_flags(c, options.section,
                    "poincare.csv and the figure's Poincaré panel get the section's\n"
                    "points of the recorded periods");
  c.add_option("--transient", options.transient, "Periods discarded before the analysis")
      ->check(non_negative_number());
  c.add_option("--mass", options.mass,
               "Mass (1-based) drawn in the figure and read by the 0-1 test (0: the last)")
      ->check(non_negative_number());
  c.add_option("--lyapunov", options.lyapunov,
               "How λ1 is estimated: tangent-vector, tangent-frame or two-trajectories\n"
               "(default, as pwl sweep and map: tangent-vector when the method has an exact\n"
               "tangent map, else two-trajectories)")
      ->check(CLI::IsMember({"tangent-vector", "tangent-frame", "two-trajectories"}));
  add_ladder_flags(c, options.ladder);
  c.add_option("--out", options.out, "Output folder");
}

void add_analyze_command(CLI::App& app) {
  auto options = std::make_shared<AnalyzeOptions>();
  CLI::App* c = app.add_subcommand(
      "analyze",
      "Classify the motion of one case (period-k, quasi-periodic, chaotic) with its evidence\n"
      "Example: pwl analyze --figure 5 --periods 1000 --transient 500 --out fig5\n"
      "         pwl analyze --figure 5 --section v5=0,down --out fig5_v5");
  add_analyze_flags(*c, *options);
  c->callback([options] { analyze(*options); });
}

}  // namespace pwl::app
