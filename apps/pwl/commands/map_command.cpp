// pwl map: a two-parameter regime map of the paper's chain or of an explicit structure, classified
// cell by cell (see analysis/include/pwl/study/regime_map.hpp), with a regime heatmap and a λ1
// heatmap.
#include <fmt/format.h>

#include <fstream>
#include <memory>
#include <sstream>

#include "commands/cli_checks.hpp"
#include "commands/flag_relations.hpp"
#include "commands/commands.hpp"
#include "commands/study_flag_checks.hpp"
#include "commands/map_command.hpp"
#include "output/gnuplot.hpp"
#include "pwl/study/regime_map.hpp"
#include "pwl/errors.hpp"
#include "commands/study_runner.hpp"

namespace pwl::app {
namespace {

// The curves of --curves for the map's figure: the gnuplot definitions, with the columns of
// curves.csv drawn across and up (3 and 4, or 4 and 3 when the map has the curves' parameters the
// other way round). Throws InputError naming --curves when the folder has no curves.csv or its
// parameters are not the map's.
std::string curves_over_map(const std::string& folder, const analysis::RegimeMapOptions& o) {
  const std::string path = folder + "/curves.csv";
  std::ifstream in(path);
  std::string header;
  if (!in || !std::getline(in, header)) {
    throw InputError(fmt::format("--curves {}: no {} (a folder of pwl continue --curves)", folder,
                                 path));
  }
  std::vector<std::string> columns;
  std::stringstream fields(header);
  for (std::string c; std::getline(fields, c, ',');) columns.push_back(c);
  const std::string x = o.first.parameter.name(), y = o.second.parameter.name();
  if (columns.size() < 4 || !((columns[2] == x && columns[3] == y) ||
                              (columns[2] == y && columns[3] == x))) {
    throw InputError(fmt::format("--curves {}: its curves are in ({}, {}), the map in ({}, {})",
                                 folder, columns.size() > 2 ? columns[2] : "?",
                                 columns.size() > 3 ? columns[3] : "?", x, y));
  }
  long codim2 = -1;  // rows after the header
  std::ifstream points(folder + "/codim2.csv");
  for (std::string line; std::getline(points, line);) ++codim2;
  return fmt::format("; curves='{0}/curves.csv'; codim2='{0}/codim2.csv'; ncodim2={1}; "
                     "xcol={2}; ycol={3}",
                     folder, std::max(codim2, 0L), columns[2] == x ? 3 : 4,
                     columns[2] == x ? 4 : 3);
}


void map(const MapFlags& f) {
  const analysis::RegimeMapOptions o = map_options(f);
  const std::string curves = f.curves.empty() ? "" : curves_over_map(f.curves, o);
  Study study = study_of(o);
  study.finish = [&](const std::map<long, analysis::PointResult>& records) {
    analysis::write_map_file(o, records, f.run.out);
    fmt::print("wrote {}/map.csv ({} cells)\n", f.run.out, records.size());
    if (f.run.no_plot) return;
    std::string why;
    const double dx = o.first.points > 1 ? (o.first.to - o.first.from) / (o.first.points - 1) : 1.0;
    const double dy =
        o.second.points > 1 ? (o.second.to - o.second.from) / (o.second.points - 1) : 1.0;
    const auto definitions = [&](const std::string& format) {
      return fmt::format(
          "data='{0}/map.csv'; out='{0}/regime_map.{6}'; out_lambda='{0}/lambda1_map.{6}'; "
          "xname='{1}'; yname='{2}'; dx={3:.17g}; dy={4:.17g}; subtitle={5}{7}{8}",
          f.run.out, parameter_label(o.first.parameter), parameter_label(o.second.parameter), dx,
          dy, gnuplot_quoted(study_title(o.model(), o.point)), format,
          o.point.starts > 1
              ? fmt::format("; out_attractors='{}/attractors_map.{}'", f.run.out, format)
              : std::string(),
          curves);
    };
    if (draw_figure(scripts_directory() + "/regime_map.gp", definitions, &why)) {
      fmt::print("wrote {0}/regime_map.png, {0}/lambda1_map.png{1} and their .svg\n", f.run.out,
                 o.point.starts > 1 ? fmt::format(", {}/attractors_map.png", f.run.out) : "");
    } else {
      fmt::print(stderr, "pwl map: no figure: {}\n", why);
    }
  };
  run_study(study, f.run);
}

}  // namespace

analysis::RegimeMapOptions map_options(const MapFlags& f) {
  analysis::RegimeMapOptions o;
  const analysis::PointModel model = f.model.model();
  if (model.explicit_structure()) {
    o.structure = model.structure();
  } else {
    o.chain = model.chain();
  }
  o.first.parameter = parse_model_parameter(model, "--x", f.x);
  parse_range("--x-range", f.x_range, &o.first.from, &o.first.to);
  check_range_ends(model, o.first.parameter, "--x-range", f.x_range, o.first.from, o.first.to);
  o.first.points = f.x_points;
  o.second.parameter = parse_model_parameter(model, "--y", f.y);
  check_relation("map", "--y", o.second.parameter.name(), "--x", o.first.parameter.name());
  parse_range("--y-range", f.y_range, &o.second.from, &o.second.to);
  check_range_ends(model, o.second.parameter, "--y-range", f.y_range, o.second.from,
                   o.second.to);
  o.second.points = f.y_points;
  o.mode = f.mode == "continuation" ? analysis::SweepMode::continuation
                                    : analysis::SweepMode::independent;
  o.point = f.point.settings(model.dofs());
  o.point.components.clear();
  o.point.section = f.section.poincare_section(model.dofs());
  if (!o.point.section.stroboscopic()) {
    throw InputError(fmt::format(
        "--section {}: a regime map keeps no Poincaré points, only each cell's regime, λ1 and K, "
        "which are classified on the stroboscopic map (at --phase) whatever the section records; "
        "record a hyperplane section with pwl sweep or pwl analyze",
        f.section.section));
  }
  if (!f.start.at_rest()) o.initial_state = f.start.state(model.dofs());
  std::string why;
  if (!o.is_valid(&why)) throw InputError(why);
  return o;
}

void add_map_flags(CLI::App& c, MapFlags& flags) {
  add_model_flags(c, flags.model);
  c.add_option("--x", flags.x,
               "Horizontal parameter: theta, alpha, zeta, gap or amplitude of the chain;\n"
               "spring<j>.stiffness, spring<j>.gap, load<j>.amplitude, load<j>.frequency or\n"
               "damping of a --structure-scene");
  c.add_option("--x-range", flags.x_range, "FROM:TO of the horizontal parameter");
  c.add_option("--x-points", flags.x_points, "Values of the horizontal parameter")
      ->check(positive_number());
  c.add_option("--y", flags.y, "Vertical parameter");
  c.add_option("--y-range", flags.y_range, "FROM:TO of the vertical parameter");
  c.add_option("--y-points", flags.y_points, "Values of the vertical parameter")
      ->check(positive_number());
  c.add_option("--mode", flags.mode,
               "independent (every cell from rest, or from --x0/--v0) or continuation (each row\n"
               "upward in the horizontal parameter from the previous cell's final state, its\n"
               "first cell from rest or --x0/--v0)")
      ->check(CLI::IsMember({"independent", "continuation"}));
  add_point_flags(c, flags.point, false);
  check_point_flags(c);
  add_section_flags(c, flags.section,
                    "A map keeps no Poincaré points, so only strobe is\n"
                    "accepted: --phase sets the stroboscopic points each cell is classified on");
  add_initial_state_flags(c, flags.start);
  add_run_flags(c, flags.run);
  c.add_option("--curves", flags.curves,
               "Draw over the regime map the bifurcation curves of this folder (written by\n"
               "pwl continue --curves in the map's two parameters)");
}


void add_map_command(CLI::App& app) {
  auto flags = std::make_shared<MapFlags>();
  CLI::App* c = app.add_subcommand(
      "map",
      "Regime map: classify every cell of a two-parameter grid\n"
      "Example: pwl map --figure 5 --x theta --x-range 0.5:3 --x-points 40 --y alpha \\\n"
      "           --y-range 1:15 --y-points 29 --out theta_alpha");
  add_map_flags(*c, *flags);
  c->callback([flags] { map(*flags); });
}

}  // namespace pwl::app
