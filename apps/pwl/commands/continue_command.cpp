// pwl continue: a periodic orbit followed in one parameter by pseudo-arclength continuation, its
// stability along the way and its bifurcations located (fold, period doubling, Neimark–Sacker,
// grazing), optionally onto the period-doubled branches (analysis/include/pwl/orbits/
// continuation.hpp). Writes as the branch grows, so that an interrupted run keeps its points; draws
// the frequency response, and with --over-sweep the brute-force bifurcation diagram of the same
// range with the branches over it.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/continue_command.hpp"
#include "commands/curve_outputs.hpp"
#include "commands/flag_relations.hpp"
#include "commands/orbit_options.hpp"
#include "commands/step_guard_report.hpp"
#include "commands/study_runner.hpp"
#include "commands/sweep_command.hpp"
#include "output/gnuplot.hpp"
#include "output/csv_writer.hpp"
#include "output/progress_line.hpp"
#include "parallel/stop_signals.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/continuation.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::app {
namespace {

constexpr int kAllDofsUpTo = 10;  // --record's default: every mass up to this many, else the last

// The masses --record names (1-based "5" or "x5"), 0-based; the default when empty.
std::vector<int> recorded_dofs(const std::vector<std::string>& record, int n) {
  std::vector<int> dofs;
  for (const std::string& name : record) {
    const char* digits = name.c_str() + (name.size() > 1 && name[0] == 'x' ? 1 : 0);
    char* end = nullptr;
    const long i = std::strtol(digits, &end, 10);
    if (*digits == '\0' || *end != '\0' || i < 1 || i > n) {
      throw InputError(fmt::format("--record {}: name a mass 1..{} (or x1..x{})", name, n, n));
    }
    if (std::find(dofs.begin(), dofs.end(), static_cast<int>(i - 1)) == dofs.end()) {
      dofs.push_back(static_cast<int>(i - 1));
    }
  }
  if (record.empty()) {
    if (n <= kAllDofsUpTo) {
      for (int i = 0; i < n; ++i) dofs.push_back(i);
    } else {
      dofs.push_back(n - 1);
    }
  }
  return dofs;
}

// Appends ",field" to a CSV row.
void add_field(std::string& row, const std::string& field) {
  row += ',';
  row += field;
}


// What the continuation writes as it goes, and its progress on standard error.
class ContinueOutputs : public orbits::ContinuationObserver {
 public:
  ContinueOutputs(const std::string& folder, const analysis::PointModel& model,
                  const analysis::SweepParameter& parameter, const OrbitMethod& method,
                  std::vector<int> dofs, bool progress)
      : folder_(folder),
        model_(model),
        parameter_(parameter),
        method_(method),
        dofs_(std::move(dofs)),
        n_(model.dofs()),
        branch_(folder + "/branch.csv", branch_columns()),
        section_(folder + "/branch_section.csv", section_columns()),
        bifurcations_(folder + "/bifurcations.csv", bifurcation_columns()),
        progress_(progress) {}

  std::vector<std::string> branch_columns() const {
    std::vector<std::string> c{"branch", "parameter", "period", "stable", "max_abs_multiplier"};
    for (int i : dofs_) c.push_back(fmt::format("amplitude_x{}", i + 1));
    for (int i : dofs_) c.push_back(fmt::format("x{}", i + 1));
    c.push_back("unstable_multipliers");
    return c;
  }
  std::vector<std::string> section_columns() const {
    std::vector<std::string> c{"parameter", "branch", "period", "stable", "iterate"};
    for (int i : dofs_) c.push_back(fmt::format("x{}", i + 1));
    for (int i : dofs_) c.push_back(fmt::format("v{}", i + 1));
    return c;
  }
  static std::vector<std::string> bifurcation_header() {
    return {"type",          "parameter",     "branch",         "period", "spring",
            "multiplier_re", "multiplier_im", "abs_multiplier", "detail"};
  }
  std::vector<std::string> bifurcation_columns() const {
    std::vector<std::string> c = bifurcation_header();
    for (int i : dofs_) c.push_back(fmt::format("amplitude_x{}", i + 1));
    for (int i : dofs_) c.push_back(fmt::format("x{}", i + 1));
    return c;
  }

