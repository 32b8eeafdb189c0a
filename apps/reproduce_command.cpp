// pwl reproduce: the paper's figures recomputed and drawn under plots/, with a report of what
// matched the paper and what did not.
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "chain_figures.hpp"
#include "commands.hpp"
#include "five_dof_figures.hpp"
#include "gnuplot.hpp"
#include "paper_scenes.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

struct ReproduceOptions {
  std::string plots;
  bool quick = false;
  std::vector<std::string> only;
};

// What the paper reports for each 5-DOF figure (SPEC.md §5).
int paper_points(const std::string& figure) { return figure == "4a" ? 2 : figure == "4b" ? 7 : 0; }

bool wanted(const ReproduceOptions& o, const std::string& figure) {
  return o.only.empty() || std::find(o.only.begin(), o.only.end(), figure) != o.only.end();
}

void reproduce(const ReproduceOptions& o) {
  for (const std::string& f : o.only) {
    if (f != "4a" && f != "4b" && f != "5-6" && f != "7-9") {
      throw InputError(fmt::format("--only: unknown figure '{}' (expected 4a, 4b, 5-6 or 7-9)", f));
    }
  }
  const std::string plots = o.plots.empty() ? plots_directory() : o.plots;
  // Wall times go to stdout only, so that the report is the same every time it is regenerated.
  std::string report = fmt::format(
      "# pwl reproduce{}\n\n"
      "## Figure 4: the 5-DOF chain, PIM (η = T/200) against kink-located dopri5 (tol 1e-10)\n\n"
      "| figure | paper: Poincaré points | PIM points | reference points | "
      "largest PIM - reference (all steps) | at Poincaré points | attractor size |\n"
      "|---|---|---|---|---|---|---|\n",
      o.quick ? " --quick (smoke run: 300 periods, not the paper's 1000; a 200-mass chain)" : "");
  for (const std::string f : {"4a", "4b"}) {
    if (!wanted(o, f)) continue;
    fmt::print("figure {}: integrating PIM and the dopri5 reference...\n", f);
    std::fflush(stdout);
    const FiveDofFigureResult r = reproduce_five_dof_figure(f, plots, o.quick);
    const std::string line =
        fmt::format("| {} | {} | {} | {} | {:.2e} | {:.2e} | {:.3g} |\n", r.figure, paper_points(f),
                    r.distinct_points, r.reference_distinct_points, r.largest_difference,
                    r.largest_poincare_difference, r.attractor_size);
    fmt::print("{}  (PIM {:.2f} s, reference {:.2f} s)\n", line, r.pim_seconds,
               r.reference_seconds);
    report += line;
  }
  if (wanted(o, "5-6")) {
    const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
    report +=
        "\n## Figures 5 and 6: the shipped scenes apps/scenes/paper_fig5.toml and "
        "paper_fig6.toml\n\n"
        "| figure | paper says | pwl finds | λ1 (per forcing period) | 0-1 test | matches |\n"
        "|---|---|---|---|---|---|\n";
    for (const SceneRegime& r : run_paper_scenes(self, plots, o.quick)) {
      // λ1's error bar is a statistical one, so only the regime goes in the report.
      report += fmt::format("| {} | {} | {} | {} | {} | {} |\n", r.figure, r.paper_regime, r.regime,
                            r.lambda1.substr(0, r.lambda1.find(" ±")), r.zero_one,
                            r.regime == r.paper_regime ? "yes" : "**no**");
    }
  }
  if (wanted(o, "7-9")) {
    const ChainFigureSummary c = reproduce_chain_figures(plots, o.quick);
    report += fmt::format(
        "\n## Figures 7-9: the {}-mass chain of section 4.2, t in [0, 200] s\n\n"
        "Largest error over the run against kink-located rkf78 at tol {:g}.\n\n"
        "| method | x1 (m) | x1' (m/s) |\n|---|---|---|\n"
        "| banded PIM, η = 0.02 s | {:.2e} | {:.2e} |\n"
        "| dopri5, tol 1e-5 (plain, like ode45) | {:.2e} | {:.2e} |\n"
        "| ratio dopri5 / PIM (paper: about 10) | {:.1f} | {:.1f} |\n",
        c.masses, o.quick ? 1e-10 : 1e-12, c.pim_error_x, c.pim_error_v, c.rk_error_x, c.rk_error_v,
        c.rk_error_x / c.pim_error_x, c.rk_error_v / c.pim_error_v);
    if (!c.drawn) throw Error("figures 7-9 were computed but gnuplot could not draw them");
  }
  const std::string path = plots + (o.quick ? "/data/report_quick.md" : "/report.md");
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write the report {}", path));
  fmt::print(f, "{}", report);
  std::fclose(f);
  fmt::print("wrote {}\n", path);
}

}  // namespace

void add_reproduce_command(CLI::App& app) {
  auto options = std::make_shared<ReproduceOptions>();
  CLI::App* c =
      app.add_subcommand("reproduce",
                         "Reproduce the paper's figures under plots/ and report what matched\n"
                         "Example: pwl reproduce            (the whole paper)\n"
                         "         pwl reproduce --quick    (a smoke run in seconds)");
  c->add_option("--plots", options->plots, "Folder for figures and data (default: plots/)");
  c->add_flag("--quick", options->quick, "Short runs, for smoke tests");
  c->add_option("--only", options->only, "Only these figures (4a, 4b, 5-6, 7-9)")->delimiter(',');
  c->callback([options] { reproduce(*options); });
}

}  // namespace pwl::app
