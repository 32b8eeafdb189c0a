// pwl reproduce: the paper's figures recomputed and drawn under plots/, with a report of what
// matched the paper and what did not.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "five_dof_figures.hpp"
#include "gnuplot.hpp"

namespace pwl::app {
namespace {

struct ReproduceOptions {
  std::string plots;
  bool quick = false;
  std::vector<std::string> only;
};

// What the paper reports for each 5-DOF figure (SPEC.md §5).
int paper_points(const std::string& figure) { return figure == "4a" ? 2 : figure == "4b" ? 7 : 0; }

void reproduce(const ReproduceOptions& o) {
  const std::string plots = o.plots.empty() ? plots_directory() : o.plots;
  std::vector<std::string> figures = o.only.empty() ? std::vector<std::string>{"4a", "4b"} : o.only;
  std::string report = fmt::format(
      "# pwl reproduce{}\n\n| figure | paper: Poincaré points | PIM points | reference points | "
      "largest PIM - reference (all steps) | at Poincaré points | attractor size | PIM s | "
      "reference s |\n|---|---|---|---|---|---|---|---|---|\n",
      o.quick ? " --quick (smoke run: 300 periods, not the paper's 1000)" : "");
  for (const std::string& f : figures) {
    fmt::print("figure {}: integrating PIM and the dopri5 reference...\n", f);
    std::fflush(stdout);
    const FiveDofFigureResult r = reproduce_five_dof_figure(f, plots, o.quick);
    const std::string line = fmt::format(
        "| {} | {} | {} | {} | {:.2e} | {:.2e} | {:.3g} | {:.2f} | {:.2f} |\n", r.figure,
        paper_points(f), r.distinct_points, r.reference_distinct_points, r.largest_difference,
        r.largest_poincare_difference, r.attractor_size, r.pim_seconds, r.reference_seconds);
    fmt::print("{}", line);
    report += line;
  }
  const std::string path = plots + (o.quick ? "/data/report_quick.md" : "/report.md");
  if (std::FILE* f = std::fopen(path.c_str(), "w")) {
    fmt::print(f, "{}", report);
    std::fclose(f);
    fmt::print("wrote {}\n", path);
  }
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
  c->add_option("--only", options->only, "Only these figures (4a, 4b)")->delimiter(',');
  c->callback([options] { reproduce(*options); });
}

}  // namespace pwl::app