  void point(const orbits::BranchPoint& p) override {
    const orbits::PeriodicOrbit& orbit = p.orbit;
    const bool stable = orbit.stable();
    std::string row = fmt::format("{},{},{},{},{}", p.branch, full_precision(p.parameter), orbit.period,
                                  stable ? 1 : 0, full_precision(orbit.multipliers.largest_modulus()));
    for (int i : dofs_) add_field(row, full_precision(p.profile.amplitude(i)));
    for (int i : dofs_) add_field(row, full_precision(orbit.state(i)));
    row += fmt::format(",{}", orbit.multipliers.unstable_count());
    branch_.row(row);
    // The k Poincaré points of a period-k orbit: its state and k - 1 returns of the map.
    Vector y = orbit.state;
    std::unique_ptr<orbits::StroboscopicMap> map;
    for (int j = 0; j < orbit.period; ++j) {
      if (j > 0) {
        if (!map) map = map_at(p.parameter);
        y = map->advance(y, 1, j - 1);
      }
      std::string s = fmt::format("{},{},{},{},{}", full_precision(p.parameter), p.branch, orbit.period,
                                  stable ? 1 : 0, j);
      for (int i : dofs_) add_field(s, full_precision(y(i)));
      for (int i : dofs_) add_field(s, full_precision(y(n_ + i)));
      section_.row(s);
    }
    ++points_;
    ++per_branch_[p.branch];
    if (stable) ++stable_[p.branch];
    const auto [at, first] = range_.try_emplace(p.branch, p.parameter, p.parameter);
    if (!first) {
      at->second.first = std::min(at->second.first, p.parameter);
      at->second.second = std::max(at->second.second, p.parameter);
    }
    period_[p.branch] = orbit.period;
    if (points_ == 1) {
      first_residual_ = orbit.residual;
      first_iterations_ = orbit.iterations;
    }
    show(p);
    stop_on_signal(folder_);
  }

  void bifurcation(const orbits::Bifurcation& b) override {
    bifurcations_.row(bifurcation_row(b));
  }

  // bifurcations.csv again from the final list (a period doubling learns which branch it started
  // only once the switch is made).
  void rewrite_bifurcations(const std::string& folder,
                            const std::vector<orbits::Bifurcation>& all) {
    FlushedCsv csv(folder + "/bifurcations.csv", bifurcation_columns());
    for (const orbits::Bifurcation& b : all) csv.row(bifurcation_row(b));
  }

  void finish_progress() { progress_.finish(); }

  // Newton on the first orbit, before any point (minutes for a chain of 10^4 masses).
  void newton(int iteration, double residual, long products) {
    if (points_ > 0 || !progress_.due(iteration == 0)) return;
    progress_.show(newton_progress_text("continue: the first orbit", iteration, residual, products,
                                        progress_.seconds()));
  }

  long points() const { return points_; }
  const std::map<int, long>& per_branch() const { return per_branch_; }
  const std::map<int, long>& stable() const { return stable_; }
  const std::map<int, std::pair<double, double>>& range() const { return range_; }
  const std::map<int, int>& period() const { return period_; }
  double first_residual() const { return first_residual_; }
  int first_iterations() const { return first_iterations_; }

 private:
  std::unique_ptr<orbits::StroboscopicMap> map_at(double p) const {
    return std::make_unique<orbits::StroboscopicMap>(model_.with(parameter_, p).point_case(),
                                                     method_.settings, method_.steps_per_period);
  }

  std::string bifurcation_row(const orbits::Bifurcation& b) {
    const bool grazing = b.type == orbits::BifurcationType::grazing;
    std::string row = fmt::format("{},{},{},{},{}", orbits::bifurcation_name(b.type),
                                  full_precision(b.parameter), b.branch, b.period,
                                  grazing ? fmt::format("{}", b.spring + 1) : std::string());
    if (grazing) {
      row += ",,,";
    } else {
      row += fmt::format(",{},{},{}", full_precision(b.multiplier.real()), full_precision(b.multiplier.imag()),
                         full_precision(std::abs(b.multiplier)));
    }
    add_field(row, bifurcation_detail(b));
    // The amplitudes of the orbit there, for the figure's marks.
    const auto cached = amplitudes_.find(b.parameter);
    if (cached == amplitudes_.end()) {
      Vector amplitude = Vector::Constant(n_, std::numeric_limits<double>::quiet_NaN());
      try {
        auto map = map_at(b.parameter);
        amplitude = orbits::orbit_profile(*map, b.state, b.period).amplitude;
      } catch (const Error&) {
        // left empty: the mark is not drawn
      }
      amplitudes_.emplace(b.parameter, amplitude);
    }
    const Vector& amplitude = amplitudes_.at(b.parameter);
    for (int i : dofs_) {
      add_field(row, std::isfinite(amplitude(i)) ? full_precision(amplitude(i)) : std::string());
    }
    // Its state at t = 0 mod T, one of its Poincaré points, for the marks over the diagram.
    for (int i : dofs_) add_field(row, full_precision(b.state(i)));
    return row;
  }

  void show(const orbits::BranchPoint& p) {
    if (!progress_.due(points_ <= 1)) return;
    progress_.show(fmt::format("continue: {} points, branch {} (period {}), {} = {:.6g}, {:.1f} s",
                               points_, p.branch, p.orbit.period, parameter_.name(), p.parameter,
                               progress_.seconds()));
  }

