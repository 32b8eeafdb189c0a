// pwl reproduce: runs every shipped scene of the paper's figures and table (and the project's
// sweep and map), as a user would (`pwl run SCENE`), copies their figures under plots/ and writes
// plots/report.md: what matched the paper and what did not. The report holds no wall times, so
// that regenerating it gives the same file.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "commands/commands.hpp"
#include "output/gnuplot.hpp"
#include "paper/paper_scenes.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

namespace fs = std::filesystem;

// The table of bifurcations.csv (pwl continue) in Markdown: one row per bifurcation, in the order
// found.
std::string bifurcation_table(const std::string& csv) {
  std::ifstream in(csv);
  if (!in) throw Error(fmt::format("cannot read {}", csv));
  std::string line;
  std::getline(in, line);  // header
  std::string table =
      "| type | θ | branch | period | spring | multiplier | detail |\n|---|---|---|---|---|---|---|\n";
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');) f.push_back(cell);
    if (f.size() < 9) throw Error(fmt::format("{}: a short row: {}", csv, line));
    const std::string multiplier =
        f[5].empty() ? "" : fmt::format("{:.6f}{:+.6f}i", std::stod(f[5]), std::stod(f[6]));
    table += fmt::format("| {} | {:.10f} | {} | {} | {} | {} | {} |\n", f[0], std::stod(f[1]), f[2],
                         f[3], f[4], multiplier, f[8]);
  }
  return table;
}

// The curves of a pwl continue --curves folder in Markdown: how many of each type, then one row per
// codimension-two point (codim2.csv), in the order found.
std::string curves_table(const std::string& folder) {
  std::map<std::string, std::set<std::string>> kinds;  // type -> curve ids
  {
    std::ifstream in(folder + "/curves.csv");
    if (!in) throw Error(fmt::format("cannot read {}/curves.csv", folder));
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::stringstream fields(line);
      std::string curve, type;
      std::getline(fields, curve, ',');
      std::getline(fields, type, ',');
      kinds[type].insert(curve);
    }
  }
  std::string text = "Curves followed:";
  for (const auto& [type, ids] : kinds) text += fmt::format(" {} {};", ids.size(), type);
  text.back() = '.';
  text += "\n\n| type | θ | α | curves | detail |\n|---|---|---|---|---|\n";
  std::ifstream in(folder + "/codim2.csv");
  if (!in) throw Error(fmt::format("cannot read {}/codim2.csv", folder));
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string cell; std::getline(fields, cell, ',');) f.push_back(cell);
    if (f.size() < 4) throw Error(fmt::format("{}/codim2.csv: a short row: {}", folder, line));
    text += fmt::format("| {} | {:.10f} | {:.10f} | {} | {} |\n", f[0], std::stod(f[1]),
                        std::stod(f[2]), f[3], f.size() > 4 ? f[4] : "");
  }
  return text;
}

struct ReproduceOptions {
  std::string plots;
  bool quick = false;
  std::vector<std::string> only;
};

// What the paper states for each figure (SPEC.md §5).
const std::map<std::string, std::string>& paper_says() {
  static const std::map<std::string, std::string> says{
      {"4a", "period-2"}, {"4b", "period-7"}, {"5", "chaotic"}, {"6", "quasi-periodic"}};
  return says;
}

// "period-7" -> 7 (0 for a regime that is not periodic).
int period_of(const std::string& regime) {
  return regime.rfind("period-", 0) == 0 ? std::stoi(regime.substr(7)) : 0;
}

// The number at the start of `text` (NaN when there is none).
double number_at(const std::string& text) {
  try {
    return std::stod(text);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

// One row of bench_chain.csv by its key: the largest errors of x1 and x1', the median wall time.
struct ChainRow {
  double error_x, error_v, wall;
};
ChainRow chain_row(const std::string& csv, const std::string& key) {
  std::ifstream in(csv);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ",", 0) != 0) continue;
    // 0 key, 1 "label", 2 "parameters", 3 runs, 4 wall, 5 cpu, 6 setup, 7 steps, 8 work,
    // 9 error_x1, 10 error_v1, ...
    std::vector<std::string> fields;
    bool quoted = false;
    std::string field;
    for (char c : line) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted)
        fields.push_back(field), field.clear();
      else
        field += c;
    }
    fields.push_back(field);
    if (fields.size() > 10)
      return {number_at(fields[9]), number_at(fields[10]), number_at(fields[4])};
  }
  throw Error(fmt::format("{}: no row for {}", csv, key));
}

