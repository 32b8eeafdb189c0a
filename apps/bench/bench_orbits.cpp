#include "bench/bench_orbits.hpp"

#include <fmt/format.h>

#include <ctime>
#include <sys/resource.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench/bench_clock.hpp"
#include "commands/cli_checks.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/orbits/continuation.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {
namespace {

using Clock = std::chrono::steady_clock;
using orbits::ShootingSolver;

struct OrbitBenchOptions {
  int repeats = 3;
  bool quick = false;
  int transient = 20;             // periods from rest: the common guess
  double tolerance = 1e-10;       // shooting and brute force alike
  // Brute-force budgets in periods: the 5-DOF cases, the medium chain, the large chain.
  std::vector<long> settle_periods{10000, 60000, 2000};
  std::vector<int> sizes{100, 1000};  // the medium and the large chain
  int points = 200;                   // continuation points per branch
  // The matrix-free continuations: the large chain's points, and the huge chain's size and
  // points.
  int large_points = 100;
  int huge_masses = 10000;
  int huge_points = 20;
  std::string corrector = "automatic";  // the continuations' corrector
  std::vector<std::string> cases;     // only these (keys below); empty: all
  std::string out = "out/bench";
  bool quiet = false;
  // After Newton-Krylov, form the whole monodromy at its orbit and compare its eigenvalues with
  // Arnoldi's (the independent check of the large chain's verdict; 2n tangent columns).
  bool check_multipliers = false;
};

// Keys of --cases.
const std::vector<std::string>& case_keys() {
  static const std::vector<std::string> keys{
      "4a",         "4a-stable",       "medium",         "large",
      "continue-5", "continue-medium", "continue-large", "continue-huge"};
  return keys;
}

// Wall and CPU time of one run.
struct Stopwatch {
  Clock::time_point wall = Clock::now();
  double cpu = cpu_seconds();
  double wall_seconds() const { return seconds_since(wall); }
  double cpu_seconds_since() const { return cpu_seconds() - cpu; }
};

double inf_norm(const Vector& v) { return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>(); }

// The figure 4a chain (α = 2, ζ = 0.2, Δ̃ = 0, Q = +1, −1, +1, ... on alternate masses) with
// `masses` masses at forcing frequency θ: for 5 masses exactly the paper's case.
NondimensionalChain fig4a_chain(int masses, double theta) {
  NondimensionalChain c = paper_five_dof_case("4a");
  c.masses = masses;
  c.theta = theta;
  c.amplitude.assign(static_cast<std::size_t>(masses), 1.0);
  for (int i = 1; i < masses; i += 2) c.amplitude[static_cast<std::size_t>(i)] = -1.0;
  return c;
}

// ---------------------------------------------------------------------------------------------
// 1. Shooting against brute force.

struct ShootingCase {
  std::string key;      // of --cases
  std::string label;    // for the table
  NondimensionalChain chain;
  Method method = Method::exact;
  std::vector<ShootingSolver> solvers;
  long settle_budget = 0;  // periods
};

struct ShootingRow {
  std::string case_label;
  int masses = 0;
  std::string method;
  bool exact_tangent = true;
  ShootingSolver solver = ShootingSolver::dense;
  int repeats = 0;
  double setup = 0.0;    // median, s: the integrator's construction
  double seconds = 0.0;  // median, s: Newton and the multipliers (wall clock)
  double cpu = 0.0;      // median CPU time of the same, s
  bool converged = false;
  std::string failure;   // Newton's message when it did not converge
  int iterations = 0;
  long evaluations = 0;
  long replays = 0;  // tangent products replayed from a recorded integration
  long krylov_products = 0;
  bool preconditioned = false;
  double residual = 0.0;
  double radius = 0.0;   // largest modulus of the multipliers
  int multipliers = 0;   // how many were computed
  bool complete = true;  // all of them (dense) or the leading ones (Arnoldi)
  bool multipliers_converged = true;
  double arnoldi_residual = 0.0;
  bool stable = false;
  Vector state;
  std::vector<std::complex<double>> leading;  // the multipliers found (Arnoldi's or all)
};

struct BruteForce {
  bool ran = false;
  bool settled = false;
  bool diverged = false;
  long periods = 0;            // periods integrated
  double difference = 0.0;     // |P(y) − y| at the last period
  double distance = -1.0;      // |y − orbit| at the end (-1: no orbit to compare with)
  double start_distance = -1.0;    // ... at the guess
  double halfway_distance = -1.0;  // ... after half the budget (when it got there)
  double seconds = 0.0;        // median, s (wall clock)
  double cpu = 0.0;            // median CPU time, s
  // Not settled but approaching the orbit: the periods still needed at the rate of the budget's
  // second half (-1: no estimate).
  double more_periods = -1.0;
  int repeats = 0;
};

// The whole monodromy at a Newton-Krylov orbit against Arnoldi's leading multipliers.
struct MultiplierCheck {
  bool ran = false;
  double form_seconds = 0.0, eigen_seconds = 0.0;
  Index size = 0;
  int outside = 0;        // eigenvalues of the monodromy outside the unit circle
  double radius = 0.0;    // its spectral radius
  double distance = 0.0;  // the farthest of Arnoldi's values from the monodromy's nearest leading one
  int compared = 0;
};

struct ShootingGroup {
  ShootingCase spec;
  std::vector<ShootingRow> rows;
  BruteForce brute;
  MultiplierCheck check;
};

std::string stable_text(const ShootingRow& r) {
  if (!r.converged) return "-";
  if (!r.multipliers_converged) return "undetermined (multipliers not converged)";
  return r.stable ? "yes" : "no";
}

std::string method_text(const ShootingRow& r) {
  return fmt::format("{} ({} tangent)", r.method, r.exact_tangent ? "exact" : "finite-difference");
}

std::string brute_text(const ShootingGroup& g) {
  const BruteForce& b = g.brute;
  if (!b.ran) return "not run";
  const ShootingRow* orbit = nullptr;
  for (const ShootingRow& r : g.rows) {
    if (r.converged) {
      orbit = &r;
      break;
    }
  }
  std::string head;
  if (orbit != nullptr && orbit->multipliers_converged && !orbit->stable) {
    head = fmt::format("cannot find it (unstable, ρ = {:.3g}); ", orbit->radius);
  }
  if (b.diverged) return head + fmt::format("blew up after {} periods", b.periods);
  if (b.settled) {
    if (b.distance < 0) return head + fmt::format("settled in {} periods (no orbit to compare)", b.periods);
    const double scale = orbit != nullptr ? std::max(1.0, inf_norm(orbit->state)) : 1.0;
    if (b.distance <= 1e-6 * scale) {
      return head + fmt::format("settled in {} periods on the same orbit (apart by {:.1e})",
                                b.periods, b.distance);
    }
    return head + fmt::format("settled in {} periods on another orbit ({:.2g} away)", b.periods,
                              b.distance);
  }
  std::string text = head + fmt::format("not settled in {} periods: successive points {:.1e} apart",
                                        b.periods, b.difference);
  if (b.distance >= 0) {
    text += fmt::format("; distance to the orbit {:.2g} at the start", b.start_distance);
    if (b.halfway_distance >= 0) text += fmt::format(", {:.2g} halfway", b.halfway_distance);
    text += fmt::format(", {:.2g} at the end", b.distance);
    if (b.more_periods > 0) {
      text += fmt::format(" (at the rate of the second half, about {:.2g} more periods)",
                          b.more_periods);
    } else if (head.empty() && b.halfway_distance >= 0) {
      text += " (not approaching it over the budget)";
    }
  }
  return text;
}

// Brute force over shooting, with ">=" when brute force did not settle (its time is then a lower
// bound of what settling would take) and "-" when it cannot find the orbit.
std::string ratio_text(const ShootingGroup& g, const ShootingRow& r) {
  const BruteForce& b = g.brute;
  if (!b.ran || !r.converged || r.seconds <= 0) return "-";
  if (r.multipliers_converged && !r.stable) return "- (unstable)";
  const double ratio = b.seconds / r.seconds;
  const bool same = b.settled && b.distance >= 0 &&
                    b.distance <= 1e-6 * std::max(1.0, inf_norm(r.state));
  if (same) return fmt::format("{:.3g}", ratio);
  if (b.settled) return fmt::format("{:.3g} (another orbit)", ratio);
  if (b.diverged) return "-";
  std::string text = fmt::format(">= {:.3g}", ratio);
  if (b.more_periods > 0) {
    const double estimate = b.seconds / static_cast<double>(b.periods) *
                            (static_cast<double>(b.periods) + b.more_periods) / r.seconds;
    text += fmt::format(" (about {:.2g} to settle, estimated)", estimate);
  }
  return text;
}

orbits::StroboscopicMap make_map(const ShootingCase& c, int steps_per_period) {
  MethodSettings settings;
  settings.method = c.method;
  return orbits::StroboscopicMap(analysis::PointCase(c.chain), settings, steps_per_period);
}

void check_multipliers(ShootingGroup& g, const std::function<void(const std::string&)>& say) {
  const ShootingRow* krylov = nullptr;
  for (const ShootingRow& r : g.rows) {
    if (r.converged && r.solver == ShootingSolver::krylov && !r.leading.empty()) krylov = &r;
  }
  if (krylov == nullptr) return;
  MultiplierCheck& c = g.check;
  say(fmt::format("{}, n = {}: the whole monodromy at the Newton-Krylov orbit ...", g.spec.label,
                  g.spec.chain.masses));
  orbits::StroboscopicMap map = make_map(g.spec, 200);
  const Stopwatch form;
  Matrix M;
  map.advance_with_jacobian(krylov->state, 1, M);
  c.form_seconds = form.wall_seconds();
  const Stopwatch eigen;
  const orbits::FloquetMultipliers all = orbits::floquet_multipliers(M);
  c.eigen_seconds = eigen.wall_seconds();
  c.ran = true;
  c.size = M.rows();
  c.outside = all.unstable_count();
  c.radius = all.largest_modulus();
  c.compared = static_cast<int>(krylov->leading.size());
  const std::size_t pool = std::min(all.values.size(), krylov->leading.size() + 2);
  for (const std::complex<double>& mu : krylov->leading) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < pool; ++i) nearest = std::min(nearest, std::abs(mu - all.values[i]));
    c.distance = std::max(c.distance, nearest);
  }
}

