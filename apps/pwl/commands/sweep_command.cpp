// pwl sweep: a one-parameter sweep of the paper's chain or of an explicit structure, the data and
// the figure of a bifurcation diagram (see analysis/include/pwl/study/parameter_sweep.hpp).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/study_flag_checks.hpp"
#include "commands/sweep_command.hpp"
#include "output/gnuplot.hpp"
#include "pwl/study/parameter_sweep.hpp"
#include "pwl/errors.hpp"
#include "commands/study_runner.hpp"

namespace pwl::app {
namespace {

// What the bifurcation diagram draws: the first recorded component of every Poincaré point,
// with the points of one parameter value and direction that fall within 1/1000 of the plotted
// range of each other (under a pixel) kept once (a periodic orbit's hundreds of returns are a few
// points), so that the SVG stays small. Same columns as poincare.csv, one component.
void write_plotted_points(const analysis::SweepOptions& o,
                          const std::map<long, analysis::PointResult>& records,
                          const std::string& path) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& [id, r] : records) {
    for (int k = 0; k < r.rows(); ++k) {
      const double y =
          r.poincare[static_cast<std::size_t>(k) * static_cast<std::size_t>(r.columns)];
      if (std::isfinite(y)) lo = std::min(lo, y), hi = std::max(hi, y);
    }
  }
  const double cell = hi > lo ? (hi - lo) / 1000.0 : 1.0;
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (file == nullptr) throw Error(fmt::format("cannot write {}", path));
  const bool crossings = !o.point.section.stroboscopic();
  fmt::print(file, "{},direction,index,{},value\n", analysis::parameter_name(o.parameter),
             crossings ? "t" : "period_index");
  for (const auto& [id, r] : records) {
    const int index = static_cast<int>(id % o.points);
    std::set<long long> seen;
    for (int k = 0; k < r.rows(); ++k) {
      const double y =
          r.poincare[static_cast<std::size_t>(k) * static_cast<std::size_t>(r.columns)];
      if (!std::isfinite(y) || !seen.insert(std::llround((y - lo) / cell)).second) continue;
      if (crossings) {
        const std::size_t row = static_cast<std::size_t>(k);
        fmt::print(file, "{:.17g},{},{},{:.17g},{:.17g}\n", o.value(index),
                   id < o.points ? "up" : "down", index,
                   row < r.section_times.size() ? r.section_times[row]
                                                : std::numeric_limits<double>::quiet_NaN(),
                   y);
      } else {
        fmt::print(file, "{:.17g},{},{},{},{:.17g}\n", o.value(index),
                   id < o.points ? "up" : "down", index, o.point.transient_periods + k + 1, y);
      }
    }
  }
  if (std::fclose(file) != 0) throw Error(fmt::format("cannot finish writing {}", path));
}

// The 1-based column of `component` in <branches>/branch_section.csv (pwl continue), for the
// figure; InputError naming --branches when there is none.
int branch_section_column(const std::string& branches, const std::string& component) {
  const std::string path = branches + "/branch_section.csv";
  std::ifstream in(path);
  std::string header;
  if (!in || !std::getline(in, header)) {
    throw InputError(fmt::format(
        "--branches {}: no {} (the folder of a pwl continue run of the same parameter)", branches,
        path));
  }
  if (!header.empty() && header.back() == '\r') header.pop_back();
  int column = 1;
  for (std::size_t from = 0;; ++column) {
    const std::size_t comma = header.find(',', from);
    if (header.substr(from, comma == std::string::npos ? std::string::npos : comma - from) ==
        component) {
      return column;
    }
    if (comma == std::string::npos) break;
    from = comma + 1;
  }
  throw InputError(fmt::format(
      "--branches {}: {} has no column {} (the sweep's first recorded component); its columns: "
      "{} (record that mass in pwl continue --record)",
      branches, path, component, header));
}

void sweep(const SweepFlags& f) { run_sweep(sweep_options(f), f.run, f.branches); }

}  // namespace

analysis::SweepOptions sweep_options(const SweepFlags& f) {
  analysis::SweepOptions o;
  const analysis::PointModel model = f.model.model();
  if (model.explicit_structure()) {
    o.structure = model.structure();
  } else {
    o.chain = model.chain();
  }
  o.parameter = parse_model_parameter(model, "--parameter", f.parameter);
  parse_range("--range", f.range, &o.from, &o.to);
  check_range_ends(model, o.parameter, "--range", f.range, o.from, o.to);
  o.points = f.points;
  o.mode = f.mode == "continuation" ? analysis::SweepMode::continuation
                                    : analysis::SweepMode::independent;
  o.upward = f.directions != "down";
  o.downward = f.directions != "up";
  o.point = f.point.settings(model.dofs());
  o.point.section = f.section.poincare_section(model.dofs());
  if (!f.start.at_rest()) o.initial_state = f.start.state(model.dofs());
  std::string why;
  if (!o.is_valid(&why)) throw InputError(why);
  return o;
}