  std::string folder_;
  const analysis::PointModel& model_;
  analysis::SweepParameter parameter_;
  OrbitMethod method_;
  std::vector<int> dofs_;
  Index n_;
  FlushedCsv branch_;
  FlushedCsv section_;
  FlushedCsv bifurcations_;
  ProgressLine progress_;
  long points_ = 0;
  std::map<int, long> per_branch_, stable_;
  std::map<int, std::pair<double, double>> range_;
  std::map<int, int> period_;
  std::map<double, Vector> amplitudes_;
  double first_residual_ = 0.0;
  int first_iterations_ = 0;
};

void print_bifurcations(const std::vector<orbits::Bifurcation>& all, const std::string& name) {
  if (all.empty()) {
    fmt::print("bifurcations: none found\n");
    return;
  }
  fmt::print("bifurcations ({}):\n", all.size());
  fmt::print("  {:<16} {:>14} {:>6} {:>6} {:>6}  {:<26} {:>10}  {}\n", "type", name, "branch",
             "period", "spring", "multiplier", "|μ|", "detail");
  for (const orbits::Bifurcation& b : all) {
    const bool grazing = b.type == orbits::BifurcationType::grazing;
    fmt::print("  {:<16} {:>14.10g} {:>6} {:>6} {:>6}  {:<26} {:>10}  {}\n",
               orbits::bifurcation_name(b.type), b.parameter, b.branch, b.period,
               grazing ? fmt::format("{}", b.spring + 1) : std::string("-"),
               grazing ? std::string("-") : multiplier_text(b.multiplier),
               grazing ? std::string("-") : fmt::format("{:.6f}", std::abs(b.multiplier)),
               bifurcation_detail(b));
  }
}

// How many of each kind were found, as gnuplot definitions, so that a figure's legend names only
// the kinds found.
std::string bifurcation_counts(const std::vector<orbits::Bifurcation>& found) {
  std::map<orbits::BifurcationType, int> kinds;
  for (const orbits::Bifurcation& b : found) ++kinds[b.type];
  return fmt::format(
      "nfold = {}; ndoubling = {}; nns = {}; ngrazing = {}; ", kinds[orbits::BifurcationType::fold],
      kinds[orbits::BifurcationType::period_doubling],
      kinds[orbits::BifurcationType::neimark_sacker], kinds[orbits::BifurcationType::grazing]);
}

void draw_frequency_response(const ContinueFlags& f, const ContinueOutputs& outputs,
                             const std::vector<orbits::Bifurcation>& found,
                             const std::vector<int>& dofs, const analysis::SweepParameter& parameter,
                             bool chain, const std::string& title) {
  const std::string& out = f.orbit.out;
  const int plotted = static_cast<int>(dofs.size());  // the last recorded mass's amplitude
  std::string periods;
  int last_branch = 0;
  for (const auto& [branch, period] : outputs.period()) {
    periods += fmt::format("bp{} = {}; ", branch, period);
    last_branch = std::max(last_branch, branch);
  }
  const std::string counts = bifurcation_counts(found);
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "branch='{0}/branch.csv'; bifurcations='{0}/bifurcations.csv'; out='{0}/"
        "frequency_response.{1}'; ycolumn={2}; bcolumn={3}; branches={4}; {5}xname={6}; "
        "yname={7}; title={8}",
        out, format, 5 + plotted, 9 + plotted, last_branch + 1, periods + counts,
        gnuplot_quoted(parameter_label(parameter)),
        gnuplot_quoted(fmt::format("amplitude max |x_{{{}}}(t)| over the orbit{}", dofs.back() + 1,
                                   chain ? " (nondimensional)" : "")),
        gnuplot_quoted(title));
  };
  draw_figure_and_report(scripts_directory() + "/frequency_response.gp", definitions,
                         out + "/frequency_response", "pwl continue", false);
}