void run_shooting(ShootingGroup& g, const OrbitBenchOptions& o,
                  const std::function<void(const std::string&)>& say) {
  constexpr int kSteps = 200;  // per forcing period (fixed-grid methods)
  const ShootingCase& c = g.spec;
  const std::string method = std::string(method_traits(c.method).name);
  // The common guess: the state after a short transient from rest.
  Vector guess;
  {
    orbits::StroboscopicMap map = make_map(c, kSteps);
    guess = Vector::Zero(map.state_size());
    if (o.transient > 0) guess = map.advance(guess, o.transient);
  }
  for (ShootingSolver solver : c.solvers) {
    ShootingRow row;
    row.case_label = c.label;
    row.masses = c.chain.masses;
    row.method = method;
    row.solver = solver;
    orbits::ShootingOptions shooting;
    shooting.solver = solver;
    shooting.tolerance = o.tolerance;
    std::vector<double> setups, times, cpus;
    for (int r = 0; r < o.repeats; ++r) {
      say(fmt::format("{}, n = {}: shooting ({}), run {} of {} ...", c.label, c.chain.masses,
                      orbits::shooting_solver_name(solver), r + 1, o.repeats));
      const auto s0 = Clock::now();
      orbits::StroboscopicMap map = make_map(c, kSteps);
      setups.push_back(seconds_since(s0));
      row.exact_tangent = map.exact_tangent();
      const Stopwatch watch;
      try {
        const orbits::PeriodicOrbit orbit = orbits::find_periodic_orbit(map, guess, shooting);
        times.push_back(watch.wall_seconds());
        cpus.push_back(watch.cpu_seconds_since());
        row.converged = true;
        row.iterations = orbit.iterations;
        row.evaluations = orbit.evaluations;
        row.replays = orbit.tangent_replays;
        row.krylov_products = orbit.krylov_products;
        row.preconditioned = orbit.preconditioned;
        row.residual = orbit.residual;
        row.radius = orbit.multipliers.largest_modulus();
        row.multipliers = static_cast<int>(orbit.multipliers.values.size());
        row.complete = orbit.multipliers.complete;
        row.multipliers_converged = orbit.multipliers.converged;
        row.arnoldi_residual = orbit.multipliers.residual;
        row.stable = orbit.stable();
        row.state = orbit.state;
        row.leading = orbit.multipliers.values;
      } catch (const orbits::ShootingError& e) {
        times.push_back(watch.wall_seconds());
        cpus.push_back(watch.cpu_seconds_since());
        row.converged = false;
        row.failure = e.what();
        row.iterations = e.iterations();
        row.residual = e.residual();
        break;  // it fails the same way every time
      }
    }
    row.repeats = static_cast<int>(times.size());
    row.setup = median(setups);
    row.seconds = median(times);
    row.cpu = median(cpus);
    g.rows.push_back(std::move(row));
  }

  if (o.check_multipliers) check_multipliers(g, say);

  // The competitor: the same integrator from the same guess, period after period.
  const ShootingRow* orbit = nullptr;
  for (const ShootingRow& r : g.rows) {
    if (r.converged) {
      orbit = &r;
      break;
    }
  }
  BruteForce& b = g.brute;
  b.ran = c.settle_budget > 0;
  if (!b.ran) return;
  std::vector<double> times, cpus;
  for (int r = 0; r < o.repeats; ++r) {
    say(fmt::format("{}, n = {}: brute force (at most {} periods), run {} of {} ...", c.label,
                    c.chain.masses, c.settle_budget, r + 1, o.repeats));
    orbits::StroboscopicMap map = make_map(c, kSteps);
    Vector y = guess;
    long k = 0;
    double difference = 0.0, halfway = -1.0;
    bool settled = false, diverged = false;
    const Stopwatch watch;
    try {
      while (k < c.settle_budget) {
        Vector next = map.advance(y, 1);
        ++k;
        difference = inf_norm(next - y);
        y = std::move(next);
        if (orbit != nullptr && k == c.settle_budget / 2) halfway = inf_norm(y - orbit->state);
        if (!(difference == difference)) {  // NaN: the motion blew up
          diverged = true;
          break;
        }
        if (difference <= o.tolerance * std::max(1.0, inf_norm(y))) {
          settled = true;
          break;
        }
      }
    } catch (const DivergenceError&) {
      diverged = true;
    }
    times.push_back(watch.wall_seconds());
    cpus.push_back(watch.cpu_seconds_since());
    b.settled = settled;
    b.diverged = diverged;
    b.periods = k;
    b.difference = difference;
    b.distance = orbit != nullptr && !diverged ? inf_norm(y - orbit->state) : -1.0;
    b.start_distance = orbit != nullptr ? inf_norm(guess - orbit->state) : -1.0;
    b.halfway_distance = settled || diverged ? -1.0 : halfway;
    if (diverged) break;
  }
  b.repeats = static_cast<int>(times.size());
  b.seconds = median(times);
  b.cpu = median(cpus);
  // Not settled but approaching the orbit (the distance fell over each half of the budget): the
  // periods still needed for the distance to reach the tolerance at the mean rate of the second
  // half, a rough estimate. (The orbit's ρ is no guide: far from the orbit the springs touch
  // differently, and the slowest decay is the open chain's.)
  if (!b.settled && !b.diverged && b.distance > 0 && b.halfway_distance > 0 &&
      b.halfway_distance < b.start_distance && b.distance < b.halfway_distance) {
    const double target = o.tolerance * std::max(1.0, inf_norm(orbit->state));
    const double half = static_cast<double>(b.periods - c.settle_budget / 2);
    const double rate = std::log(b.distance / b.halfway_distance) / half;  // < 0, per period
    if (b.distance > target) b.more_periods = std::log(target / b.distance) / rate;
  }
}

