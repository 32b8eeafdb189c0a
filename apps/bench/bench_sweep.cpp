#include "bench/bench_sweep.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <vector>

#include "bench/bench_clock.hpp"
#include "commands/cli_checks.hpp"
#include "pwl/study/parameter_grid.hpp"
#include "pwl/study/parameter_sweep.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/pim_integrator.hpp"
#include "pwl/integrators/reference_integrator.hpp"

namespace pwl::app {
namespace {

struct SweepBenchOptions {
  int points = 1000;
  double from = 0.5;
  double to = 3.0;
  int transient = 500;
  int periods = 500;
  int steps_per_period = 200;
  int repeats = 3;          // of the whole sweep
  int stepper_repeats = 5;  // of the throughput measurement
  int dopri5_every = 50;    // dopri5 timed on every k-th point
  int efficiency_points = 16;
  std::string out = "plots/data";
  bool quiet = false;
};

analysis::SweepOptions sweep_of(const SweepBenchOptions& o) {
  analysis::SweepOptions s;
  s.chain = paper_five_dof_case("5");  // α = 5, ζ = 0.2, Δ̃ = 0, Q = (1, -1, 1, -1, 1)
  s.parameter = analysis::SweepParameter::theta;
  s.from = o.from;
  s.to = o.to;
  s.points = o.points;
  s.point.transient_periods = o.transient;
  s.point.recorded_periods = o.periods;
  s.point.steps_per_period = o.steps_per_period;
  s.point.components = {4, 9};
  std::string why;
  if (!s.is_valid(&why)) throw InputError("bench sweep: " + why);
  return s;
}

// Wall time of the points `ids` of the sweep on `threads` threads.
double time_points(const analysis::SweepOptions& s, const std::vector<long>& ids, int threads,
                   const analysis::PointSettings& settings) {
  std::vector<analysis::GridTask> tasks;
  for (long id : ids) tasks.push_back({{id}, false, {}});
  const auto start = std::chrono::steady_clock::now();
  analysis::run_grid(
      tasks, [&](long id) { return s.chain_of(id); }, s.start_state(), settings, {},
      [](long, const analysis::PointResult&) {}, {threads});
  return seconds_since(start);
}

// Largest difference of the Poincaré points (full state) over `periods` periods from rest.
double poincare_error(const NondimensionalChain& chain, Integrator& method, Integrator& reference,
                      int periods) {
  const Vector rest = Vector::Zero(chain.masses);
  method.set_state(0.0, rest, rest);
  reference.set_state(0.0, rest, rest);
  double worst = 0.0;
  for (int k = 1; k <= periods; ++k) {
    method.advance_to(k * chain.period());
    reference.advance_to(k * chain.period());
    worst = std::max({worst, (method.position() - reference.position()).cwiseAbs().maxCoeff(),
                      (method.velocity() - reference.velocity()).cwiseAbs().maxCoeff()});
  }
  return worst;
}

std::unique_ptr<Integrator> pim_of(const GapStructure& s, double step) {
  PimOptions p;
  p.step = step;
  return make_pim_integrator(s, p);
}

std::unique_ptr<Integrator> dopri5(const GapStructure& s, double period, double tol) {
  ReferenceOptions r;
  r.method = RungeKuttaMethod::dopri5;
  r.relative_tolerance = r.absolute_tolerance = tol;
  r.locate_kinks = true;
  r.max_step = period / 8;
  return make_reference_integrator(s, r);
}

void run(const SweepBenchOptions& o) {
  const int cores = omp_get_max_threads();
  const analysis::SweepOptions sweep = sweep_of(o);
  auto say = [&](const std::string& text) {
    if (!o.quiet) fmt::print(stderr, "{}\n", text);
  };

  // 1. Stepper throughput on one core: figure 5's case, 2e6 steps per repeat.
  say("measuring the 5-DOF PIM stepper on one core ...");
  std::vector<double> rates;
  {
    const NondimensionalChain c = paper_five_dof_case("5");
    const GapStructure s = make_chain(c);
    auto pim = pim_of(s, c.period() / o.steps_per_period);
    const long periods = 10000;
    for (int r = 0; r < o.stepper_repeats; ++r) {
      pim->set_state(0.0, Vector::Zero(5), Vector::Zero(5));
      const auto start = std::chrono::steady_clock::now();
      pim->advance_to(static_cast<double>(periods) * c.period());
      rates.push_back(static_cast<double>(periods * o.steps_per_period) / seconds_since(start));
    }
  }
  const double rate = median(rates);

  // 2. Parallel efficiency: the same points on 1 thread and on all.
  say(fmt::format("measuring parallel efficiency on {} threads ...", cores));
  std::vector<long> sample;
  for (int i = 0; i < o.efficiency_points; ++i) {
    sample.push_back(static_cast<long>(i) * (o.points - 1) / std::max(1, o.efficiency_points - 1));
  }
  std::vector<double> one, all;
  for (int r = 0; r < o.repeats; ++r) {
    one.push_back(time_points(sweep, sample, 1, sweep.point));
    all.push_back(time_points(sweep, sample, cores, sweep.point));
  }
  const double efficiency = median(one) / (cores * median(all));

  // 3a. The whole sweep by the PIM.
  std::vector<long> every(static_cast<std::size_t>(o.points));
  for (int i = 0; i < o.points; ++i) every[static_cast<std::size_t>(i)] = i;
  std::vector<double> walls;
  for (int r = 0; r < o.repeats; ++r) {
    say(fmt::format("PIM sweep of {} points, run {} of {} ...", o.points, r + 1, o.repeats));
    walls.push_back(time_points(sweep, every, cores, sweep.point));
  }
  const double wall = median(walls);
  const double total_steps = static_cast<double>(o.points) * (o.transient + o.periods) *
                             o.steps_per_period;

  // 3b. The dopri5 tolerance that matches the PIM's Poincaré-point accuracy: errors over the first
  // 10 periods from rest against dopri5 at 1e-12, at three values of θ, largest over them.
  say("calibrating the dopri5 tolerance ...");
  double pim_error = 0.0;
  std::map<double, double> dopri_error;
  const std::vector<double> tolerances{1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  for (double theta : {0.75, 1.5, 2.5}) {
    const NondimensionalChain c = analysis::with_parameter(sweep.chain, sweep.parameter, theta);
    const GapStructure s = make_chain(c);
    auto reference = dopri5(s, c.period(), 1e-12);
    auto pim = pim_of(s, c.period() / o.steps_per_period);
    pim_error = std::max(pim_error, poincare_error(c, *pim, *reference, 10));
    for (double tol : tolerances) {
      auto d = dopri5(s, c.period(), tol);
      dopri_error[tol] = std::max(dopri_error[tol], poincare_error(c, *d, *reference, 10));
    }
  }
  double tolerance = tolerances.back();
  for (double tol : tolerances) {  // the largest tolerance at least as accurate as the PIM
    if (dopri_error[tol] <= pim_error) {
      tolerance = tol;
      break;
    }
  }

  // 3c. dopri5 and the PIM on the same subset of points.
  std::vector<long> subset;
  for (int i = 0; i < o.points; i += o.dopri5_every) subset.push_back(i);
  analysis::PointSettings by_dopri5 = sweep.point;
  by_dopri5.method.method = Method::dopri5;  // kink-located, as the sweep's points always were
  by_dopri5.method.tolerance = tolerance;
  by_dopri5.method.locate_kinks = true;
  std::vector<double> dopri_walls, pim_walls;
  for (int r = 0; r < o.repeats; ++r) {
    say(fmt::format("dopri5 (tol {:.0e}) on {} points, run {} of {} ...", tolerance, subset.size(),
                    r + 1, o.repeats));
    dopri_walls.push_back(time_points(sweep, subset, cores, by_dopri5));
    pim_walls.push_back(time_points(sweep, subset, cores, sweep.point));
  }
  const double dopri_subset = median(dopri_walls), pim_subset = median(pim_walls);
  const double scale = static_cast<double>(o.points) / static_cast<double>(subset.size());
  const double ratio = dopri_subset / pim_subset;

  fmt::print("| quantity | value | target |\n|---|---|---|\n");
  fmt::print("| 5-DOF PIM steps per second, one core (median of {}) | {:.3g} | >= 1e7 |\n",
             o.stepper_repeats, rate);
  fmt::print("| parallel efficiency on {} threads ({} points, median of {}) | {:.2f} | |\n", cores,
             sample.size(), o.repeats, efficiency);
  fmt::print("| PIM sweep: {} points, {}+{} periods, η = T/{}, λ1 and K (s, median of {}) | {:.2f} "
             "| < 15 on 2 cores |\n",
             o.points, o.transient, o.periods, o.steps_per_period, o.repeats, wall);
  fmt::print("| PIM sweep: steps per second per thread | {:.3g} | |\n",
             total_steps / wall / cores);
  fmt::print("| Poincaré-point error over 10 periods: PIM η = T/{} / dopri5 tol {:.0e} | {:.2e} / "
             "{:.2e} | |\n",
             o.steps_per_period, tolerance, pim_error, dopri_error[tolerance]);
  fmt::print("| dopri5 (kink-located, tol {:.0e}) on {} of the points, scaled to {} (s) | {:.2f} | |\n",
             tolerance, subset.size(), o.points, dopri_subset * scale);
  fmt::print("| dopri5 / PIM on the same {} points | {:.1f} | >= 10 |\n", subset.size(), ratio);

  std::filesystem::create_directories(o.out);
  const std::string path = o.out + "/bench_sweep.csv";
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(f, "quantity,value\n");
  fmt::print(f, "threads,{}\n", cores);
  fmt::print(f, "stepper_steps_per_second_one_core,{:.6g}\n", rate);
  fmt::print(f, "parallel_efficiency,{:.4f}\n", efficiency);
  fmt::print(f, "pim_sweep_points,{}\n", o.points);
  fmt::print(f, "pim_sweep_seconds,{:.4f}\n", wall);
  fmt::print(f, "pim_sweep_steps_per_second_per_thread,{:.6g}\n", total_steps / wall / cores);
  fmt::print(f, "pim_poincare_error,{:.4e}\n", pim_error);
  fmt::print(f, "dopri5_tolerance,{:.0e}\n", tolerance);
  fmt::print(f, "dopri5_poincare_error,{:.4e}\n", dopri_error[tolerance]);
  fmt::print(f, "dopri5_subset_points,{}\n", subset.size());
  fmt::print(f, "dopri5_subset_seconds,{:.4f}\n", dopri_subset);
  fmt::print(f, "pim_subset_seconds,{:.4f}\n", pim_subset);
  fmt::print(f, "dopri5_sweep_seconds_scaled,{:.4f}\n", dopri_subset * scale);
  fmt::print(f, "dopri5_over_pim,{:.3f}\n", ratio);
  std::fclose(f);
  fmt::print("\nwrote {}\n", path);
}

}  // namespace

void add_sweep_bench(CLI::App& bench) {
  auto o = std::make_shared<SweepBenchOptions>();
  CLI::App* c = bench.add_subcommand(
      "sweep",
      "Speed of a θ sweep of the 5-DOF chain: stepper throughput, parallel efficiency, and the\n"
      "sweep's wall time by the PIM beside kink-located dopri5 at the same Poincaré accuracy\n"
      "Example: pwl bench sweep --out plots/data");
  c->add_option("--points", o->points, "Points of the θ sweep")->check(positive_number());
  c->add_option("--transient", o->transient, "Transient periods per point")
      ->check(non_negative_number());
  c->add_option("--periods", o->periods, "Recorded periods per point")->check(number_in(100, 1000000));
  c->add_option("--repeats", o->repeats, "Timed runs (median)")->check(positive_number());
  c->add_option("--dopri5-every", o->dopri5_every, "dopri5 on every k-th point")
      ->check(positive_number());
  c->add_option("--out", o->out, "Folder for bench_sweep.csv");
  c->add_flag("--quiet", o->quiet, "Print only the table");
  c->callback([o] { run(*o); });
}

}  // namespace pwl::app