void run_over_sweep(const ContinueFlags& f, const analysis::PointModel& model,
                    const analysis::SweepParameter& parameter, const OrbitMethod& method,
                    double from, double to, const std::vector<int>& dofs,
                    const std::vector<orbits::Bifurcation>& found, const std::string& title) {
  const int dof = dofs.back();  // the figures draw the last recorded mass
  analysis::SweepOptions o;
  if (model.explicit_structure()) {
    o.structure = model.structure();
  } else {
    o.chain = model.chain();
  }
  o.parameter = parameter;
  o.from = std::min(from, to);
  o.to = std::max(from, to);
  o.points = f.over_sweep;
  o.mode = analysis::SweepMode::continuation;
  const int n = model.dofs();
  o.point.transient_periods = f.orbit.transient;
  o.point.recorded_periods = f.over_periods;
  o.point.steps_per_period = method.steps_per_period;
  o.point.lyapunov = false;
  o.point.method = method.settings;
  o.point.lyapunov_estimate = analysis::default_lyapunov_estimate(method.settings.method);
  o.point.components = {dof, n + dof};
  // Each branch of the diagram starts where the orbit's guess does: --x0/--v0, else rest.
  if (!f.orbit.run.start.at_rest()) o.initial_state = f.orbit.run.start.state(n);
  std::string why;
  if (!o.is_valid(&why)) throw InputError(fmt::format("--over-sweep {}: {}", f.over_sweep, why));
  RunFlags run;
  run.out = f.orbit.out + "/over_sweep";
  run.quiet = f.orbit.quiet;
  run.no_plot = f.no_plot;
  run.threads = f.threads;
  fmt::print("over-sweep: {} values of {} by continuation up and down, {} + {} periods each, "
             "into {}\n",
             f.over_sweep, parameter.name(), o.point.transient_periods, o.point.recorded_periods,
             run.out);
  run_sweep(o, run, f.orbit.out);
  if (f.no_plot) return;
  const int recorded = static_cast<int>(dofs.size());
  const std::string counts = bifurcation_counts(found);
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "poincare='{0}/bifurcation_points.csv'; section='{1}/branch_section.csv'; column=5; "
        "scolumn={2}; bifurcations='{1}/bifurcations.csv'; bxcolumn={7}; {8}"
        "out='{1}/branch_over_diagram.{3}'; xname={4}; yname={5}; title={6}",
        run.out, f.orbit.out, 5 + recorded, format, gnuplot_quoted(parameter_label(parameter)),
        gnuplot_quoted(fmt::format("x_{{{}}} at t = kT{}", dof + 1,
                                   model.explicit_structure() ? "" : " (nondimensional)")),
        gnuplot_quoted(title), 9 + 2 * recorded, counts);
  };
  draw_figure_and_report(scripts_directory() + "/branch_over_diagram.gp", definitions,
                         f.orbit.out + "/branch_over_diagram", "pwl continue", false);
}