// ---------------------------------------------------------------------------------------------
// 2. Continuation.

struct ContinuationCase {
  std::string key;
  std::string label;
  NondimensionalChain chain;  // at the start value of θ
  Method method = Method::exact;
  double end = 3.0;
  int points = 0;  // 0: the options' points
};

struct ContinuationRow {
  std::string label;
  int masses = 0;
  std::string method;
  bool exact_tangent = true;
  int repeats = 0;
  double start = 0.0, end = 0.0;  // the range asked
  double lowest = 0.0, highest = 0.0, last = 0.0;  // θ reached
  long points = 0;
  double seconds = 0.0;  // median, s (the first point's Newton included; wall clock)
  double cpu = 0.0;      // median CPU time, s
  std::string corrector;
  long monodromies = 0;   // integrations of the map with its monodromy (the last run)
  long integrations = 0;  // and without
  std::vector<orbits::Bifurcation> bifurcations;
  std::vector<std::string> notes;
  std::string failure;
  // Matrix-free (beyond the dense limit): a cold orbit at the start (`pwl orbit`'s Newton–Krylov
  // and Arnoldi from the same guess), timed in the same run; the warm points' time (from the
  // first point accepted to the last, per point); the products per point (the last run); the
  // process's peak resident memory after the run.
  bool matrix_free = false;
  double cold_orbit = 0.0;  // median, s
  double warm_point = 0.0;  // median, s
  long krylov_products = 0, arnoldi_products = 0;
  double peak_rss_mb = 0.0;
};

