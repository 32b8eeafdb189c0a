#include "bench/bench_curves.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_clock.hpp"
#include "commands/cli_checks.hpp"
#include "output/shell_command.hpp"
#include "output/shipped_files.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

namespace fs = std::filesystem;

struct CurvesBenchOptions {
  int repeats = 1;
  bool quick = false;
  std::string out = "out/bench";
};

// The index-th number (0-based) on the line of `text` that follows the first `prefix`, reading
// unsigned decimals such as 31.28 or 1264 (NaN when absent). Plain string scanning: GCC 12 warns
// (maybe-uninitialized, an error here) inside <regex> under the sanitizers' -O2.
double number_after(const std::string& text, const std::string& prefix, int index = 0) {
  const std::size_t at = text.find(prefix);
  if (at == std::string::npos) return std::nan("");
  const std::size_t begin = at + prefix.size();
  const std::string line = text.substr(begin, text.find('\n', begin) - begin);
  int seen = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const bool digit = std::isdigit(static_cast<unsigned char>(line[i])) != 0;
    if (!digit) continue;
    std::size_t end = i;
    while (end < line.size() &&
           (std::isdigit(static_cast<unsigned char>(line[end])) != 0 || line[end] == '.')) {
      ++end;
    }
    if (seen++ == index) return std::stod(line.substr(i, end - i));
    i = end;
  }
  return std::nan("");
}

struct CurvesRun {
  double wall = 0.0;          // the whole pwl continue --curves run
  double branch_seconds = 0.0, curves_seconds = 0.0;
  double branch_points = 0.0, curve_points = 0.0, curves = 0.0, codim2 = 0.0;
};