void continue_orbit(const ContinueFlags& f) {
  const auto start = std::chrono::steady_clock::now();
  const OrbitFlags& o = f.orbit;
  const ContinuationProblem problem = continuation_problem(f);
  const analysis::PointModel& base = problem.base;
  const analysis::SweepParameter& parameter = problem.parameter;
  const double from = problem.from, to = problem.to;
  const int n = base.dofs();
  const std::vector<int>& dofs = problem.dofs;
  const analysis::PointCase& first_case = problem.first_case;
  const OrbitMethod& method = problem.method;
  const orbits::ContinuationOptions& c = problem.options;

  Vector guess;
  {
    orbits::StroboscopicMap map(first_case, method.settings, method.steps_per_period);
    note_when_no_tangent_map(map);
    guess = starting_guess(o, map);
  }
  std::string title = fmt::format(
      "pwl continue in {} of the period-{} orbit (base case {}; {})", parameter.name(), o.period,
      base.explicit_structure() ? base.structure().label : o.run.description(),
      orbit_method_label(method));
  // For a gnuplot title: no single quotes, underscores escaped (enhanced text's subscript).
  title.erase(std::remove(title.begin(), title.end(), '\''), title.end());
  for (std::size_t at = title.find('_'); at != std::string::npos; at = title.find('_', at + 2)) {
    title.insert(at, "\\");
  }
  fmt::print("continuation of the period-{} orbit of n = {}, {} in {} from {} to {}, by {}{}\n",
             o.period, n, o.run.description(), parameter.name(), from, to,
             orbit_method_label(method), method.chosen ? " (the default for orbits)" : "");
  fmt::print("guess at {} = {}: {}\n", parameter.name(), from,
             o.guess_file.empty()
                 ? fmt::format("the state {} forcing periods after {}", o.transient, o.run.start.text())
                 : o.guess_file);
  std::filesystem::create_directories(o.out);
  // SIGINT and SIGTERM stop the run between two rows, every row written whole.
  const StopSignals signals;
  ContinueOutputs outputs(o.out, base, parameter, method, dofs, !o.quiet);
  orbits::ContinuationResult result;
  orbits::ContinuationOptions with_progress = c;
  with_progress.shooting.on_iteration = [&outputs](int iteration, double residual, long products) {
    outputs.newton(iteration, residual, products);
  };
  try {
    result = orbits::continue_periodic_orbit(base, guess, with_progress, &outputs);
  } catch (...) {
    outputs.finish_progress();
    throw;
  }
  outputs.finish_progress();
  outputs.rewrite_bifurcations(o.out, result.bifurcations);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  fmt::print("start: Newton at {} = {}: residual {:.3e} after {} iteration(s)\n", parameter.name(),
             from, outputs.first_residual(), outputs.first_iterations());
  for (const auto& [branch, count] : outputs.per_branch()) {
    const auto& [lo, hi] = outputs.range().at(branch);
    const auto stable = outputs.stable().find(branch);
    fmt::print("branch {} (period {}): {} points, {} from {:.10g} to {:.10g}, {} stable\n", branch,
               outputs.period().at(branch), count, parameter.name(), lo, hi,
               stable == outputs.stable().end() ? 0 : stable->second);
  }
  print_bifurcations(result.bifurcations, parameter.name());
  if (!result.notes.empty()) {
    fmt::print("notes:\n");
    for (const std::string& note : result.notes) fmt::print("  {}\n", note);
  }
  if (result.matrix_free) {
    fmt::print("work (matrix-free): {} GMRES products, {} multiplier products (by Davidson at {} "
               "point(s), by Arnoldi at {}), {} other integrations of the map; {} step(s) cut to "
               "explain the multipliers' signature\n",
               result.krylov_products, result.arnoldi_products, result.davidson_points,
               result.arnoldi_points, result.integrations, result.step_cuts);
    if (result.unconverged_multipliers > 0) {
      fmt::print("  at {} point(s) the multipliers stopped short of their tolerance: their stability rests on "
                 "unconverged Ritz values\n",
                 result.unconverged_multipliers);
    }
    if (result.uncovered_bands > 0) {
      fmt::print("  at {} point(s) the multipliers stopped at half their basis still above {:.6g} "
                 "in modulus: more of them may lie there than were reported, and the band was "
                 "watched there only as far as they reach\n",
                 result.uncovered_bands, 1.0 - c.shooting.arnoldi.margin);
    }
  } else {
    fmt::print("work: {} monodromies, {} other integrations of the map; {} step(s) cut to explain "
               "the multipliers' signature\n",
               result.monodromies, result.integrations, result.step_cuts);
  }
  if (std::isfinite(result.narrowest_band)) {
    const double asked = result.band;
    fmt::print("band: steps checked for a multiplier within half of {:.6g} of the circle "
               "without a partner at its other end{}; {} step(s) halved\n",
               asked,
               result.narrowest_band < asked
                   ? fmt::format(" (narrowed to {:.3g} where only the leading multipliers were "
                                 "known)",
                                 result.narrowest_band)
                   : "",
               result.band_cuts);
  }
  fmt::print("time: {:.2f} s ({} points)\n", seconds, outputs.points());
  fmt::print("wrote {0}/branch.csv, {0}/branch_section.csv and {0}/bifurcations.csv\n", o.out);
  if (!f.no_plot) {
    draw_frequency_response(f, outputs, result.bifurcations, dofs, parameter,
                            !base.explicit_structure(), title);
  }
  if (problem.curves) {
    const auto begin = std::chrono::steady_clock::now();
    const std::vector<orbits::Bifurcation> starts =
        curve_starts(problem, result.bifurcations);
    CurveOutputs curve_outputs(o.out, *problem.curves, n, !o.quiet);
    orbits::CurvesResult curves;
    try {
      curves = orbits::follow_bifurcation_curves(base, starts, *problem.curves, &curve_outputs);
    } catch (...) {
      curve_outputs.finish_progress();
      throw;
    }
    curve_outputs.finish_progress();
    print_curves(curves, *problem.curves);
    if (!curves.notes.empty()) {
      fmt::print("curve notes:\n");
      for (const std::string& note : curves.notes) fmt::print("  {}\n", note);
    }
    fmt::print("curves' work: {} monodromies, {} other integrations of the map\n",
               curves.monodromies, curves.integrations);
    if (curves.krylov_products > 0 || curves.arnoldi_products > 0) {
      fmt::print("  matrix-free curves: {} GMRES products, {} multiplier products (by Davidson at "
                 "{} point(s), by Arnoldi at {})\n",
                 curves.krylov_products, curves.arnoldi_products, curves.davidson_points,
                 curves.arnoldi_points);
      if (curves.unconverged_multipliers > 0 || curves.uncovered_bands > 0) {
        fmt::print("  at {} corrected point(s) Arnoldi stopped short of its tolerance and at {} it "
                   "did not reach below the modulus its margin asks: no fold-, flip- or "
                   "Neimark-Sacker-grazing point is looked for there\n",
                   curves.unconverged_multipliers, curves.uncovered_bands);
      }
    }
    fmt::print("curves' time: {:.2f} s ({} rows)\n",
               std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count(),
               curve_outputs.rows());
    fmt::print("wrote {0}/curves.csv and {0}/codim2.csv\n", o.out);
    if (!f.no_plot) draw_curves(o.out, *problem.curves, curves, title);
  }
  if (f.over_sweep > 0) {
    run_over_sweep(f, base, parameter, method, from, to, dofs, result.bifurcations, title);
  }
}

}  // namespace

