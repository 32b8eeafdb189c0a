// The jobs as a library (simulate_command.hpp, analyze_command.hpp, sweep_command.hpp,
// map_command.hpp), as an embedding calls them: the flags parsed by the jobs' own registration,
// the runs in memory. --x0/--v0 against the closed-form free vibration of a damped oscillator,
// --phase against the times it names, and the checks of bad values with the flag and value named;
// continue_command.hpp's multiplier margin, the branch's and the curves'.
#include <CLI/CLI.hpp>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "commands/analyze_command.hpp"
#include "commands/continue_command.hpp"
#include "commands/map_command.hpp"
#include "commands/simulate_command.hpp"
#include "commands/sweep_command.hpp"
#include "pwl/errors.hpp"

using namespace pwl;
using namespace pwl::app;
using Catch::Contains;

namespace {

// The free damped vibration of m x'' + c x' + k x = 0 (underdamped) from x0, v0: x and v at t.
struct FreeVibration {
  double m, c, k, x0, v0;
  void at(double t, double* x, double* v) const {
    const double decay = c / (2 * m);
    const double omega = std::sqrt(k / m - decay * decay);
    const double b = (v0 + decay * x0) / omega;
    const double e = std::exp(-decay * t);
    *x = e * (x0 * std::cos(omega * t) + b * std::sin(omega * t));
    *v = e * (v0 * std::cos(omega * t) - (x0 * omega + decay * b) * std::sin(omega * t));
  }
};

template <class Options>
void parse(void (*add)(CLI::App&, Options&), Options& options, const std::string& line) {
  CLI::App app;
  add(app, options);
  app.parse(line, false);
}

}  // namespace

TEST_CASE("An initial state from --x0 and --v0 starts the closed-form free damped oscillation",
          "[commands]") {
  // One mass, no load, a gap spring that is never reached: x'' + ζ x' + x = 0 (ζ = 0.2).
  for (const std::string method : {"pim", "exact"}) {
    SimulateOptions options;
    parse(add_simulate_flags, options,
          "--n 1 --loads 0 --gap 100 --x0 0.3 --v0 -0.2 --periods 4 --record 1 --method " + method);
    SimulationArrays arrays;
    const SimulationSummary summary = simulate_case(options, arrays);
    const GapStructure structure = options.run.structure();
    const FreeVibration truth{structure.mass.coeff(0, 0), structure.damping.coeff(0, 0),
                              structure.stiffness.coeff(0, 0), 0.3, -0.2};
    REQUIRE(truth.c > 0.0);
    // The stroboscopic points at t = kT, k = 0..4 (the initial state first), and every step.
    REQUIRE(arrays.section_times.size() == 5);
    CHECK(arrays.section_states[0] == 0.3);
    CHECK(arrays.section_states[1] == -0.2);
    double worst = 0.0;
    for (std::size_t k = 0; k < arrays.section_times.size(); ++k) {
      CHECK(std::abs(arrays.section_times[k] - k * summary.period) < 1e-12);
      double x = 0, v = 0;
      truth.at(arrays.section_times[k], &x, &v);
      worst = std::max({worst, std::abs(arrays.section_states[2 * k] - x),
                        std::abs(arrays.section_states[2 * k + 1] - v)});
    }
    REQUIRE(arrays.trajectory_columns == 3);
    const std::size_t rows = arrays.trajectory.size() / 3;
    CHECK(rows >= 4);
    for (std::size_t r = 0; r < rows; ++r) {
      double x = 0, v = 0;
      truth.at(arrays.trajectory[3 * r], &x, &v);
      worst = std::max({worst, std::abs(arrays.trajectory[3 * r + 1] - x),
                        std::abs(arrays.trajectory[3 * r + 2] - v)});
    }
    INFO(method << ": largest difference from the closed form " << worst);
    // No spring ever touches, so the motion is linear and both methods are exact: the PIM's step
    // is the matrix exponential itself (to rounding), the event-driven solver's its modal form.
    CHECK(worst < 1e-12);
    // From rest the same case stays at rest.
    SimulateOptions rest;
    parse(add_simulate_flags, rest, "--n 1 --loads 0 --gap 100 --periods 2 --method " + method);
    SimulationArrays still;
    simulate_case(rest, still);
    for (double value : still.section_states) CHECK(value == 0.0);
  }
}