std::string five_dof_comparison_row(const std::string& key, const std::string& printed) {
  // "distinct Poincaré points of mass 5: 2 (dopri5, kink-located, tol 1e-10: 2); cloud size 1.32"
  const std::string points = line_after(printed, "distinct Poincaré points of mass 5: ");
  const int pim = static_cast<int>(number_at(points));
  const std::size_t colon = points.rfind(": ");
  const int reference =
      colon == std::string::npos ? -1 : static_cast<int>(number_at(points.substr(colon + 2)));
  const std::string size = line_after(points, "cloud size ");
  const int paper = period_of(paper_says().at(key));
  return fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", key, paper_says().at(key), pim,
                     reference,
                     line_after(printed, "largest difference (every x and x', every step): "),
                     line_after(printed, "largest difference at the Poincaré points: "), size,
                     pim == paper && reference == paper ? "yes" : "**no**");
}

void copy_figures(const ReproducedScene& s, const std::string& from, const std::string& to) {
  for (const auto& [made, name] : s.figures) {
    for (const char* extension : {".png", ".svg"}) {
      const fs::path source = fs::path(from) / (made + extension);
      if (!fs::exists(source)) {
        fmt::print(stderr, "pwl reproduce: {} did not draw {} (is gnuplot installed?)\n", s.scene,
                   source.string());
        continue;
      }
      fs::copy_file(source, fs::path(to) / (name + extension),
                    fs::copy_options::overwrite_existing);
    }
  }
}

// The keys --only names, with "paper" (the paper's figures and table) and "studies" (pwl's own)
// standing for their scenes. Throws InputError for a name that is neither a key nor a group.
std::vector<std::string> only_keys(const std::vector<std::string>& only,
                                   const std::vector<ReproducedScene>& scenes) {
  std::vector<std::string> keys;
  for (const std::string& name : only) {
    if (name == "paper" || name == "studies") {
      for (const ReproducedScene& s : scenes) {
        if (s.paper == (name == "paper")) keys.push_back(s.key);
      }
      continue;
    }
    if (std::none_of(scenes.begin(), scenes.end(), [&](const auto& s) { return s.key == name; })) {
      std::vector<std::string> all;
      for (const ReproducedScene& s : scenes) all.push_back(s.key);
      throw InputError(fmt::format("--only: unknown figure '{}' (expected paper, studies, {})",
                                   name, fmt::join(all, ", ")));
    }
    keys.push_back(name);
  }
  return keys;
}