std::string bifurcation_detail(const orbits::Bifurcation& b) {
  std::vector<std::string> parts;
  if (b.type == orbits::BifurcationType::grazing) {
    parts.emplace_back(b.at_largest_gap ? "largest gap" : "smallest gap");
  }
  if (b.to_branch >= 0) parts.push_back(fmt::format("starts branch {}", b.to_branch));
  if (b.joined_by >= 0) parts.push_back(fmt::format("ends branch {}", b.joined_by));
  if (!b.located) parts.emplace_back("not located (detected between two branch points)");
  return fmt::format("{}", fmt::join(parts, "; "));
}

ContinuationProblem continuation_problem(const ContinueFlags& f) {
  const OrbitFlags& o = f.orbit;
  check_orbit_flags(o);
  const analysis::PointModel base = o.run.model();
  if (f.parameter.empty()) throw InputError("--parameter: name the parameter to follow");
  const analysis::SweepParameter parameter = parse_model_parameter(base, "--parameter", f.parameter);
  if (f.range.empty()) throw InputError("--range: give the range as FROM:TO");
  double from = 0, to = 0;
  parse_range("--range", f.range, &from, &to);
  if (!std::isfinite(from) || !std::isfinite(to) || from == to) {
    throw InputError(fmt::format("--range = \"{}\": the two ends must be different finite values",
                                 f.range));
  }
  std::string why;
  for (const double end : {from, to}) {
    if (!base.accepts(parameter, end, &why)) {
      throw InputError(fmt::format("--range = \"{}\": at {} = {}: {}", f.range, parameter.name(),
                                   end, why));
    }
  }
  check_relation("continue", "--min-step", f.min_step, "--max-step", f.max_step);
  check_relation("continue", "--min-step", f.min_step, "--step", f.step);
  if (f.max_points < 2) throw InputError(fmt::format("--max-points = {} must be >= 2", f.max_points));
  if (f.over_sweep == 1) {
    throw InputError("--over-sweep = 1: a bifurcation diagram needs at least 2 values");
  }
  const int n = base.dofs();
  const std::vector<int> dofs = recorded_dofs(f.record, n);

  const analysis::PointModel at_start = base.with(parameter, from);
  const analysis::PointCase first_case = at_start.point_case();
  const OrbitMethod method = orbit_method(o, first_case.structure, first_case.period);
  if (!method_traits(method.settings.method).fixed_grid && o.run.dt != 0.0) {
    throw InputError("--dt: the continuation's step is --steps-per-period (the period varies)");
  }
  {
    // orbit_method judged the step at the start; η ω_max grows or shrinks monotonically with
    // every parameter a model varies (stiffness, damping, frequency), so the far end is the
    // other extreme the branch can reach.
    const analysis::PointCase last_case = base.with(parameter, to).point_case();
    guard_step(last_case.structure,
               method.settings.for_period(last_case.period, method.steps_per_period),
               last_case.period, o.run.force);
  }
  orbits::ContinuationOptions c;
  c.parameter = parameter;
  c.start = from;
  c.end = to;
  c.initial_step = f.step;
  c.min_step = f.min_step;
  c.max_step = f.max_step;
  c.max_points = f.max_points;
  c.grazing = !f.no_grazing;
  c.band = f.band;  // checked by its flag, and by c.is_valid below for flags not parsed
  c.corrector = orbits::parse_corrector(f.corrector);
  c.switch_branches = f.switch_branches;
  c.max_branches = f.max_branches;
  c.method = method.settings;
  c.steps_per_period = method.steps_per_period;
  c.shooting = shooting_options(o);  // automatic: matrix-free beyond the dense limit
  if (!c.is_valid(&why)) throw InputError(why);

  ContinuationProblem problem{base, parameter, from, to, dofs, first_case, method, c, {}, 0};
  if (f.curves.empty()) {
    if (!f.curve_types.empty() || f.start_bifurcation != 0) {
      throw InputError(fmt::format("{} needs --curves Q=FROM:TO",
                                   f.curve_types.empty() ? "--start-bifurcation" : "--curve-types"));
    }
    return problem;
  }
  const std::size_t equals = f.curves.find('=');
  if (equals == std::string::npos) {
    throw InputError(fmt::format("--curves = \"{}\": give the second parameter and its range as "
                                 "Q=FROM:TO (alpha=1:15)",
                                 f.curves));
  }
  orbits::CurvesOptions curves;
  curves.first = parameter;
  curves.second = parse_model_parameter(base, "--curves", f.curves.substr(0, equals));
  check_relation("continue", "--curves", curves.second.name(), "--parameter", parameter.name());
  parse_range("--curves", f.curves.substr(equals + 1), &curves.q_from, &curves.q_to);
  if (!std::isfinite(curves.q_from) || !std::isfinite(curves.q_to) ||
      curves.q_from == curves.q_to) {
    throw InputError(fmt::format("--curves = \"{}\": the two ends must be different finite values",
                                 f.curves));
  }
  for (const double end : {curves.q_from, curves.q_to}) {
    if (!base.accepts(curves.second, end, &why)) {
      throw InputError(fmt::format("--curves = \"{}\": at {} = {}: {}", f.curves,
                                   curves.second.name(), end, why));
    }
  }
  double q0 = 0.0;
  try {
    q0 = base.value(curves.second);
  } catch (const InputError& e) {
    throw InputError(fmt::format("--curves = \"{}\": {}", f.curves, e.what()));
  }
  if (!(q0 >= std::min(curves.q_from, curves.q_to) && q0 <= std::max(curves.q_from, curves.q_to))) {
    throw InputError(fmt::format("--curves = \"{}\": the branch is at {} = {}, outside that range "
                                 "(the curves start on the branch)",
                                 f.curves, curves.second.name(), q0));
  }
  if (!f.curve_types.empty()) {
    curves.types.clear();
    for (const std::string& name : f.curve_types) {
      try {
        curves.types.push_back(orbits::parse_curve_type(name));
      } catch (const InputError& e) {
        throw InputError(fmt::format("--curve-types {}: {}", name, e.what()));
      }
    }
  }
  curves.p_from = from;
  curves.p_to = to;
  curves.max_points = f.curve_points;
  curves.corrector = c.corrector;
  curves.method = c.method;
  curves.steps_per_period = c.steps_per_period;
  curves.shooting = c.shooting;  // automatic: matrix-free beyond the dense limit
  // The branch's default margin serves its band; the curves have none, so they keep their own
  // default unless another margin is asked (typed, or set in flags filled without parsing).
  if (o.multiplier_margin == orbits::kContinuationMargin) {
    curves.shooting.arnoldi.margin = orbits::CurvesOptions{}.shooting.arnoldi.margin;
  }
  curves.profile_samples = c.profile_samples;
  if (!curves.is_valid(&why)) throw InputError("--curves: " + why);
  problem.curves = curves;
  problem.start_bifurcation = f.start_bifurcation;
  return problem;
}

