// pwl bench: speed and accuracy measurements, printed as tables and written as CSV.
//   pwl bench chain      the paper's Table 1 (section 4.2 chain), measured side by side
//   pwl bench scaling    time per step and memory of the banded PIM as the chain grows
//   pwl bench accuracy   work-precision diagrams (accuracy_bench.hpp)
//   pwl bench stability  where each method breaks as the contacts stiffen (accuracy_bench.hpp)
//   pwl bench sweep      a θ sweep of the 5-DOF chain (bench_sweep.hpp)
//   pwl bench orbits     periodic orbits by shooting against brute force, continuation (bench_orbits.hpp)
//   pwl bench soak       a sweep killed at random and resumed, 20 times: the same files (bench_soak.hpp)
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands/cli_checks.hpp"
#include "pwl/integrators/accuracy_step.hpp"
#include "bench/accuracy_bench.hpp"
#include "bench/bench_chain.hpp"
#include "bench/bench_curves.hpp"
#include "bench/bench_orbits.hpp"
#include "bench/bench_scaling.hpp"
#include "bench/bench_soak.hpp"
#include "bench/bench_sweep.hpp"
#include "bench/chain_figures.hpp"
#include "pwl/errors.hpp"
#include "commands/commands.hpp"

namespace pwl::app {
namespace {

void add_chain(CLI::App& bench) {
  auto o = std::make_shared<ChainBenchOptions>();
  CLI::App* c = bench.add_subcommand(
      "chain",
      "The paper's Table 1: its section 4.2 chain (n = 1000, t in [0, 200] s) by the banded PIM,\n"
      "the banded switching PIM, the dense PIM and dopri5, with the largest error of x1 and x1'\n"
      "against a reference, and the fastest pwl row as accurate as each dopri5 row\n"
      "Example: pwl bench chain --out out/bench\n"
      "         pwl run apps/scenes/paper_fig7-9_table1.toml   (the paper's methods, figures 7-9)");
  c->add_option("--n", o->masses, "Number of masses")->check(number_in(2, 100000000));
  c->add_option("--t-end", o->t_end, "End of the run (s)")->check(positive_number());
  c->add_option("--runs", o->runs, "Timed runs per method (median)")->check(positive_number());
  c->add_option("--dense-runs", o->dense_runs, "Timed runs of the dense PIM")
      ->check(positive_number());
  c->add_option("--step", o->paper_step, "The paper's step (s)")->check(positive_number());
  c->add_option("--wished-step", o->wished_step, "η1 given to the step rule (s)")
      ->check(positive_number());
  c->add_option("--rule-bands", o->rule_bands, "q given to the step rule, comma separated")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--reference-tol", o->reference_tolerance, "Tolerance of the reference")
      ->check(positive_number());
  c->add_option("--reference-grid", o->reference_grid,
                "Spacing of the reference's recorded points (s)")
      ->check(positive_number());
  c->add_flag("!--no-reference-check", o->reference_check,
              "Skip the second reference that bounds the first's error");
  c->add_option("--switching-steps", o->switching_steps,
                "Steps of the banded switching PIM rows (s), comma separated")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--switching-degrees", o->switching_degrees,
                "Force degrees d of the banded switching PIM rows (order d + 3), comma separated:\n"
                "one row per step and degree")
      ->delimiter(',')
      ->check(number_in(0, 8));
  c->add_option("--rtol-rows", o->accuracy_requests,
                "Accuracy requests (--rtol) of the banded switching PIM rows, comma separated:\n"
                "the step chosen on the loads' first two periods, choice and run timed together")
      ->delimiter(',')
      ->check(positive_number())
      ->check(number_in(kSmallestRelativeTolerance, 0.5));
  c->add_option("--floor-steps", o->floor_steps,
                "Steps of the floor table (s), comma separated: one bare product T v timed at\n"
                "each, times the run's steps")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--methods", o->methods,
                "Only these methods: pim-banded, pim-rule, pim-switching, pim-rtol, pim-dense, dopri5-1e-5, "
                "dopri5-1e-10, dopri5-1e-5-kinks, dopri5-1e-10-kinks")
      ->delimiter(',');
  c->add_flag("--without-dense", o->without_dense,
              "Leave the dense PIM out (it takes minutes per run at n = 1000)");
  c->add_option("--out", o->out, "Folder for bench_chain.csv and the cached reference");
  c->add_flag("--figures", o->figures,
              "Also draw the paper's figures 7-9 into --out (needs pim-banded and dopri5-1e-5)");
  c->add_flag("--quiet", o->quiet, "Print only the table");
  c->callback([o] {
    if (o->figures && !o->methods.empty()) {
      for (const char* needed : {"pim-banded", "dopri5-1e-5"}) {
        if (std::find(o->methods.begin(), o->methods.end(), needed) == o->methods.end())
          throw InputError(fmt::format("--figures needs {} in --methods", needed));
      }
    }
    const ChainBenchResult r = run_chain_bench(*o);
    const std::string table = format_chain_table(r);
    fmt::print("{}", table);
    if (std::FILE* f = std::fopen((o->out + "/bench_chain.md").c_str(), "w")) {
      fmt::print(f, "{}", table);
      std::fclose(f);
    }
    fmt::print("\nwrote {0}/bench_chain.csv and {0}/bench_chain.md\n", o->out);
    std::string why;
    if (o->figures) {
      if (draw_chain_figures(r, o->out, &why)) {
        fmt::print("wrote {0}/fig7.png, {0}/fig8.png, {0}/fig9.png and their .svg\n", o->out);
      } else {
        fmt::print(stderr, "pwl bench chain: figures 7-9 not drawn: {}\n", why);
      }
    }
  });
}