void reproduce(const ReproduceOptions& options) {
  const std::vector<ReproducedScene>& scenes = reproduced_scenes();
  ReproduceOptions o = options;
  o.only = only_keys(options.only, scenes);
  const std::string plots = o.plots.empty() ? plots_directory() : o.plots;
  // A smoke run keeps its data, figures and report apart under data/quick, so that it never
  // replaces the committed figures nor the data of a full run.
  const std::string data = o.quick ? plots + "/data/quick" : plots + "/data";
  const std::string figures = o.quick ? data + "/figures" : figures_directory(plots);
  fs::create_directories(figures);
  const std::string self = fs::read_symlink("/proc/self/exe").string();

  std::string report = fmt::format(
      "# pwl reproduce{}\n\nEach row comes from a shipped scene (apps/scenes/), run as "
      "`pwl run SCENE`.\n",
      o.quick ? " --quick (a smoke run: shorter runs, a 200-mass chain, small grids; not the "
                "paper's settings)"
              : "");
  std::string five_dof, regimes, chain, charts, bifurcations, curves;
  int done = 0, wanted = 0;
  // Seconds spent on the paper's scenes and on pwl's own studies, and how many of each ran.
  double part_seconds[2] = {0.0, 0.0};
  int part_scenes[2] = {0, 0};
  int paper_wanted = 0;
  for (const ReproducedScene& s : scenes) {
    const bool run = o.only.empty() || std::count(o.only.begin(), o.only.end(), s.key) > 0;
    wanted += run;
    paper_wanted += run && s.paper;
  }
  for (const ReproducedScene& s : scenes) {
    if (!o.only.empty() && std::count(o.only.begin(), o.only.end(), s.key) == 0) continue;
    const std::string out = fmt::format("{}/{}", data, fs::path(s.scene).stem().string());
    // A fresh run (sweeps and maps would otherwise ask for --resume), unless the scene continues
    // an earlier one's (the same scene file, so the same folder).
    if (s.continues.empty()) {
      fs::remove_all(out);
    } else if (!fs::exists(out)) {
      throw InputError(fmt::format("--only {0}: it draws again over the run of {1}, which {2} has "
                                   "not: run --only {1},{0}",
                                   s.key, s.continues, data));
    }
    fmt::print("[{}/{}] pwl run {}/{}{}\n", ++done, wanted, scenes_directory(), s.scene,
               o.quick ? " (quick)" : "");
    std::fflush(stdout);
    const auto start = std::chrono::steady_clock::now();
    const std::string printed = run_scene(self, s, out, data, o.quick);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    copy_figures(s, out, figures);
    if (s.key == "4a" || s.key == "4b") {
      const std::string row = five_dof_comparison_row(s.key, printed);
      five_dof += row;
      fmt::print("  {}", row);
    } else if (s.key == "5" || s.key == "6") {
      const std::string regime = line_after(printed, "regime: ");
      const std::string lambda = line_after(printed, "lambda1: ");
      const std::string k = line_after(printed, "0-1 test: ");
      if (regime.empty()) throw Error(fmt::format("{} printed no regime:\n{}", s.scene, printed));
      // λ1's error bar is a statistical one, so only the value goes in the report.
      regimes += fmt::format("| {} | {} | {} | {} | {} | {} |\n", s.key, paper_says().at(s.key),
                             regime, lambda.substr(0, lambda.find(" ±")), k,
                             regime == paper_says().at(s.key) ? "yes" : "**no**");
      fmt::print("  the paper says {}, pwl finds {} (λ1 {}; {})\n", paper_says().at(s.key), regime,
                 lambda, k);
    } else if (s.key == "7-9") {
      const std::string csv = out + "/bench_chain.csv";
      const auto [pim_x, pim_v, pim_wall] = chain_row(csv, "pim-banded");
      const auto [rk_x, rk_v, rk_wall] = chain_row(csv, "dopri5-1e-5");
      const auto [tight_x, tight_v, tight_wall] = chain_row(csv, "dopri5-1e-10");
      chain += fmt::format(
          "| banded PIM, η = 0.02 s | {:.2e} | {:.2e} | 1 |\n"
          "| dopri5, tol 1e-5 (plain, like ode45) | {:.2e} | {:.2e} | {:.1f} (paper: about 10) |\n"
          "| dopri5, tol 1e-10 (plain) | {:.2e} | {:.2e} | {:.1e} |\n",
          pim_x, pim_v, rk_x, rk_v, rk_x / pim_x, tight_x, tight_v, tight_x / pim_x);
      chain += fmt::format(
          "\nThe paper's accuracy claim, the PIM about 10 times more accurate than ode45 at 1e-5 "
          "in x1: **{}** ({:.1f} times). Its speed claims, ode45 5.0 and 55.7 times slower than "
          "the PIM at 1e-5 and 1e-10, against dopri5 here (judged against half the paper's "
          "ratios; the wall times themselves vary from run to run and are in "
          "data/paper_fig7-9_table1/bench_chain.md; plots/README.md, \"Figures 7-9 and Table 1\", says why): "
          "**{}** at 1e-5, **{}** at 1e-10.\n",
          rk_x / pim_x >= 5.0 ? "holds" : "does not hold", rk_x / pim_x,
          rk_wall / pim_wall >= 2.5 ? "holds" : "does not hold",
          tight_wall / pim_wall >= 27.85 ? "holds" : "does not hold");
      fmt::print(
          "  largest error of x1: banded PIM {:.2e} m, dopri5 1e-5 {:.2e} m (ratio {:.1f})\n",
          pim_x, rk_x, rk_x / pim_x);
      fmt::print("  wall times (they vary, so they stay out of the report): {}/bench_chain.md\n",
                 out);
    } else {
      for (const auto& [made, name] : s.figures)
        charts += fmt::format("- {}: `{}`\n", name, s.scene);
      if (s.key == "continuation") bifurcations = bifurcation_table(out + "/bifurcations.csv");
      if (s.key == "theta-alpha-curves") curves = curves_table(out);
    }
    fmt::print("  done in {:.1f} s\n", seconds);
    part_seconds[s.paper ? 0 : 1] += seconds;
    ++part_scenes[s.paper ? 0 : 1];
    if (s.paper && part_scenes[0] == paper_wanted) {
      fmt::print("the paper's figures and table: {} scene(s) in {:.1f} s, drawn in {}{}\n",
                 part_scenes[0], part_seconds[0], figures,
                 wanted > paper_wanted ? "; pwl's own studies follow (--only paper skips them)"
                                       : "");
    }
    std::fflush(stdout);
  }
  if (part_scenes[1] > 0) {
    fmt::print("pwl's own studies: {} scene(s) in {:.1f} s\n", part_scenes[1], part_seconds[1]);
  }
  if (!five_dof.empty()) {
    report +=
        "\n## Figures 4a and 4b: the 5-DOF chain, PIM (η = T/200) against kink-located dopri5 "
        "(tol 1e-10) on the same grid\n\n"
        "| figure | paper | PIM: distinct Poincaré points | reference: distinct points | "
        "largest PIM - reference (all states, all steps) | at the Poincaré points | size of the "
        "Poincaré cloud | matches |\n|---|---|---|---|---|---|---|---|\n" +
        five_dof;
  }
  if (!regimes.empty()) {
    report +=
        "\n## Figures 5 and 6: the motion classified (pwl analyze)\n\n"
        "| figure | paper says | pwl finds | λ1 (per forcing period) | 0-1 test | matches |\n"
        "|---|---|---|---|---|---|\n" +
        regimes;
  }
  if (!chain.empty()) {
    report +=
        "\n## Figures 7-9 and Table 1: the section 4.2 chain, t in [0, 200] s\n\n"
        "Largest error over the run against kink-located rkf78. Wall times are in "
        "data/paper_fig7-9_table1/bench_chain.md (they vary from run to run).\n\n"
        "| method | x1 (m) | x1' (m/s) | error x1 / banded PIM |\n|---|---|---|---|\n" +
        chain;
  }
  if (!charts.empty()) report += "\n## The project's own charts\n\n" + charts;
  if (!bifurcations.empty()) {
    report +=
        "\n## The 5-DOF chain's periodic orbits in θ (pwl continue): the bifurcations found\n\n"
        "Figure 5's chain (α = 5, ζ = 0.2, Δ̃ = 0), its period-1 orbit followed from θ = 0.5 by "
        "pseudo-arclength continuation on the exact solver, and the period-2k branches born at its "
        "period doublings; every bifurcation located on its branch (pwl continue's "
        "bifurcations.csv). Spring j is the gap spring of mass j.\n\n" +
        bifurcations;
  }
  if (!curves.empty()) {
    report +=
        "\n## The 5-DOF chain's bifurcation curves in (θ, α) (pwl continue --curves)\n\n"
        "Figure 5's chain, its period-1 branch in θ over [0.5, 3] at α = 5, and every fold, period "
        "doubling, Neimark–Sacker point and grazing located on it followed in (θ, α) over α in "
        "[1, 15]; their codimension-two points (pwl continue's codim2.csv), each located on its "
        "curves. Spring j is the gap spring of mass j.\n\n" +
        curves;
  }
  // Only the whole run replaces plots/report.md.
  const std::string path = o.quick          ? data + "/report_quick.md"
                           : o.only.empty() ? plots + "/report.md"
                                            : data + "/report_only.md";
  std::ofstream(path) << report;
  fmt::print("wrote {} and the figures in {}\n", path, figures);
}

}  // namespace

