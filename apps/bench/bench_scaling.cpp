#include "bench/bench_scaling.hpp"

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>
#include <omp.h>

#include "bench/bench_clock.hpp"
#include "pwl/integrators/banded_propagator.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"

extern char** environ;

namespace pwl::app {
namespace {

using Clock = std::chrono::steady_clock;

// Median over repeats of the CPU time per call of `body`, called `calls` times per repeat.
template <class Body>
double time_per_call_us(int repeats, int calls, Body&& body) {
  std::vector<double> per;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = thread_seconds();
    for (int k = 0; k < calls; ++k) body();
    per.push_back(1e6 * (thread_seconds() - t0) / calls);
  }
  return median(per);
}

}  // namespace

void run_scaling_single(long masses, const ScalingBenchOptions& o) {
  const GapStructure structure = make_chain(paper_large_chain(static_cast<int>(masses)));
  const auto t0 = Clock::now();
  BandedExponentialOptions band;
  band.share_rows = o.share_rows;
  BandedPropagator propagator(make_banded_step_operators(structure, o.step, band));
  const double setup = std::chrono::duration<double>(Clock::now() - t0).count();
  const Vector rest = Vector::Zero(masses);
  // CPU time of one thread first (products kept on this thread), the threaded timing after.
  const int max_threads = omp_get_max_threads();
  omp_set_num_threads(1);
  // Every size times the same stretch of motion (steps 20 .. 20 + steps from rest, so that the
  // springs act as much per mass), repeated until each size has done about the same work: a
  // short repeat of a small chain is otherwise at the mercy of the scheduler.
  // In double and capped before the cast: a --work past the range of an integer asks for the cap.
  const double work = o.work / (static_cast<double>(masses) * static_cast<double>(o.steps));
  const int repeats = std::max(o.repeats, static_cast<int>(std::clamp(work, 1.0, 200.0)));
  // Each repeat times the stretch of steps and then as many bare products T v (on copies of
  // the stepper's vectors), so that the ratio of the two is taken within one repeat: the
  // machine's speed drifts between repeats more than the ratio does.
  const BandedStepOperators& ops = propagator.operators();
  Vector state, out(propagator.state().size());
  volatile double sink = 0.0;
  std::vector<double> per_step, per_product, ratios;
  for (int r = 0; r < repeats; ++r) {
    propagator.set_state(0.0, rest, rest);
    for (int k = 0; k < 20; ++k) propagator.step();
    const double c0 = thread_seconds();
    for (int k = 0; k < o.steps; ++k) propagator.step();
    per_step.push_back(1e6 * (thread_seconds() - c0) / o.steps);
    state = propagator.state();
    const double c1 = thread_seconds();
    for (int k = 0; k < o.steps; ++k) {
      ops.transition.multiply(state.data(), out.data());
      sink = sink + out[0];
    }
    per_product.push_back(1e6 * (thread_seconds() - c1) / o.steps);
    ratios.push_back(per_step.back() / per_product.back());
  }
  const double step_us = median(per_step);
  const double transition_us = median(per_product);
  const double step_per_product = median(ratios);

  // The products of a step with the last forces, every row of Ψ and Φ, on their own.
  const Vector forces = propagator.spring_forces();
  Vector p(forces.size());
  for (std::size_t j = 0; j < ops.spring_order.size(); ++j) {
    p[static_cast<Index>(j)] = forces[ops.spring_order[j]];
  }
  const double products_us = time_per_call_us(repeats, o.steps, [&] {
    ops.transition.multiply(state.data(), out.data());
    ops.force_now.multiply_add(p.data(), out.data());
    ops.force_next.multiply_add(p.data(), out.data());
    sink = sink + out[0];
  });
  // Wall time per step on one thread and on all of them, over the same stretch of motion.
  const auto wall_per_step_us = [&](int threads) {
    omp_set_num_threads(threads);
    std::vector<double> per;
    for (int r = 0; r < repeats; ++r) {
      propagator.set_state(0.0, rest, rest);
      for (int k = 0; k < 20; ++k) propagator.step();
      const auto w0 = Clock::now();
      for (int k = 0; k < o.steps; ++k) propagator.step();
      per.push_back(1e6 * std::chrono::duration<double>(Clock::now() - w0).count() / o.steps);
    }
    return median(per);
  };
  const double wall_one = wall_per_step_us(1);
  const double wall_threads = wall_per_step_us(max_threads);
  fmt::print("masses={} band={} setup={:.6g} step_us={:.6g} transition_us={:.6g} "
             "step_per_product={:.6g} products_us={:.6g} operator_mb={:.6g} stored_rows={} "
             "repeats={} threads={} wall_one_us={:.6g} wall_threads_us={:.6g}\n",
             masses, ops.truncation.band, setup, step_us, transition_us, step_per_product,
             products_us,
             static_cast<double>(propagator.memory_bytes()) / 1e6, ops.transition.stored_rows(),
             repeats, max_threads, wall_one, wall_threads);
  std::fflush(stdout);
}