std::vector<orbits::Bifurcation> curve_starts(const ContinuationProblem& problem,
                                              const std::vector<orbits::Bifurcation>& found) {
  if (!problem.curves) return {};
  const auto wanted = [&](const orbits::Bifurcation& b) {
    const auto& types = problem.curves->types;
    return std::find(types.begin(), types.end(), orbits::curve_type_of(b.type)) != types.end();
  };
  if (problem.start_bifurcation == 0) {
    std::vector<orbits::Bifurcation> starts;
    for (const orbits::Bifurcation& b : found) {
      if (wanted(b)) starts.push_back(b);
    }
    return starts;
  }
  const auto row = static_cast<std::size_t>(problem.start_bifurcation);
  if (row > found.size()) {
    throw InputError(fmt::format("--start-bifurcation {}: bifurcations.csv has {} row(s)", row,
                                 found.size()));
  }
  const orbits::Bifurcation& b = found[row - 1];
  if (!b.located) {
    throw InputError(fmt::format("--start-bifurcation {}: that {} was detected, not located: no "
                                 "curve starts there",
                                 row, orbits::bifurcation_name(b.type)));
  }
  if (!wanted(b)) {
    throw InputError(fmt::format("--start-bifurcation {}: that row is a {}, which --curve-types "
                                 "leaves out",
                                 row, orbits::bifurcation_name(b.type)));
  }
  return {b};
}