void run_sweep(const analysis::SweepOptions& o, const RunFlags& run, const std::string& branches) {
  const std::string component =
      o.point.components.empty()
          ? std::string("x")
          : analysis::component_name(o.point.components[0], o.model().dofs());
  // Checked before the sweep runs, so that a wrong folder costs nothing.
  const int branch_column = branches.empty() || run.no_plot
                                ? 0
                                : branch_section_column(branches, component);
  Study study = study_of(o);
  study.finish = [&](const std::map<long, analysis::PointResult>& records) {
    analysis::write_sweep_files(o, records, run.out);
    fmt::print("wrote {0}/poincare.csv and {0}/classification.csv ({1} points)\n", run.out,
               records.size());
    if (run.no_plot) return;
    write_plotted_points(o, records, run.out + "/bifurcation_points.csv");
    const auto definitions = [&](const std::string& format) {
      std::string overlay;
      if (branch_column > 0) {
        overlay = fmt::format("branches={}; bcolumn={}; ",
                              gnuplot_quoted(branches + "/branch_section.csv"), branch_column);
      }
      return overlay +
             fmt::format(
                 "poincare='{0}/bifurcation_points.csv'; classes='{0}/classification.csv'; "
                 "out='{0}/bifurcation.{4}'; column=5; xname='{1}'; "
                 "yname='{2} at {5} (nondimensional)'; title={3}",
                 run.out, parameter_label(o.parameter), component,
                 gnuplot_quoted(fmt::format(
                     "pwl sweep of {} ({}): {}", analysis::parameter_name(o.parameter),
                     o.mode == analysis::SweepMode::continuation ? "continuation" : "independent",
                     study_title(o.model(), o.point))),
                 format, o.point.section.label(o.model().dofs()));
    };
    draw_figure_and_report(scripts_directory() + "/bifurcation.gp", definitions,
                           run.out + "/bifurcation", "pwl sweep", false);
  };
  run_study(study, run);
}

void add_sweep_flags(CLI::App& c, SweepFlags& flags) {
  add_model_flags(c, flags.model);
  c.add_option("--parameter", flags.parameter,
               "Parameter swept: theta, alpha, zeta, gap (Δ̃) or amplitude (scales Q) of the\n"
               "chain; spring<j>.stiffness, spring<j>.gap, load<j>.amplitude, load<j>.frequency\n"
               "or damping (scales C) of a --structure-scene (j from 1)");
  c.add_option("--range", flags.range, "FROM:TO, from < to");
  // At least 1, checked with the sweep (SweepOptions::is_valid: "points = 0 must be at least 1").
  c.add_option("--points", flags.points, "Number of parameter values N")->check(finite_number());
  c.add_option("--mode", flags.mode,
               "independent (every point from rest, or from --x0/--v0) or continuation (from the\n"
               "previous point's final state, upward and downward; each branch's first point\n"
               "from rest or --x0/--v0)")
      ->check(CLI::IsMember({"independent", "continuation"}));
  c.add_option("--directions", flags.directions, "Continuation branches: both, up or down")
      ->check(CLI::IsMember({"both", "up", "down"}));
  add_point_flags(c, flags.point, true);
  check_point_flags(c);
  add_section_flags(c, flags.section,
                    "poincare.csv (t, the crossing time, instead\n"
                    "of period_index for a hyperplane) and the diagram get the section's points of\n"
                    "--record's components");
  add_initial_state_flags(c, flags.start);
  add_run_flags(c, flags.run);
  c.add_option("--branches", flags.branches,
               "Also draw the periodic-orbit branches of a pwl continue folder (its\n"
               "branch_section.csv: stable filled, unstable open) over the diagram's points")
      ->check(CLI::ExistingDirectory);
}

void add_sweep_command(CLI::App& app) {
  auto flags = std::make_shared<SweepFlags>();
  CLI::App* c = app.add_subcommand(
      "sweep",
      "Bifurcation diagram: Poincaré points and regimes over one parameter\n"
      "Example: pwl sweep --figure 5 --parameter theta --range 0.5:3 --points 200 \\\n"
      "           --mode continuation --out theta_sweep\n"
      "         pwl sweep --structure-scene apps/scenes/two_mass_stop.toml \\\n"
      "           --parameter spring1.gap --range 0.05:0.5 --points 50 --out gap_sweep");
  add_sweep_flags(*c, *flags);
  c->callback([flags] { sweep(*flags); });
}

}  // namespace pwl::app