TEST_CASE("One value of --x0 or --v0 is every mass's", "[commands]") {
  InitialStateFlags start;
  start.x0 = {0.5};
  start.v0 = {1, 2, 3};
  const Vector y = start.state(3);
  CHECK(y == (Vector(6) << 0.5, 0.5, 0.5, 1, 2, 3).finished());
  CHECK(start.text() == "x0 = (0.5), v0 = (1,2,3)");
  CHECK(InitialStateFlags().state(2) == Vector::Zero(4));
  CHECK(InitialStateFlags().text() == "rest");
}

TEST_CASE("Bad initial states and sections are refused naming the flag and the value",
          "[commands]") {
  const auto refused = [](const std::string& flags, const std::string& message) {
    SimulateOptions options;
    parse(add_simulate_flags, options, "--figure 4a --periods 2 " + flags);
    SimulationArrays arrays;
    CHECK_THROWS_AS(simulate_case(options, arrays), InputError);
    CHECK_THROWS_WITH(simulate_case(options, arrays), Contains(message));
  };
  refused("--x0 1,2", "--x0 1,2: 2 values for 5 masses");
  refused("--x0 0,0,nan,0,0", "--x0 0,0,nan,0,0: nan is not a finite number");
  refused("--v0 inf", "--v0 inf: inf is not a finite number");
  refused("--section v9=0,down", "--section v9=0,down: v9 names no state component");
  refused("--section x2=0.1", "--section x2=0.1: give strobe, or a hyperplane");
  refused("--phase 1", "--phase 1: the phase is a fraction of the forcing period, 0 <= P < 1");
  refused("--phase -0.5", "--phase -0.5:");
  refused("--phase nan", "--phase nan:");
  refused("--record 6", "--record 6: masses are numbered 1..5");
}

TEST_CASE("Stroboscopic points at --phase are at t = (k + P) T of the kept periods", "[commands]") {
  SimulateOptions options;
  parse(add_simulate_flags, options,
        "--figure 4a --periods 6 --skip-periods 2 --phase 0.25 --method exact");
  SimulationArrays arrays;
  const SimulationSummary summary = simulate_case(options, arrays);
  // (2 T, 6 T]: k + 0.25 for k = 2..5.
  REQUIRE(arrays.section_times.size() == 4);
  for (std::size_t j = 0; j < 4; ++j) {
    CHECK(std::abs(arrays.section_times[j] - (j + 2.25) * summary.period) < 1e-12);
  }
  CHECK(summary.section.phase == 0.25);
  // A hyperplane section's points are its crossings: v5 = 0 at each.
  SimulateOptions crossing;
  parse(add_simulate_flags, crossing, "--figure 4a --periods 6 --section v5=0,down");
  SimulationArrays points;
  simulate_case(crossing, points);
  REQUIRE(points.section_times.size() >= 4);
  for (std::size_t j = 0; j < points.section_times.size(); ++j) {
    CHECK(points.section_states[10 * j + 9] == 0.0);
    CHECK(points.section_times[j] > 0.0);
  }
}

TEST_CASE("analyze_case gives the verdict, its evidence and the section points in memory",
          "[commands]") {
  AnalyzeOptions options;
  parse(add_analyze_flags, options, "--figure 4a --periods 300 --transient 150");
  const AnalyzeResult strobe = analyze_case(options);
  CHECK(strobe.result.regime == "period-2");
  REQUIRE(strobe.classification);
  CHECK(strobe.classification->period == 2);
  CHECK(strobe.section_times.size() == 150);
  CHECK(strobe.section_periods.front() == 151);
  CHECK(strobe.section_states.size() == 150 * 10);
  AnalyzeOptions hyperplane;
  parse(add_analyze_flags, hyperplane,
        "--figure 4a --periods 300 --transient 150 --section v5=0,down");
  const AnalyzeResult crossings = analyze_case(hyperplane);
  // The same motion, classified on the same stroboscopic points; other points recorded.
  CHECK(crossings.result.regime == strobe.result.regime);
  CHECK(crossings.result.lambda1 == strobe.result.lambda1);
  CHECK(crossings.result.K == strobe.result.K);
  REQUIRE(crossings.section_times.size() >= 75);
  for (std::size_t j = 0; j < crossings.section_times.size(); ++j) {
    CHECK(crossings.section_states[10 * j + 9] == 0.0);
  }
  AnalyzeOptions bad;
  parse(add_analyze_flags, bad, "--figure 4a --periods 300 --transient 150 --x0 1,2,3");
  CHECK_THROWS_WITH(analyze_case(bad), Contains("--x0 1,2,3: 3 values for 5 masses"));
}