void add_continue_flags(CLI::App& command, ContinueFlags& flags) {
  add_orbit_flags(command, flags.orbit, false);  // with continue_orbit_flags' defaults
  command.get_option("--out")->default_str("continuation");
  command.get_option("--transient")
      ->description("Guess: the state this many forcing periods after rest, at the start of\n"
                    "--range (also each --over-sweep point's transient)");
  command.add_option("--parameter", flags.parameter,
                     "Parameter followed: theta, alpha, zeta, gap (Δ̃) or amplitude (scales Q) of "
                     "the\n"
                     "chain; spring<j>.stiffness, spring<j>.gap, load<j>.amplitude, "
                     "load<j>.frequency\n"
                     "or damping (scales C) of a --structure-scene (j from 1)")
      ->required();
  command.add_option("--range", flags.range,
                     "FROM:TO: the branch starts at FROM and is followed toward TO (either order)")
      ->required();
  command.add_flag("--switch-branches", flags.switch_branches,
                   "At each period doubling, follow the period-2k branch born there too");
  command.add_option("--max-branches", flags.max_branches, "Branches switched onto, at most")
      ->check(non_negative_number());
  command.add_option("--max-points", flags.max_points, "Points per branch, at most")
      ->check(positive_number());
  command.add_option("--step", flags.step,
                     "Arclength of the first step (0: |TO − FROM|/100)")
      ->check(non_negative_number());
  command.add_option("--min-step", flags.min_step,
                     "Smallest step; a branch stops below it (0: 1e-7 |TO − FROM|)")
      ->check(non_negative_number());
  command.add_option("--max-step", flags.max_step, "Largest step (0: |TO − FROM|/25)")
      ->check(non_negative_number());
  command.add_option("--record", flags.record,
                     "Masses whose amplitude and state branch.csv keeps, comma separated (5 or "
                     "x5);\n"
                     "the figures draw the last one. Default: every mass up to 10, else the last")
      ->delimiter(',');
  command.add_flag("--no-grazing", flags.no_grazing, "Do not look for grazing bifurcations");
  command.add_option("--band", flags.band,
                     "Band round the unit circle watched between points: a step is halved while a\n"
                     "multiplier within half of it of the circle has no partner at its other end,\n"
                     "so that none goes out and back within a step unseen; matrix-free, narrowed\n"
                     "to what the leading multipliers cover, not below --multiplier-margin where\n"
                     "they converged within half their basis. 0: off")
      ->default_val(0.05)
      ->check(number_check({0.0, 1.0, false, true, "a number in [0, 1)"}, "[0,1)"));
  command.add_option("--corrector", flags.corrector,
                     "chord (Newton steps on the monodromy of the point predicted from, formed\n"
                     "again only where they stop contracting), newton (the monodromy at every\n"
                     "iterate) or automatic (newton up to 20 state components, chord above)")
      ->check(CLI::IsMember({"automatic", "chord", "newton"}));
  command.add_option("--over-sweep", flags.over_sweep,
                     "Also run the brute-force bifurcation diagram of the range (pwl sweep by\n"
                     "continuation, up and down) with this many values into OUT/over_sweep, and "
                     "draw\n"
                     "the branches over it (OUT/branch_over_diagram.png)")
      ->check(non_negative_number());
  command.add_option("--over-periods", flags.over_periods,
                     "Poincaré points recorded per value of --over-sweep (after --transient)")
      ->check(positive_number());
  command.add_flag("--no-plot", flags.no_plot, "Write the CSV files only");
  command.add_option("--threads", flags.threads,
                     "OpenMP threads of --over-sweep (default: all cores)")
      ->check(non_negative_number());
  command.add_option("--curves", flags.curves,
                     "Q=FROM:TO: after the branch, follow each fold, period doubling,\n"
                     "Neimark-Sacker point and grazing it located in the plane of --parameter\n"
                     "and Q over FROM:TO (any parameter --parameter takes), with their\n"
                     "codimension-two points: OUT/curves.csv, OUT/codim2.csv,\n"
                     "OUT/bifurcation_curves.png. Beyond the dense limit (200 masses)\n"
                     "the curves are followed matrix-free, by Newton-Krylov (no cusp or\n"
                     "generalised period-doubling point is looked for there)");
  command.add_option("--curve-types", flags.curve_types,
                     "The curves to follow: fold, period-doubling, neimark-sacker, grazing,\n"
                     "comma separated (default: all four)")
      ->delimiter(',');
  command.add_option("--start-bifurcation", flags.start_bifurcation,
                     "Follow only the curve of this row of bifurcations.csv (1 for the first;\n"
                     "0: every located row of the --curve-types)")
      ->check(non_negative_number());
  command.add_option("--curve-points", flags.curve_points,
                     "Points of each curve in each direction from the branch, at most")
      ->check(positive_number());
}

void add_continue_command(CLI::App& app) {
  auto flags = std::make_shared<ContinueFlags>();
  CLI::App* c = app.add_subcommand(
      "continue",
      "Follow a periodic orbit in one parameter (pseudo-arclength continuation), with its\n"
      "stability and its bifurcations: fold, period doubling, Neimark-Sacker, grazing\n"
      "Example: pwl continue --figure 5 --parameter theta --range 0.5:3 --out theta_branch\n"
      "         pwl continue --figure 5 --parameter theta --range 0.5:3 --switch-branches \\\n"
      "           --over-sweep 200 --out theta_branch");
  add_continue_flags(*c, *flags);
  c->callback([c, flags] {
    read_method_given(*c, flags->orbit);
    continue_orbit(*flags);
  });
}

}  // namespace pwl::app