void add_reproduce_command(CLI::App& app) {
  auto options = std::make_shared<ReproduceOptions>();
  CLI::App* c = app.add_subcommand(
      "reproduce",
      "Run every shipped scene of the paper's figures and table, draw them under plots/figures and\n"
      "report what matched the paper (plots/report.md)\n"
      "The paper's figures and table come first (about 30 s on 2 idle cores), pwl's own studies\n"
      "after them (about 5 minutes); each is printed with its time.\n"
      "Example: pwl reproduce\n"
      "         pwl reproduce --only paper    (the paper's figures and table only)\n"
      "         pwl reproduce --only 4a,7-9\n"
      "         pwl reproduce --quick      (a smoke run in seconds; all it writes in plots/data/quick)");
  c->add_option("--plots", options->plots, "Plots folder: figures/, data/ and report.md (default: plots/)");
  c->add_flag("--quick", options->quick, "Short runs, for smoke tests");
  c->add_option("--only", options->only,
                "Only these: 4a, 4b, 5, 6, 7-9 (or paper: all five), theta-sweep,\n"
                "theta-alpha-map, continuation, basins, theta-alpha-curves,\n"
                "theta-alpha-map-curves (or studies: all six; the last draws the map of\n"
                "theta-alpha-map again, with the curves of theta-alpha-curves over it)")
      ->delimiter(',');
  c->callback([options] { reproduce(*options); });
}

}  // namespace pwl::app