std::vector<ScalingRow> run_scaling_bench(const ScalingBenchOptions& o,
                                          const std::string& self_exe) {
  if (o.sizes.empty() || o.steps < 1 || o.repeats < 1 || !(o.step > 0.0) || !(o.work > 0.0)) {
    throw InputError(
        "bench scaling: give at least one size, steps >= 1, repeats >= 1, step > 0, work > 0");
  }
  std::filesystem::create_directories(o.out);
  std::vector<ScalingRow> rows;
  for (long n : o.sizes) {
    if (n < 2) throw InputError(fmt::format("bench scaling: size {} must be at least 2", n));
    if (!o.quiet) {
      fmt::print("n = {} ...\n", n);
      std::fflush(stdout);
    }
    std::vector<std::string> args{self_exe,
                                  "bench",
                                  "scaling",
                                  "--single",
                                  std::to_string(n),
                                  "--step",
                                  fmt::format("{:.17g}", o.step),
                                  "--steps",
                                  std::to_string(o.steps),
                                  "--repeats",
                                  std::to_string(o.repeats),
                                  "--work",
                                  fmt::format("{:.17g}", o.work)};
    if (!o.share_rows) args.push_back("--unshared");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    int pipe_fd[2];
    if (pipe(pipe_fd) != 0) throw Error("bench scaling: cannot create a pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, pipe_fd[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, pipe_fd[0]);
    pid_t pid = 0;
    const int spawned =
        posix_spawn(&pid, self_exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(pipe_fd[1]);
    if (spawned != 0) {
      close(pipe_fd[0]);
      throw Error(fmt::format("bench scaling: cannot run {}", self_exe));
    }
    std::string output;
    char buffer[4096];
    for (ssize_t got; (got = read(pipe_fd[0], buffer, sizeof buffer)) > 0;) {
      output.append(buffer, static_cast<std::size_t>(got));
    }
    close(pipe_fd[0]);
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      throw Error(fmt::format("bench scaling: the run for n = {} failed:\n{}", n, output));
    }
    ScalingRow row;
    const std::size_t at = output.rfind("masses=");
    if (at == std::string::npos ||
        std::sscanf(output.c_str() + at,
                    "masses=%ld band=%ld setup=%lf step_us=%lf transition_us=%lf "
                    "step_per_product=%lf products_us=%lf operator_mb=%lf stored_rows=%ld "
                    "repeats=%d threads=%d wall_one_us=%lf wall_threads_us=%lf",
                    &row.masses, &row.band, &row.setup_seconds, &row.step_us, &row.transition_us,
                    &row.step_per_product, &row.products_us, &row.operator_mb, &row.stored_rows,
                    &row.repeats, &row.threads, &row.wall_one_us, &row.wall_threads_us) != 13) {
      throw Error(fmt::format("bench scaling: unexpected output for n = {}:\n{}", n, output));
    }
    row.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
    if (!o.quiet) {
      fmt::print("  band {}, step {:.1f} us, T v {:.1f} us, products {:.1f} us, peak {:.1f} MB, "
                 "{} threads {:.2f}x\n",
                 row.band, row.step_us, row.transition_us, row.products_us, row.peak_rss_mb,
                 row.threads, row.wall_one_us / row.wall_threads_us);
    }
    rows.push_back(row);
  }
  std::FILE* f = std::fopen((o.out + "/bench_scaling.csv").c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}/bench_scaling.csv", o.out));
  fmt::print(f, "masses,band,setup_s,step_us,transition_us,step_per_product,products_us,"
                "operator_mb,stored_rows,peak_rss_mb,threads,wall_one_us,wall_threads_us\n");
  for (const ScalingRow& r : rows) {
    fmt::print(f, "{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{:.6g},{},{:.6g},{:.6g}\n",
               r.masses, r.band, r.setup_seconds, r.step_us, r.transition_us, r.step_per_product,
               r.products_us,
               r.operator_mb, r.stored_rows, r.peak_rss_mb, r.threads, r.wall_one_us,
               r.wall_threads_us);
  }
  std::fclose(f);
  return rows;
}

std::string format_scaling_table(const std::vector<ScalingRow>& rows,
                                 const ScalingBenchOptions& o) {
  std::string s = fmt::format(
      "\nBanded PIM on the paper's chain from rest, η = {:g} s: CPU time of this thread per step "
      "over steps 20 to {}, median over repeats (more for small n){}.\n"
      "Floor: the bare product T v with the stepper's T, timed in each repeat after its steps; "
      "step / (T v) is the median of the repeats' ratios. T v + Ψ P + Φ P as dense-row products "
      "(the stepper adds Ψ P and Φ P from the acting springs' columns when few act).\n\n"
      "| n | band q | repeats | set-up s | step us | step ns / mass | T v us | T v + Ψ P + Φ P us | "
      "step / (T v) | operators MB | T rows stored | peak RSS MB | wall us, 1 thread | "
      "wall us, threads | speed-up |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
      o.step, 20 + o.steps, o.share_rows ? "" : "; every row stored (no sharing)");
  for (const ScalingRow& r : rows) {
    s += fmt::format("| {} | {} | {} | {:.3f} | {:.1f} | {:.2f} | {:.1f} | {:.1f} | {:.2f} | {:.2f} | "
                     "{} | {:.1f} | {:.1f} | {:.1f} ({}) | {:.2f}x |\n",
                     r.masses, r.band, r.repeats, r.setup_seconds, r.step_us,
                     1e3 * r.step_us / static_cast<double>(r.masses), r.transition_us,
                     r.products_us, r.step_per_product, r.operator_mb, r.stored_rows,
                     r.peak_rss_mb, r.wall_one_us, r.wall_threads_us, r.threads,
                     r.wall_one_us / r.wall_threads_us);
  }
  if (rows.size() >= 2) {
    const ScalingRow& a = rows.front();
    const ScalingRow& b = rows.back();
    const double size_ratio = static_cast<double>(b.masses) / static_cast<double>(a.masses);
    const double time_ratio = b.step_us / a.step_us;
    s += fmt::format(
        "\nn x{:.0f}: time per step x{:.1f}{}, bare T v x{:.1f}, operator memory x{:.1f}, peak RSS "
        "x{:.1f} (+{:.2f} kB per mass between the two).\n",
        size_ratio, time_ratio,
        time_ratio < 1.2 * size_ratio ? " (linear: per mass within 20%)" : " (not linear)",
        b.transition_us / a.transition_us, b.operator_mb / a.operator_mb, b.peak_rss_mb / a.peak_rss_mb,
        1e3 * (b.peak_rss_mb - a.peak_rss_mb) / static_cast<double>(b.masses - a.masses));
  }
  for (const ScalingRow& r : rows) {
    const double ratio = r.step_per_product;
    s += fmt::format("n = {}: a step costs {:.2f} bare products T v (target <= 2: {})\n", r.masses,
                     ratio, ratio <= 2.0 ? "met" : fmt::format("missed by {:.2f}x", ratio / 2.0));
  }
  return s;
}

}  // namespace pwl::app
