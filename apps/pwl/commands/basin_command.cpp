// pwl basin: the basins of attraction of one case over a grid of initial states in two state
// components (see analysis/include/pwl/study/basin_map.hpp), every cell classified and matched to
// the attractor it ends on, with a figure coloured by attractor.
#include "commands/basin_command.hpp"

#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "commands/cli_checks.hpp"
#include "commands/flag_relations.hpp"
#include "commands/commands.hpp"
#include "commands/study_flag_checks.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/parameter_sweep.hpp"

namespace pwl::app {
namespace {

// Both ends of a FROM:TO range of initial values finite.
void check_finite_range(const std::string& flag, const std::string& text, double from, double to,
                        int points) {
  if (!std::isfinite(from) || !std::isfinite(to)) {
    throw InputError(fmt::format("{} = \"{}\": FROM and TO must be finite numbers", flag, text));
  }
  if (points > 1 && !(from < to)) {
    throw InputError(fmt::format("{} = \"{}\": give FROM < TO", flag, text));
  }
}

void basin(const BasinFlags& f) {
  const analysis::BasinMapOptions o = basin_options(f);
  Study study = basin_study(o);
  study.finish = [&](const std::map<long, analysis::PointResult>& records) {
    const analysis::BasinMap basins = analysis::match_basins(o, records);
    analysis::write_basin_files(o, records, basins, f.run.out);
    fmt::print("wrote {0}/basin.csv ({1} cells), {0}/attractors.csv and {0}/attractor_points.csv "
               "({2} attractor{3})\n",
               f.run.out, records.size(), basins.attractors.size(),
               basins.attractors.size() == 1 ? "" : "s");
    for (const analysis::Attractor& a : basins.attractors) {
      fmt::print("  attractor {}: {}, {} cells ({:.1f}%)\n", a.id, a.name(), a.motions,
                 100.0 * static_cast<double>(a.motions) / static_cast<double>(records.size()));
    }
    if (f.run.no_plot) return;
    const int dofs = o.model().dofs();
    const double dx = o.first.points > 1 ? (o.first.to - o.first.from) / (o.first.points - 1) : 1.0;
    const double dy =
        o.second.points > 1 ? (o.second.to - o.second.from) / (o.second.points - 1) : 1.0;
    // The legend names each attractor with its size, the largest |x_i| over its tail, which tells
    // a small orbit from a large one of the same name.
    std::string labels;
    for (const analysis::Attractor& a : basins.attractors) {
      const double share =
          100.0 * static_cast<double>(a.motions) / static_cast<double>(records.size());
      const std::string size =
          a.points.rows() > 0
              ? fmt::format(", max |x| at t = 0 mod T: {:.3g}",
                            a.points.leftCols(dofs).cwiseAbs().maxCoeff())
              : std::string();
      labels += fmt::format("; label{}={}", a.id,
                            gnuplot_quoted(fmt::format("{}: {}{} ({:.0f}%)", a.id, a.name(), size,
                                                       share)));
    }
    const auto definitions = [&](const std::string& format) {
      // attractor_points.csv: attractor, then x1..xn, v1..vn (column 2 + component).
      return fmt::format(
          "data='{0}/basin.csv'; points='{0}/attractor_points.csv'; out='{0}/basin.{1}'; "
          "xname='{2}'; yname='{3}'; xcol={4}; ycol={5}; dx={6:.17g}; dy={7:.17g}; "
          "attractors={8}; subtitle={9}{10}",
          f.run.out, format, analysis::component_name(o.first.component, dofs),
          analysis::component_name(o.second.component, dofs), o.first.component + 2,
          o.second.component + 2, dx, dy, basins.attractors.size(),
          gnuplot_quoted(study_title(o.model(), o.point)), labels);
    };
    draw_figure_and_report(scripts_directory() + "/basin.gp", definitions, f.run.out + "/basin",
                           "pwl basin", false);
  };
  run_study(study, f.run);
}

}  // namespace

Study basin_study(const analysis::BasinMapOptions& o) {
  Study study;
  study.description = o.describe();
  study.tasks = o.tasks();
  study.case_of = [o](long id) { return o.case_of(id); };
  study.initial_state = o.initial_state(0);
  study.settings = o.settings();
  return study;
}

analysis::BasinMapOptions basin_options(const BasinFlags& f) {
  analysis::BasinMapOptions o;
  const analysis::PointModel model = f.model.model();
  if (model.explicit_structure()) {
    o.structure = model.structure();
  } else {
    o.chain = model.chain();
  }
  const int dofs = model.dofs();
  o.first.component = parse_component("--x", f.x, dofs);
  parse_range("--x-range", f.x_range, &o.first.from, &o.first.to);
  check_finite_range("--x-range", f.x_range, o.first.from, o.first.to, f.x_points);
  o.first.points = f.x_points;
  o.second.component = parse_component("--y", f.y, dofs);
  parse_range("--y-range", f.y_range, &o.second.from, &o.second.to);
  check_finite_range("--y-range", f.y_range, o.second.from, o.second.to, f.y_points);
  o.second.points = f.y_points;
  check_relation("basin", "--y", analysis::component_name(o.second.component, dofs), "--x",
                 analysis::component_name(o.first.component, dofs));
  if (f.point.starts != 1) {
    throw InputError(fmt::format("--starts {}: a basin map starts every cell from its own state "
                                 "(the grid); give 1",
                                 f.point.starts));
  }
  o.point = f.point.settings(dofs);
  o.point.kept_points = f.kept_points;
  if (f.kept_points < 2) {
    throw InputError(fmt::format("--kept-points {}: must be at least 2 (the attractors are matched "
                                 "on the last points of each motion)",
                                 f.kept_points));
  }
  check_relation("basin", "--kept-points", f.kept_points, "--periods", f.point.periods);
  o.matching.periodic_tolerance = f.periodic_tolerance;
  o.matching.cloud_factor = f.cloud_factor;
  if (!f.start.at_rest()) o.base_state = f.start.state(dofs);
  std::string why;
  if (!o.is_valid(&why)) throw InputError(why);
  return o;
}

void add_basin_flags(CLI::App& c, BasinFlags& flags) {
  add_model_flags(c, flags.model);
  c.add_option("--x", flags.x, "Horizontal state component of the initial states: x1..xn, v1..vn");
  c.add_option("--x-range", flags.x_range, "FROM:TO of the horizontal component");
  c.add_option("--x-points", flags.x_points, "Values of the horizontal component")
      ->check(positive_number());
  c.add_option("--y", flags.y, "Vertical state component");
  c.add_option("--y-range", flags.y_range, "FROM:TO of the vertical component");
  c.add_option("--y-points", flags.y_points, "Values of the vertical component")
      ->check(positive_number());
  c.add_option("--kept-points", flags.kept_points,
               "Stroboscopic points of each motion's tail the attractors are matched on (at least\n"
               "2 and the longest period to tell apart)")
      ->check(positive_number());
  c.add_option("--periodic-tolerance", flags.periodic_tolerance,
               "Two period-k tails are one orbit when their points agree within this, relative\n"
               "to the orbit's size")
      ->check(positive_number());
  c.add_option("--cloud-factor", flags.cloud_factor,
               "Two non-periodic tails are one attractor when each lies within this many\n"
               "nearest-neighbour spacings of the other")
      ->check(positive_number());
  add_point_flags(c, flags.point, false);
  check_point_flags(c);
  add_initial_state_flags(c, flags.start);
  add_run_flags(c, flags.run);
}

void add_basin_command(CLI::App& app) {
  auto flags = std::make_shared<BasinFlags>();
  CLI::App* c = app.add_subcommand(
      "basin",
      "Basins of attraction: start one case from every initial state of a grid in two state\n"
      "components (the others from --x0/--v0, else 0), classify each motion and match it to\n"
      "the attractor it ends on\n"
      "Example: pwl basin --n 1 --alpha 3 --zeta 0.1 --gap 1.5 --loads 0.5 --theta 1.2 \\\n"
      "           --x x1 --x-range -4:4 --y v1 --y-range -4:4 --out basin");
  add_basin_flags(*c, *flags);
  c->callback([flags] { basin(*flags); });
}

}  // namespace pwl::app