void add_scaling(CLI::App& bench) {
  auto o = std::make_shared<ScalingBenchOptions>();
  auto single = std::make_shared<long>(0);
  auto unshared = std::make_shared<bool>(false);
  CLI::App* c = bench.add_subcommand(
      "scaling",
      "Time per step and peak memory of the banded PIM for n = 1000 ... 10^6, beside the bare\n"
      "banded products of one step, on one thread and on all (OpenMP row blocks from 10^5 rows)\n"
      "Example: pwl bench scaling --sizes 1000,16000,256000,1000000");
  c->add_option("--sizes", o->sizes, "Numbers of masses, comma separated")
      ->delimiter(',')
      ->check(number_at_least(2));
  c->add_option("--step", o->step, "Step (s)")->check(positive_number());
  c->add_option("--steps", o->steps, "Timed steps per repeat")->check(positive_number());
  c->add_option("--repeats", o->repeats, "Repeats (median)")->check(positive_number());
  c->add_option("--work", o->work,
                "Mass-steps each size repeats to at least (at most 200 repeats): small chains "
                "repeat more")
      ->check(positive_number());
  c->add_flag("--unshared", *unshared,
              "Store every operator row (no sharing of identical rows): the memory-bound case");
  c->add_option("--out", o->out, "Folder for bench_scaling.csv");
  c->add_flag("--quiet", o->quiet, "Print only the table");
  c->add_option("--single", *single, "Internal: run one size and print one line")
      ->check(naming("--single", non_negative_number()))
      ->group("");  // hidden
  c->callback([o, single, unshared] {
    o->share_rows = !*unshared;
    if (*single > 0) {
      run_scaling_single(*single, *o);
      return;
    }
    const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
    const std::vector<ScalingRow> rows = run_scaling_bench(*o, self);
    const std::string table = format_scaling_table(rows, *o);
    fmt::print("{}", table);
    if (std::FILE* f = std::fopen((o->out + "/bench_scaling.md").c_str(), "w")) {
      fmt::print(f, "{}", table);
      std::fclose(f);
    }
    fmt::print("\nwrote {0}/bench_scaling.csv and {0}/bench_scaling.md\n", o->out);
  });
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks: print tables and write CSV");
  bench->require_subcommand(1);
  add_chain(*bench);
  add_scaling(*bench);
  add_accuracy_benches(*bench);
  add_sweep_bench(*bench);
  add_orbits_bench(*bench);
  add_curves_bench(*bench);
  add_soak_bench(*bench);
}

}  // namespace pwl::app