// The times at which a continuation's points arrive.
class PointClock : public orbits::ContinuationObserver {
 public:
  void point(const orbits::BranchPoint& /*point*/) override { times_.push_back(Clock::now()); }
  // Seconds per point from the first point to the last (0 with fewer than two).
  double per_point() const {
    if (times_.size() < 2) return 0.0;
    return std::chrono::duration<double>(times_.back() - times_.front()).count() /
           static_cast<double>(times_.size() - 1);
  }

 private:
  std::vector<Clock::time_point> times_;
};

std::string bifurcation_list(const ContinuationRow& r, std::size_t at_most) {
  if (r.bifurcations.empty()) return "none";
  std::map<std::string, int> counts;
  for (const auto& b : r.bifurcations) ++counts[orbits::bifurcation_name(b.type)];
  std::string text = fmt::format("{}:", r.bifurcations.size());
  bool first = true;
  for (const auto& [name, count] : counts) {
    text += fmt::format("{} {} {}", first ? "" : ",", count, name);
    first = false;
  }
  text += " (θ =";
  for (std::size_t i = 0; i < r.bifurcations.size() && i < at_most; ++i) {
    text += fmt::format("{} {:.4f}", i == 0 ? "" : ",", r.bifurcations[i].parameter);
  }
  if (r.bifurcations.size() > at_most) text += ", ...";
  return text + ")";
}

ContinuationRow run_continuation(const ContinuationCase& c, const OrbitBenchOptions& o,
                                 const std::function<void(const std::string&)>& say) {
  ContinuationRow row;
  row.label = c.label;
  row.masses = c.chain.masses;
  row.method = std::string(method_traits(c.method).name);
  row.start = c.chain.theta;
  row.end = c.end;
  orbits::ContinuationOptions options;
  options.parameter = analysis::SweepParameter::theta;
  options.start = c.chain.theta;
  options.end = c.end;
  options.max_points = c.points > 0 ? c.points : o.points;
  options.method.method = c.method;
  options.shooting.tolerance = o.tolerance;
  options.corrector = orbits::parse_corrector(o.corrector);
  row.corrector = o.corrector;  // until a run says which one "automatic" took
  const analysis::PointModel model(c.chain);
  Vector guess;
  {
    orbits::StroboscopicMap map(model.point_case(), options.method, options.steps_per_period);
    row.exact_tangent = map.exact_tangent();
    guess = Vector::Zero(map.state_size());
    if (o.transient > 0) guess = map.advance(guess, o.transient);
  }
  std::vector<double> times, cpus, colds, warms;
  for (int r = 0; r < o.repeats; ++r) {
    if (2 * static_cast<Index>(c.chain.masses) > options.shooting.dense_state_limit) {
      // The cold orbit the warm points are measured against, as `pwl orbit` finds it: with
      // ShootingOptions' own multiplier margin (0), not the one continuation asks for its band.
      say(fmt::format("{}, n = {}: a cold orbit at θ = {}, run {} of {} ...", c.label,
                      c.chain.masses, c.chain.theta, r + 1, o.repeats));
      orbits::StroboscopicMap map(model.point_case(), options.method, options.steps_per_period);
      orbits::ShootingOptions as_orbit = options.shooting;
      as_orbit.arnoldi.margin = orbits::ShootingOptions{}.arnoldi.margin;
      const Stopwatch cold;
      try {
        orbits::find_periodic_orbit(map, guess, as_orbit);
      } catch (const Error& e) {
        row.failure = std::string("cold orbit: ") + e.what();
        break;
      }
      colds.push_back(cold.wall_seconds());
    }
    say(fmt::format("{}, n = {}: continuation of {} points, run {} of {} ...", c.label,
                    c.chain.masses, options.max_points, r + 1, o.repeats));
    const Stopwatch watch;
    try {
      PointClock clock;
      const orbits::ContinuationResult result =
          orbits::continue_periodic_orbit(model, guess, options, &clock);
      times.push_back(watch.wall_seconds());
      cpus.push_back(watch.cpu_seconds_since());
      warms.push_back(clock.per_point());
      row.matrix_free = result.matrix_free;
      row.krylov_products = result.krylov_products;
      row.arnoldi_products = result.arnoldi_products;
      struct rusage usage {};
      getrusage(RUSAGE_SELF, &usage);
      row.peak_rss_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
      row.points = static_cast<long>(result.points.size());
      row.corrector = orbits::corrector_name(result.corrector);
      row.monodromies = result.monodromies;
      row.integrations = result.integrations;
      row.bifurcations = result.bifurcations;
      row.notes = result.notes;
      if (!result.points.empty()) {
        row.lowest = row.highest = result.points.front().parameter;
        for (const auto& p : result.points) {
          row.lowest = std::min(row.lowest, p.parameter);
          row.highest = std::max(row.highest, p.parameter);
        }
        row.last = result.points.back().parameter;
      }
    } catch (const Error& e) {
      row.failure = e.what();
      break;
    }
  }
  row.repeats = static_cast<int>(times.size());
  row.seconds = median(times);
  row.cpu = median(cpus);
  if (!colds.empty()) row.cold_orbit = median(colds);
  if (!warms.empty()) row.warm_point = median(warms);
  return row;
}