void run(const CurvesBenchOptions& o) {
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  fs::create_directories(o.out);
  const std::string work = o.out + "/bench_curves_runs";
  const std::string curves_scene = scenes_directory() + "/theta_alpha_curves.toml";
  const std::string map_scene = scenes_directory() + "/theta_alpha_map.toml";
  std::string curves_sets = " --set output.no_plot=true --set run.quiet=true";
  std::string map_sets = " --set output.no_plot=true --set run.quiet=true";
  if (o.quick) {
    curves_sets += " --set continuation.curves=alpha=4.5:5.5 --set continuation.range=0.9:1.1";
    map_sets += " --set map.x_points=10 --set map.y_points=8 --set map.x_range=0.9:1.1 "
                "--set map.y_range=4.5:5.5 --set run.transient=100 --set run.periods=100";
  }
  std::vector<CurvesRun> curves_runs;
  std::vector<double> map_walls;
  double cells = 0.0;
  for (int r = 0; r < o.repeats; ++r) {
    fs::remove_all(work);
    const auto start = BenchClock::now();
    const std::string printed = captured_output(
        fmt::format("{} run {} --set output.out={}{}", shell_quoted(self),
                    shell_quoted(curves_scene), shell_quoted(work + "/curves"), curves_sets));
    CurvesRun c;
    c.wall = seconds_since(start);
    c.branch_seconds = number_after(printed, "\ntime: ", 0);
    c.branch_points = number_after(printed, "\ntime: ", 1);
    c.curves_seconds = number_after(printed, "curves' time: ", 0);
    c.curve_points = number_after(printed, "curves' time: ", 1);
    c.curves = number_after(printed, "\ncurves (", 0);
    c.codim2 = number_after(printed, "codimension-two points (", 0);
    if (std::isnan(c.codim2)) c.codim2 = 0.0;
    for (const double read : {c.branch_seconds, c.branch_points, c.curves_seconds, c.curve_points,
                              c.curves}) {
      if (std::isnan(read)) {
        throw Error(fmt::format("bench curves: the run of {} did not print its times and counts "
                                "as expected:\n{}",
                                curves_scene, printed));
      }
    }
    curves_runs.push_back(c);
    const auto map_start = BenchClock::now();
    const std::string map_printed = captured_output(
        fmt::format("{} run {} --set output.out={}{}", shell_quoted(self),
                    shell_quoted(map_scene), shell_quoted(work + "/map"), map_sets));
    map_walls.push_back(seconds_since(map_start));
    cells = number_after(map_printed, "map.csv (", 0);
    if (std::isnan(cells)) {
      throw Error(fmt::format("bench curves: the run of {} did not print its cells:\n{}",
                              map_scene, map_printed));
    }
    fmt::print("run {}: curves {:.1f} s, map {:.1f} s\n", r + 1, c.wall, map_walls.back());
    std::fflush(stdout);
  }
  const auto med = [&](auto field) {
    std::vector<double> v;
    for (const CurvesRun& c : curves_runs) v.push_back(field(c));
    return median(v);
  };
  const double branch_s = med([](const CurvesRun& c) { return c.branch_seconds; });
  const double curves_s = med([](const CurvesRun& c) { return c.curves_seconds; });
  const double whole_s = med([](const CurvesRun& c) { return c.wall; });
  const double map_s = median(map_walls);
  const CurvesRun& last = curves_runs.back();
  std::string table = fmt::format(
      "| case ({}, medians of {}) | wall s | points | points / s |\n|---|---|---|---|\n",
      o.quick ? "quick" : "figure 5's chain, theta 0.5..3, alpha 1..15", o.repeats);
  table += fmt::format("| one-parameter continuation in theta (the branch) | {:.2f} | {:.0f} | "
                       "{:.0f} |\n",
                       branch_s, last.branch_points, last.branch_points / branch_s);
  table += fmt::format("| the curves in (theta, alpha): {:.0f} curves, {:.0f} codimension-two "
                       "points | {:.2f} | {:.0f} | {:.0f} |\n",
                       last.curves, last.codim2, curves_s, last.curve_points,
                       last.curve_points / curves_s);
  table += fmt::format("| the whole run (branch and curves, pwl run {}) | {:.2f} | | |\n",
                       fs::path(curves_scene).filename().string(), whole_s);
  table += fmt::format("| the brute-force regime map of the same range (pwl run {}, {:.0f} "
                       "cells, both cores) | {:.2f} | {:.0f} cells | |\n",
                       fs::path(map_scene).filename().string(), cells, map_s, cells);
  table += fmt::format("\nThe curve set in {:.2f} s against the map's {:.2f} s: {:.2f}x {}.\n",
                       whole_s, map_s, whole_s < map_s ? map_s / whole_s : whole_s / map_s,
                       whole_s < map_s ? "faster" : "slower");
  fmt::print("\n{}", table);
  const auto open = [&](const std::string& name) {
    std::FILE* f = std::fopen((o.out + "/" + name).c_str(), "w");
    if (f == nullptr) throw Error(fmt::format("cannot write {}/{}", o.out, name));
    return f;
  };
  {
    std::FILE* f = open("bench_curves.md");
    fmt::print(f, "{}", table);
    std::fclose(f);
  }
  {
    std::FILE* f = open("bench_curves.csv");
    fmt::print(f,
               "case,wall_seconds,points,points_per_second\nbranch,{0:.17g},{1},{2:.17g}\n"
               "curves,{3:.17g},{4},{5:.17g}\nwhole,{6:.17g},,\nmap,{7:.17g},{8},\n",
               branch_s, last.branch_points, last.branch_points / branch_s, curves_s,
               last.curve_points, last.curve_points / curves_s, whole_s, map_s, cells);
    std::fclose(f);
  }
  fmt::print("\nwrote {0}/bench_curves.csv and {0}/bench_curves.md\n", o.out);
}

}  // namespace

void add_curves_bench(CLI::App& bench) {
  auto o = std::make_shared<CurvesBenchOptions>();
  CLI::App* c = bench.add_subcommand(
      "curves",
      "Bifurcation curves in two parameters against one-parameter continuation (points per\n"
      "second) and against the brute-force regime map of the same range (wall time)\n"
      "Example: pwl bench curves --out out/bench");
  c->add_option("--repeats", o->repeats, "Runs of each (median)")->check(positive_number());
  c->add_flag("--quick", o->quick, "Small cases, a smoke test");
  c->add_option("--out", o->out, "Folder for bench_curves.csv and bench_curves.md");
  c->callback([o] { run(*o); });
}

}  // namespace pwl::app
