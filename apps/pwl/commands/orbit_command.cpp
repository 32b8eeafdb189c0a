// pwl orbit: the period-k orbit of one case by shooting (Newton on the stroboscopic map, see
// analysis/include/pwl/orbits/periodic_orbit.hpp), stable or not, with its Floquet multipliers.
// Unlike simulate, it finds an orbit whether the motion settles on it or not: the unstable
// period-1 orbit inside the period-2 motion of figure 4a, for instance.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/orbit_command.hpp"
#include "commands/orbit_options.hpp"
#include "output/csv_writer.hpp"
#include "output/progress_line.hpp"
#include "pwl/errors.hpp"
#include "pwl/orbits/orbit_profile.hpp"
#include "pwl/orbits/periodic_orbit.hpp"

namespace pwl::app {
namespace {

constexpr Index kPathDofs = 100;  // orbit_path.csv is written up to this many masses

// orbit_path.csv: t and x1..xn at every step of a fixed-grid method (every T/steps of another)
// over the k periods of the orbit from its state at t = 0.
void write_path(orbits::StroboscopicMap& map, const Vector& state, int periods, int samples,
                const std::string& path) {
  const Index n = map.dofs();
  std::vector<std::string> columns{"t"};
  for (Index i = 1; i <= n; ++i) columns.push_back(fmt::format("x{}", i));
  CsvWriter csv(path, columns);
  Integrator& integrator = map.integrator();
  integrator.set_state(0.0, state.head(n), state.tail(n));
  csv.row(0.0, state.head(n));
  const double T = map.forcing_period();
  if (method_traits(map.settings().method).fixed_grid) {
    integrator.advance_to(periods * T,
                          [&](double t, const Vector& x, const Vector&) { csv.row(t, x); });
    return;
  }
  const long count = static_cast<long>(periods) * samples;
  for (long i = 1; i <= count; ++i) {
    integrator.advance_to(static_cast<double>(i) * periods * T / static_cast<double>(count));
    csv.row(integrator.time(), integrator.position());
  }
}

void orbit(const OrbitCommandFlags& f) {
  const auto start = std::chrono::steady_clock::now();
  const OrbitFlags& o = f.orbit;
  OrbitProblem problem = orbit_problem(f);
  const Index n = problem.point.structure.dofs();
  const OrbitMethod& method = problem.method;
  orbits::StroboscopicMap& map = *problem.map;
  note_when_no_tangent_map(map);
  const Vector guess = starting_guess(o, map);
  ProgressLine progress(!o.quiet);
  orbits::ShootingOptions shooting = problem.shooting;
  shooting.on_iteration = [&progress](int iteration, double residual, long products) {
    if (!progress.due(iteration == 0)) return;
    progress.show(newton_progress_text("orbit", iteration, residual, products, progress.seconds()));
  };
  const orbits::PeriodicOrbit orbit = [&] {
    try {
      const orbits::PeriodicOrbit found = orbits::find_periodic_orbit(map, guess, shooting);
      progress.finish();
      return found;
    } catch (...) {
      progress.finish();
      throw;
    }
  }();
  const orbits::PeriodicOrbit minimal = orbits::at_minimal_period(map, orbit, problem.shooting);

  std::filesystem::create_directories(o.out);
  {
    std::vector<std::string> columns = state_columns("t", n);
    columns.erase(columns.begin());  // x1..xn, v1..vn
    CsvWriter csv(o.out + "/orbit.csv", columns);
    csv.row(std::vector<double>(orbit.state.data(), orbit.state.data() + orbit.state.size()));
  }
  {
    CsvWriter csv(o.out + "/floquet.csv", {"re", "im", "abs"});
    for (const auto& mu : orbit.multipliers.values) csv.row({mu.real(), mu.imag(), std::abs(mu)});
  }
  const bool path = !f.no_path && n <= kPathDofs;
  if (path) {
    write_path(map, orbit.state, o.period, method.steps_per_period, o.out + "/orbit_path.csv");
  }
  const orbits::OrbitProfile profile = orbits::orbit_profile(map, orbit.state, o.period);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const orbits::FloquetMultipliers& mu = orbit.multipliers;
  fmt::print("case: n = {}, {}; period-{} orbit by {}{}\n", n, o.run.description(), o.period,
             orbit_method_label(method), method.chosen ? " (the default for orbits)" : "");
  fmt::print("guess: {}\n", o.guess_file.empty()
                                ? fmt::format("the state {} forcing periods after {}", o.transient, o.run.start.text())
                                : o.guess_file);
  fmt::print("Newton: {} iteration(s), residual |φ(y) − y|_∞ = {:.3e} (tolerance {:.1e}), {} "
             "integrations of the map, {} solver{}{}\n",
             orbit.iterations, orbit.residual, o.newton_tolerance, orbit.evaluations,
             orbits::shooting_solver_name(orbit.solver),
             orbit.solver == orbits::ShootingSolver::krylov
                 ? fmt::format(" ({} GMRES products)", orbit.krylov_products)
                 : std::string(),
             f.shots > 1 ? fmt::format(", {} shots", f.shots) : std::string());
  if (!mu.values.empty()) {
    fmt::print("Floquet multipliers: {} ({}), largest |μ| = {:.10g} (μ = {}){}\n",
               mu.values.size(),
               mu.complete ? std::string("all")
                           : fmt::format("the leading ones, by {}", eigen_solver_name(mu.method)),
               mu.largest_modulus(), multiplier_text(mu.values.front()),
               orbit.exact_tangent ? "" : ", from forward differences");
  }
  if (minimal.period == orbit.period) {
    fmt::print("minimal period: {}\n", orbit.period);
  } else {
    fmt::print("minimal period: {0} (the period-{1} orbit found is the period-{0} orbit taken {2} "
               "times; solved again at period {0}: residual {3:.3e}{4})\n",
               minimal.period, orbit.period, orbit.period / minimal.period, minimal.residual,
               minimal.multipliers.values.empty()
                   ? std::string()
                   : fmt::format(", largest |μ| = {:.10g}", minimal.multipliers.largest_modulus()));
  }
  fmt::print("amplitude max|x{}| over the orbit: {:.10g}\n", n, profile.amplitude(n - 1));
  const int outside = mu.unstable_count();
  if (!mu.converged) {
    // The leading multipliers did not meet their tolerance: no verdict from them.
    fmt::print("verdict: undetermined ({} did not converge: residual {:.1e}; {} of its "
               "multipliers outside the unit circle)\n",
               eigen_solver_name(mu.method), mu.residual, outside);
  } else {
    // The eigen-solver's count doubles until its smallest multiplier lies below 1 − margin; where it
    // stopped at half its basis first, those outside may be more than it reports.
    const double margin = problem.shooting.arnoldi.margin;
    std::string band;
    if (!mu.complete && mu.band_covered && margin > 0) {
      band = fmt::format("; every multiplier above {:.6g} in modulus is among the {}", 1 - margin,
                         mu.values.size());
    } else if (!mu.band_covered) {
      band = fmt::format("; more may lie above {:.6g} in modulus: {} stopped at {} of them",
                         1 - margin, eigen_solver_name(mu.method), mu.values.size());
    }
    fmt::print("verdict: {} ({}{} multiplier{} outside the unit circle{})\n",
               orbit.stable() ? "stable" : "unstable", mu.band_covered ? "" : "at least ",
               outside, outside == 1 ? "" : "s", band);
  }
  fmt::print("time: {:.3f} s\n", seconds);
  fmt::print("wrote {0}/orbit.csv, {0}/floquet.csv{1}\n", o.out,
             path ? fmt::format(" and {}/orbit_path.csv", o.out) : std::string());
}

}  // namespace

OrbitProblem orbit_problem(const OrbitCommandFlags& f) {
  const OrbitFlags& o = f.orbit;
  check_orbit_flags(o);
  if (f.shots < 1) throw InputError(fmt::format("--shots = {} must be >= 1", f.shots));
  analysis::PointModel model = o.run.model();
  analysis::PointCase point = model.point_case();
  const OrbitMethod method = orbit_method(o, point.structure, point.period);

  orbits::ShootingOptions shooting = shooting_options(o);
  shooting.shots = f.shots;
  shooting.solver = orbits::parse_shooting_solver(f.solver);
  shooting.arnoldi.count = f.floquet_count;
  shooting.arnoldi.krylov_dimension =
      std::max(shooting.arnoldi.krylov_dimension, 2 * f.floquet_count + 10);
  shooting.arnoldi.davidson_dimension =
      std::max(shooting.arnoldi.davidson_dimension, 2 * f.floquet_count + 10);
  if (f.shots > 1 && shooting.solver == orbits::ShootingSolver::krylov) {
    throw InputError(fmt::format("--shots {}: multiple shooting needs --solver dense or automatic",
                                 f.shots));
  }
  if (f.shots > 1 && f.shots % o.period != 0 && o.period % f.shots != 0) {
    throw InputError(fmt::format(
        "--shots {}: the arcs of multiple shooting divide the {} period(s) of the orbit (shots a "
        "divisor of --period) or each period (a multiple of it)",
        f.shots, o.period));
  }
  std::string why;
  if (!shooting.is_valid(&why)) throw InputError(why);
  auto map = std::make_unique<orbits::StroboscopicMap>(point, method.settings,
                                                       method.steps_per_period);
  return {std::move(model), std::move(point), method, shooting, std::move(map)};
}

void add_orbit_command_flags(CLI::App& command, OrbitCommandFlags& flags) {
  add_orbit_flags(command, flags.orbit, true);
  command.add_option("--shots", flags.shots,
                     "Multiple shooting: arcs of the orbit (a divisor of --period, or a multiple "
                     "of it:\n"
                     "that many arcs per period); for strongly unstable orbits")
      ->check(positive_number());
  command.add_option("--solver", flags.solver,
                     "Newton's linear algebra: dense (form the monodromy), krylov (GMRES on "
                     "products,\n"
                     "Arnoldi for the leading multipliers) or automatic (dense up to 400 state\n"
                     "components)")
      ->check(CLI::IsMember({"automatic", "dense", "krylov"}));
  command.add_option("--floquet-count", flags.floquet_count,
                     "Krylov: how many leading multipliers Arnoldi computes")
      ->check(positive_number());
  command.add_flag(
      "--no-path", flags.no_path,
      "Leave out orbit_path.csv (t, x1..xn over the orbit; written up to 100 masses)");
}

void add_orbit_command(CLI::App& app) {
  auto flags = std::make_shared<OrbitCommandFlags>();
  CLI::App* c = app.add_subcommand(
      "orbit",
      "Periodic orbit by shooting (Newton on the stroboscopic map), its Floquet multipliers and\n"
      "its stability, whether the motion settles on it or not\n"
      "Example: pwl orbit --figure 4a --period 1 --out orbit4a\n"
      "         pwl orbit --figure 4a --period 2 --guess-file orbit4a/orbit.csv --out orbit4a2");
  add_orbit_command_flags(*c, *flags);
  c->callback([c, flags] {
    read_method_given(*c, flags->orbit);
    orbit(*flags);
  });
}

}  // namespace pwl::app