// ---------------------------------------------------------------------------------------------
// Tables and files.

std::string seconds_text(double wall, double cpu) { return fmt::format("{:.3g} ({:.3g})", wall, cpu); }

std::string format_tables(const OrbitBenchOptions& o, const std::vector<ShootingGroup>& groups,
                          const std::vector<ContinuationRow>& continuations) {
  std::string t;
  if (!groups.empty()) {
    t += fmt::format(
        "Periodic orbit and its Floquet multipliers from the state after {} periods from rest "
        "(tolerance {:.0e}; times: medians of {} runs, wall clock with the CPU time of all threads in "
        "parentheses):\n\n",
        o.transient, o.tolerance, o.repeats);
    t += "| case | n | method | solver | setup s | shooting s | Newton it. | map evals | GMRES "
         "products | residual | ρ(M) | multipliers | stable | brute force (same integrator, same "
         "guess) | brute force s | brute force / shooting |\n";
    t += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const ShootingGroup& g : groups) {
      for (const ShootingRow& r : g.rows) {
        const std::string solver =
            orbits::shooting_solver_name(r.solver) +
            (r.solver == ShootingSolver::krylov && r.preconditioned ? " (preconditioned)" : "");
        if (!r.converged) {
          t += fmt::format("| {} | {} | {} | {} | {:.3g} | {} | {} | - | - | {:.1e} | - | - | "
                           "- | {} | {} | - |\n",
                           r.case_label, r.masses, method_text(r), solver, r.setup,
                           seconds_text(r.seconds, r.cpu), r.iterations, r.residual,
                           "Newton failed: " + r.failure + "; brute force: " + brute_text(g),
                           g.brute.ran ? seconds_text(g.brute.seconds, g.brute.cpu) : "-");
          continue;
        }
        const std::string multipliers =
            r.complete ? fmt::format("all {}", r.multipliers)
                       : fmt::format("leading {} (Krylov{})", r.multipliers,
                                     r.multipliers_converged
                                         ? ""
                                         : fmt::format(", residual {:.1e}", r.arnoldi_residual));
        t += fmt::format(
            "| {} | {} | {} | {} | {:.3g} | {} | {} | {} | {} | {:.1e} | {} | {} | {} | {} | {} | "
            "{} |\n",
            r.case_label, r.masses, method_text(r), solver, r.setup, seconds_text(r.seconds, r.cpu),
            r.iterations,
            r.replays > 0 ? fmt::format("{} (+{} replayed)", r.evaluations, r.replays)
                          : fmt::format("{}", r.evaluations),
            r.solver == ShootingSolver::krylov ? fmt::format("{}", r.krylov_products) : "-",
            r.residual,
            r.multipliers_converged ? fmt::format("{:.6g}", r.radius)
                                    : fmt::format("{:.6g} (not converged)", r.radius),
            multipliers, stable_text(r), brute_text(g),
            g.brute.ran ? seconds_text(g.brute.seconds, g.brute.cpu) : "-", ratio_text(g, r));
      }
    }
    for (const ShootingGroup& g : groups) {
      const ShootingRow* dense = nullptr;
      const ShootingRow* krylov = nullptr;
      for (const ShootingRow& r : g.rows) {
        if (r.converged && r.solver == ShootingSolver::dense) dense = &r;
        if (r.converged && r.solver == ShootingSolver::krylov) krylov = &r;
      }
      if (dense != nullptr && krylov != nullptr && krylov->seconds > 0) {
        t += fmt::format(
            "\n{}, n = {}: dense / Krylov shooting time = {:.3g} ({:.3g} s / {:.3g} s); the two "
            "orbits differ by {:.1e}, their ρ(M) by {:.1e}.\n",
            g.spec.label, g.spec.chain.masses, dense->seconds / krylov->seconds, dense->seconds,
            krylov->seconds, inf_norm(dense->state - krylov->state),
            std::abs(dense->radius - krylov->radius));
      }
      if (g.check.ran) {
        const MultiplierCheck& c = g.check;
        t += fmt::format(
            "\n{}, n = {}: the whole {} x {} monodromy at the Newton-Krylov orbit ({:.3g} s to form, "
            "{:.3g} s for its eigenvalues): {} outside the unit circle, ρ(M) = {:.9g}; the Krylov "
            "{} leading multipliers are its leading ones to {:.1e}.\n",
            g.spec.label, g.spec.chain.masses, c.size, c.size, c.form_seconds, c.eigen_seconds,
            c.outside, c.radius, c.compared, c.distance);
      }
      for (const ShootingRow& r : g.rows) {
        if (!r.exact_tangent) {
          t += fmt::format(
              "\n{}, n = {}: {} has no exact tangent map here: its products are forward "
              "differences (one extra integration per product).\n",
              g.spec.label, g.spec.chain.masses, r.method);
          break;
        }
      }
    }
  }
  if (!continuations.empty()) {
    t += fmt::format(
        "\n\nPseudo-arclength continuation in θ of the period-1 orbit, at most {} points (times: "
        "medians of {} runs, wall clock with the CPU time in parentheses):\n\n",
        o.points, o.repeats);
    t += "| case | n | method | corrector | θ asked | θ reached | points | monodromies / plain "
         "integrations | bifurcations | total s | ms per point | why it stopped |\n";
    t += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const ContinuationRow& r : continuations) {
      if (r.matrix_free) continue;
      if (!r.failure.empty()) {
        t += fmt::format(
            "| {} | {} | {} | {} | {:g} → {:g} | - | - | - | - | - | - | failed: {} |\n", r.label,
            r.masses, r.method, r.corrector, r.start, r.end, r.failure);
        continue;
      }
      std::string notes;
      for (const std::string& n : r.notes) notes += (notes.empty() ? "" : "; ") + n;
      t += fmt::format("| {} | {} | {} ({} tangent) | {} | {:g} → {:g} | {:.4f} ... {:.4f} | {} | "
                       "{} / {} | {} | {} | {:.3g} | {} |\n",
                       r.label, r.masses, r.method, r.exact_tangent ? "exact" : "finite-difference",
                       r.corrector, r.start, r.end, r.lowest, r.highest, r.points, r.monodromies,
                       r.integrations, bifurcation_list(r, 8),
                       seconds_text(r.seconds, r.cpu), r.points > 0 ? 1e3 * r.seconds / static_cast<double>(r.points) : 0.0,
                       notes);
    }
    bool header = false;
    for (const ContinuationRow& r : continuations) {
      if (!r.matrix_free && r.failure.empty()) continue;
      if (!r.matrix_free && r.masses * 2 <= 400) continue;
      if (!header) {
        t += fmt::format(
            "\n\nMatrix-free continuation (no monodromy: Newton–Krylov on the bordered system, "
            "leading multipliers by warm-started preconditioned Davidson, or Arnoldi), against a cold orbit (Newton–Krylov "
            "and the multipliers from the same guess, as `pwl orbit`) at the start in the same run "
            "(medians of {} runs):\n\n",
            o.repeats);
        t += "| case | n | θ asked | θ reached | points | cold orbit s | warm point s | warm / "
             "cold | GMRES products per point | multiplier products per point | bifurcations | "
             "total s | peak memory MB | why it stopped |\n";
        t += "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        header = true;
      }
      if (!r.failure.empty()) {
        t += fmt::format("| {} | {} | {:g} → {:g} | - | - | - | - | - | - | - | - | - | - | "
                         "failed: {} |\n",
                         r.label, r.masses, r.start, r.end, r.failure);
        continue;
      }
      std::string notes;
      for (const std::string& n : r.notes) notes += (notes.empty() ? "" : "; ") + n;
      const double per = r.points > 0 ? 1.0 / static_cast<double>(r.points) : 0.0;
      t += fmt::format("| {} | {} | {:g} → {:g} | {:.4f} ... {:.4f} | {} | {:.3g} | {:.3g} | "
                       "{:.2f} | {:.0f} | {:.0f} | {} | {} | {:.0f} | {} |\n",
                       r.label, r.masses, r.start, r.end, r.lowest, r.highest, r.points,
                       r.cold_orbit, r.warm_point,
                       r.cold_orbit > 0 ? r.warm_point / r.cold_orbit : 0.0,
                       static_cast<double>(r.krylov_products) * per,
                       static_cast<double>(r.arnoldi_products) * per, bifurcation_list(r, 8),
                       seconds_text(r.seconds, r.cpu), r.peak_rss_mb, notes);
    }
  }
  return t;
}