TEST_CASE("Sweeps and maps take the section and the initial state, and say them", "[commands]") {
  SweepFlags sweep;
  parse(add_sweep_flags, sweep,
        "--figure 4a --points 2 --range 0.9:1.1 --transient 20 --periods 20 --x0 0.1 "
        "--section v5=0,down --mode continuation");
  const analysis::SweepOptions o = sweep_options(sweep);
  REQUIRE(o.initial_state.size() == 10);
  CHECK(o.initial_state[0] == 0.1);
  CHECK(o.initial_state[9] == 0.0);
  const std::string described = o.describe();
  CHECK_THAT(described, Contains("initial_state = 0.10000000000000001,0.10000000000000001"));
  CHECK_THAT(described, Contains("section = hyperplane\nsection_component = 9\n"));
  // In memory: every point, its crossings with their times.
  const std::map<long, analysis::PointResult> points = compute_study(study_of(o), 1);
  REQUIRE(points.size() == 4);
  for (const auto& [id, r] : points) {
    CHECK(r.section_times.size() == static_cast<std::size_t>(r.rows()));
    CHECK(r.rows() > 0);
  }
  // The continuation's first point upward starts from --x0: as an independent point from there.
  SweepFlags single;
  parse(add_sweep_flags, single,
        "--figure 4a --points 1 --range 0.9:0.9 --transient 20 --periods 20 --x0 0.1 "
        "--section v5=0,down");
  const std::map<long, analysis::PointResult> first =
      compute_study(study_of(sweep_options(single)));
  CHECK(first.at(0).section_times == points.at(0).section_times);
  CHECK(first.at(0).final_state == points.at(0).final_state);

  MapFlags map;
  parse(add_map_flags, map,
        "--figure 4a --x-points 2 --y-points 2 --transient 10 --periods 20 --v0 0.2 --phase 0.5");
  const analysis::RegimeMapOptions m = map_options(map);
  CHECK(m.initial_state[5] == 0.2);
  CHECK(m.point.section.phase == 0.5);
  CHECK_THAT(m.describe(), Contains("phase = 0.5\n"));
  MapFlags refused;
  parse(add_map_flags, refused, "--figure 4a --section v3=0,down");
  CHECK_THROWS_WITH(map_options(refused),
                    Contains("--section v3=0,down: a regime map keeps no Poincaré points"));
}

TEST_CASE("pwl continue asks its branch for continuation's multiplier margin, its curves for theirs",
          "[commands]") {
  const auto problem = [](const std::string& line) {
    ContinueFlags flags;
    CLI::App app;
    add_continue_flags(app, flags);
    app.parse(line, false);
    read_method_given(app, flags.orbit);
    return continuation_problem(flags);
  };
  const std::string branch = "--figure 5 --parameter theta --range 1.5:1.6";
  const double curves_default = orbits::CurvesOptions{}.shooting.arnoldi.margin;
  REQUIRE(orbits::kContinuationMargin != curves_default);

  // Unparsed flags carry the same default as parsed ones.
  CHECK(ContinueFlags{}.orbit.multiplier_margin == orbits::kContinuationMargin);
  CHECK(orbits::ContinuationOptions{}.shooting.arnoldi.margin == orbits::kContinuationMargin);

  const ContinuationProblem plain = problem(branch + " --curves alpha=4:6");
  CHECK(plain.options.shooting.arnoldi.margin == orbits::kContinuationMargin);
  REQUIRE(plain.curves.has_value());
  CHECK(plain.curves->shooting.arnoldi.margin == curves_default);

  const ContinuationProblem given = problem(branch + " --curves alpha=4:6 --multiplier-margin 0.002");
  CHECK(given.options.shooting.arnoldi.margin == 0.002);
  REQUIRE(given.curves.has_value());
  CHECK(given.curves->shooting.arnoldi.margin == 0.002);

  const ContinuationProblem zero = problem(branch + " --multiplier-margin 0");
  CHECK(zero.options.shooting.arnoldi.margin == 0.0);
  CHECK_FALSE(zero.curves.has_value());

  // Flags filled in without parsing: a margin other than the default reaches the curves too.
  ContinueFlags unparsed;
  unparsed.parameter = "theta";
  unparsed.range = "1.5:1.6";
  unparsed.curves = "alpha=4:6";
  unparsed.orbit.run.figure = "5";
  unparsed.orbit.multiplier_margin = 0.01;
  const ContinuationProblem filled = continuation_problem(unparsed);
  CHECK(filled.options.shooting.arnoldi.margin == 0.01);
  REQUIRE(filled.curves.has_value());
  CHECK(filled.curves->shooting.arnoldi.margin == 0.01);
}