std::string csv_quoted(const std::string& text) {
  std::string q = "\"";
  for (char ch : text) {
    if (ch == '"') q += '"';
    q += ch;
  }
  return q + "\"";
}

void write_csv(const std::string& path, const std::vector<ShootingGroup>& groups,
               const std::vector<ContinuationRow>& continuations) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}", path));
  fmt::print(f,
             "section,case,n,method,exact_tangent,solver,repeats,setup_seconds,seconds,cpu_seconds,"
             "converged,"
             "iterations,evaluations,tangent_replays,krylov_products,residual,spectral_radius,multipliers,"
             "multipliers_converged,stable,brute_status,brute_periods,brute_difference,"
             "brute_distance,brute_more_periods,brute_seconds,brute_cpu_seconds,brute_over_shooting,"
             "theta_start,"
             "theta_end,theta_lowest,theta_highest,points,bifurcations,seconds_per_point,"
             "bifurcation_list,corrector,monodromies,plain_integrations,matrix_free,cold_orbit_seconds,"
             "warm_point_seconds,gmres_products,arnoldi_products,peak_rss_mb\n");
  for (const ShootingGroup& g : groups) {
    const BruteForce& b = g.brute;
    const std::string status = !b.ran ? "not-run" : b.diverged ? "diverged"
                               : b.settled                   ? "settled"
                                                             : "not-settled";
    for (const ShootingRow& r : g.rows) {
      // Empty where brute force cannot find the orbit (unstable) or blew up.
      const bool comparable = b.ran && !b.diverged && r.converged && r.seconds > 0 &&
                              !(r.multipliers_converged && !r.stable);
      const std::string ratio = comparable ? fmt::format("{:.6g}", b.seconds / r.seconds) : "";
      fmt::print(f,
                 "shooting,{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{},{},{},{},{},{:.3e},{:.10g},{},{},{},"
                 "{},{},{:.3e},{:.3e},{:.4g},{:.6g},{:.6g},{},,,,,,,,,,,,,,,,,\n",
                 csv_quoted(r.case_label), r.masses, r.method, r.exact_tangent ? 1 : 0,
                 orbits::shooting_solver_name(r.solver), r.repeats, r.setup, r.seconds, r.cpu,
                 r.converged ? 1 : 0, r.iterations, r.evaluations, r.replays, r.krylov_products, r.residual,
                 r.radius, r.multipliers, r.multipliers_converged ? 1 : 0,
                 !r.converged ? "" : !r.multipliers_converged ? "undetermined" : r.stable ? "yes" : "no",
                 status, b.periods, b.difference, b.distance, b.more_periods, b.seconds, b.cpu,
                 ratio);
    }
  }
  for (const ContinuationRow& r : continuations) {
    std::string list;
    for (const auto& bif : r.bifurcations) {
      list += fmt::format("{}{} {:.10g}", list.empty() ? "" : "; ",
                          orbits::bifurcation_name(bif.type), bif.parameter);
    }
    fmt::print(f,
               "continuation,{},{},{},{},{},{},,{:.6g},{:.6g},{},,,,,,,,,,,,,,,,,,{:.10g},{:.10g},"
               "{:.10g},{:.10g},{},{},{:.6g},{},{},{},{},{},{:.6g},{:.6g},{},{},{:.1f}\n",
               csv_quoted(r.label), r.masses, r.method, r.exact_tangent ? 1 : 0,
               r.matrix_free ? "krylov" : "dense", r.repeats, r.seconds, r.cpu,
               r.failure.empty() ? 1 : 0, r.start, r.end, r.lowest, r.highest, r.points,
               r.bifurcations.size(),
               r.points > 0 ? r.seconds / static_cast<double>(r.points) : 0.0, csv_quoted(list),
               r.corrector, r.monodromies, r.integrations, r.matrix_free ? 1 : 0, r.cold_orbit,
               r.warm_point, r.krylov_products, r.arnoldi_products, r.peak_rss_mb);
  }
  std::fclose(f);
}

bool wanted(const OrbitBenchOptions& o, const std::string& key) {
  return o.cases.empty() || std::find(o.cases.begin(), o.cases.end(), key) != o.cases.end();
}

void run(OrbitBenchOptions o, bool repeats_given) {
  for (const std::string& key : o.cases) {
    if (std::find(case_keys().begin(), case_keys().end(), key) == case_keys().end()) {
      throw InputError(fmt::format("--cases: {} is not a case; use {}", key,
                                   fmt::join(case_keys(), ", ")));
    }
  }
  if (o.settle_periods.size() != 3) {
    throw InputError(fmt::format(
        "--settle-periods: expected 3 budgets (5-DOF, medium, large chain), got {}",
        o.settle_periods.size()));
  }
  if (o.sizes.size() != 2) {
    throw InputError(fmt::format("--sizes: expected 2 sizes (medium, large chain), got {}",
                                 o.sizes.size()));
  }
  if (o.quick) {  // a smoke run: smaller chains, budgets and branches
    o.sizes = {std::min(o.sizes[0], 10), std::min(o.sizes[1], 100)};
    o.settle_periods = {std::min<long>(o.settle_periods[0], 2000),
                        std::min<long>(o.settle_periods[1], 2000),
                        std::min<long>(o.settle_periods[2], 100)};
    o.points = std::min(o.points, 20);
    o.large_points = std::min(o.large_points, 5);
    o.huge_masses = std::min(o.huge_masses, 250);
    o.huge_points = std::min(o.huge_points, 3);
    if (!repeats_given) o.repeats = 1;
  }
  const auto say = [&](const std::string& text) {
    if (!o.quiet) fmt::print(stderr, "{}\n", text);
  };

  std::vector<ShootingCase> cases;
  if (wanted(o, "4a")) {
    cases.push_back({"4a", "figure 4a (θ = 1)", fig4a_chain(5, 1.0), Method::exact,
                     {ShootingSolver::dense}, o.settle_periods[0]});
  }
  if (wanted(o, "4a-stable")) {
    cases.push_back({"4a-stable", "figure 4a chain, θ = 1.2", fig4a_chain(5, 1.2), Method::exact,
                     {ShootingSolver::dense}, o.settle_periods[0]});
  }
  if (wanted(o, "medium")) {
    cases.push_back({"medium", "figure 4a chain, θ = 1.5", fig4a_chain(o.sizes[0], 1.5),
                     Method::pim_switching, {ShootingSolver::dense, ShootingSolver::krylov},
                     o.settle_periods[1]});
  }
  if (wanted(o, "large")) {
    cases.push_back({"large", "figure 4a chain, θ = 1.5", fig4a_chain(o.sizes[1], 1.5),
                     Method::pim_switching_banded, {ShootingSolver::krylov}, o.settle_periods[2]});
  }
  std::vector<ShootingGroup> groups;
  for (const ShootingCase& c : cases) {
    ShootingGroup g;
    g.spec = c;
    run_shooting(g, o, say);
    groups.push_back(std::move(g));
  }

  std::vector<ContinuationRow> continuations;
  if (wanted(o, "continue-5")) {
    continuations.push_back(run_continuation(
        {"continue-5", "figure 4a chain", fig4a_chain(5, 1.2), Method::exact, 3.0}, o, say));
  }
  if (wanted(o, "continue-medium")) {
    continuations.push_back(run_continuation({"continue-medium", "figure 4a chain",
                                              fig4a_chain(o.sizes[0], 1.0), Method::pim_switching,
                                              3.0},
                                             o, say));
  }
  // Matrix-free: the paper's size and ten times it, from θ = 1.5 upward (stable period-1 orbits
  // whose leading multipliers are the long-wave modes crowded against 1): toward 1.8 at the
  // paper's size, which its 100 points do not reach (they end near 1.78, past 24 grazings; toward
  // 1.6 the branch ended after 44), toward 1.6 at ten times it (its 20 points end near 1.513).
  if (wanted(o, "continue-large")) {
    continuations.push_back(run_continuation({"continue-large", "figure 4a chain, matrix-free",
                                              fig4a_chain(o.sizes[1], 1.5),
                                              Method::pim_switching, 1.8, o.large_points},
                                             o, say));
  }
  if (wanted(o, "continue-huge")) {
    continuations.push_back(run_continuation({"continue-huge", "figure 4a chain, matrix-free",
                                              fig4a_chain(o.huge_masses, 1.5),
                                              Method::pim_switching, 1.6, o.huge_points},
                                             o, say));
  }

  const std::string table = format_tables(o, groups, continuations);
  fmt::print("{}", table);
  std::filesystem::create_directories(o.out);
  write_csv(o.out + "/bench_orbits.csv", groups, continuations);
  if (std::FILE* f = std::fopen((o.out + "/bench_orbits.md").c_str(), "w")) {
    fmt::print(f, "{}", table);
    std::fclose(f);
  }
  fmt::print("\nwrote {0}/bench_orbits.csv and {0}/bench_orbits.md\n", o.out);
}

}  // namespace

void add_orbits_bench(CLI::App& bench) {
  auto o = std::make_shared<OrbitBenchOptions>();
  CLI::App* c = bench.add_subcommand(
      "orbits",
      "Periodic orbits by shooting against brute-force settling (n = 5, 100, 1000; dense and\n"
      "Newton-Krylov), and 200-point continuations in θ with their bifurcations\n"
      "Example: pwl bench orbits --out out/bench\n"
      "         pwl bench orbits --cases large --repeats 1   (only the 1000-mass chain)");
  c->add_option("--repeats", o->repeats, "Timed runs per measurement (median)")
      ->check(positive_number());
  c->add_flag("--quick", o->quick,
              "A smoke run: chains of 10 and 100 masses, small budgets, 20-point branches, one run "
              "unless --repeats");
  c->add_flag("--check-multipliers", o->check_multipliers,
              "After Newton-Krylov, form the whole monodromy at its orbit (2n tangent columns) and "
              "compare its eigenvalues with Arnoldi's leading multipliers");
  c->add_option("--transient", o->transient, "Periods from rest to the common guess")
      ->check(non_negative_number());
  c->add_option("--tol", o->tolerance, "Tolerance of shooting and of brute-force settling")
      ->check(positive_number());
  c->add_option("--settle-periods", o->settle_periods,
                "Brute-force budgets in periods: 5-DOF, medium chain, large chain (0: no brute "
                "force)")
      ->delimiter(',')
      ->check(non_negative_number());
  c->add_option("--sizes", o->sizes, "Masses of the medium and the large chain")
      ->delimiter(',')
      ->check(number_in(2, 1000000));
  c->add_option("--points", o->points, "Continuation points per branch")->check(number_in(2, 100000));
  c->add_option("--cases", o->cases,
                "Only these: 4a, 4a-stable, medium, large, continue-5, continue-medium, "
                "continue-large, continue-huge")
      ->delimiter(',');
  c->add_option("--corrector", o->corrector,
                "The continuations' corrector: automatic (newton up to 20 state components, chord\n"
                "above), chord or newton (the monodromy at every iterate)")
      ->check(CLI::IsMember({"automatic", "chord", "newton"}));
  c->add_option("--out", o->out, "Folder for bench_orbits.csv and bench_orbits.md");
  c->add_flag("--quiet", o->quiet, "Print only the tables");
  c->callback([o, c] { run(*o, c->count("--repeats") > 0); });
}

}  // namespace pwl::app
