// pwl bench stability: where each method breaks as the contact stiffens, and what it costs to
// reach a given accuracy.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include "bench/accuracy_bench.hpp"
#include "commands/cli_checks.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/analysis/period_detection.hpp"
#include "pwl/model/chain_builders.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"

namespace pwl::app::accuracy_detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What a run did, worst first: the order in which a cell of the chart is labelled.
enum class Status { ok = 0, blow_up = 1, refused = 2, missed_contacts = 3, wrong_regime = 4 };

const char* status_name(Status s) {
  switch (s) {
    case Status::ok: return "ok";
    case Status::blow_up: return "blows up";
    case Status::refused: return "refused";
    case Status::missed_contacts: return "misses contacts";
    case Status::wrong_regime: return "wrong regime";
  }
  return "?";
}

struct StabilityOptions {
  std::vector<double> alphas{1, 10, 100, 1e3, 1e4, 1e5, 1e6};
  std::vector<int> steps{25, 50, 100, 200, 400, 800, 1600, 3200, 6400};
  std::vector<double> tolerances{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  int periods = 200;          // the run judged for blow-up, missed contacts and regime
  int regime_points = 40;     // the last Poincaré points judged for the regime
  int accuracy_periods = 10;  // the window whose error and cost are reported
  double target = 1e-6;
  int repeats = 3;
  double budget = 5.0;
  std::string out;
  std::string plots;
  bool quick = false;
  bool no_plot = false;
};

// The exact solver's account of one α.
struct Reference {
  std::vector<Vector> states;  // Poincaré points
  long events = 0;
  int period = 0;
  double seconds = 0.0;
};

struct Outcome {
  Status status = Status::ok;
  std::string why;
  double error = kNaN;      // over the first accuracy_periods periods
  double run_error = kNaN;  // over the whole run
  double seconds = kNaN;    // to integrate the first accuracy_periods periods
  long events = 0;
  int period = 0;
};

int regime(const std::vector<Vector>& states, int points) {
  const std::size_t n = std::min<std::size_t>(states.size(), static_cast<std::size_t>(points));
  const std::vector<Vector> tail(states.end() - static_cast<std::ptrdiff_t>(n), states.end());
  analysis::PeriodOptions po;
  po.k_max = 16;
  po.cycles = 2;
  po.tolerance = 1e-3;
  return analysis::detect_period(tail, po).period;
}

// How the spring switches a method makes are counted: its own located events, or the sign
// changes of the gaps between the ends of its steps.
enum class Counting { located, step_ends };

Outcome run_one(const GapStructure& s, const Factory& make, const std::vector<double>& times,
                const Reference& ref, Counting counting, const StabilityOptions& o) {
  Outcome out;
  // First run: the error, the regime and the switches seen (with an observer, untimed).
  std::vector<Vector> states;
  try {
    std::unique_ptr<Integrator> integrator = make();
    const Index n = integrator->dofs();
    integrator->set_state(0.0, Vector::Zero(n), Vector::Zero(n));
    Vector sign = (s.gap_functions(Vector::Zero(n)).array() > 0.0).cast<double>();
    long toggles = 0;
    const StepObserver count = [&](double, const Vector& x, const Vector&) {
      const Vector now = (s.gap_functions(x).array() > 0.0).cast<double>();
      toggles += static_cast<long>((now - sign).cwiseAbs().sum());
      sign = now;
    };
    out.error = out.run_error = 0.0;
    for (std::size_t k = 0; k < times.size(); ++k) {
      integrator->advance_to(times[k], counting == Counting::step_ends ? count : StepObserver());
      Vector state(2 * n);
      state << integrator->position(), integrator->velocity();
      if (!state.allFinite()) throw DivergenceError("the state is not finite");
      const double e = (state - ref.states[k]).cwiseAbs().maxCoeff();
      out.run_error = std::max(out.run_error, e);
      if (k < static_cast<std::size_t>(o.accuracy_periods)) out.error = std::max(out.error, e);
      states.push_back(std::move(state));
    }
    out.events = counting == Counting::located ? integrator->stats().kink_events : toggles;
  } catch (const InputError& e) {
    out.status = Status::refused;
    out.why = e.what();
    return out;
  } catch (const Error& e) {  // divergence, an LCP that failed
    out.status = Status::blow_up;
    out.why = e.what();
    return out;
  }
  if (!(out.run_error < 1e3)) {
    out.status = Status::blow_up;
    out.why = fmt::format("error {:.3g}", out.run_error);
    return out;
  }
  out.period = regime(states, o.regime_points);
  if (out.period != ref.period) {
    out.status = Status::wrong_regime;
    out.why = fmt::format("period {} instead of {}", out.period, ref.period);
  } else if (out.events < static_cast<long>(0.95 * static_cast<double>(ref.events))) {
    out.status = Status::missed_contacts;
    out.why = fmt::format("{} switches of {}", out.events, ref.events);
  }
  // Timed runs (no observer) over the accuracy window.
  const std::vector<double> window(times.begin(), times.begin() + o.accuracy_periods);
  const Run timed = measure(make, window, {}, o.repeats, o.budget);
  out.seconds = timed.ok ? timed.median_seconds : kNaN;
  return out;
}

struct MethodResults {
  std::string key;
  std::string label;
  // The method and whether it locates kinks; each cell sets the step (fixed grid) or the
  // tolerance (adaptive).
  MethodSettings settings;
  bool fixed_step() const { return method_traits(settings.method).fixed_grid; }
  // Per α: the parameter (steps per period or tolerance) and its outcome.
  std::map<double, std::vector<std::pair<double, Outcome>>> by_alpha;
};

void stability(StabilityOptions o) {
  if (o.plots.empty()) o.plots = figures_directory(plots_directory());
  if (o.out.empty()) o.out = plots_directory() + "/data/stability";
  if (o.quick) {
    o.alphas = {1, 100, 1e4, 1e6};
    o.steps = {50, 200, 800, 3200};
    o.tolerances = {1e-4, 1e-7, 1e-10};
    o.periods = std::min(o.periods, 60);
    o.regime_points = std::min(o.regime_points, 20);
    o.accuracy_periods = std::min(o.accuracy_periods, 5);
    o.repeats = 1;
  }
  if (o.accuracy_periods < 1 || o.accuracy_periods > o.periods) {
    throw InputError(fmt::format("--accuracy-periods = {} must be in 1..--periods = {}",
                                 o.accuracy_periods, o.periods));
  }
  if (o.periods < 2 * o.regime_points) {
    throw InputError(fmt::format("--periods = {} must be at least twice --regime-points = {}",
                                 o.periods, o.regime_points));
  }
  for (double a : o.alphas) {
    if (!(a > 0.0) || !std::isfinite(a)) throw InputError(fmt::format("--alpha {} must be positive", a));
  }
  for (int n : o.steps) {
    if (n < 1) throw InputError(fmt::format("--steps {} must be at least 1", n));
  }
  std::filesystem::create_directories(o.out);
  std::filesystem::create_directories(o.plots);

  const auto settings_of = [](Method method, bool locate_kinks) {
    MethodSettings settings;
    settings.method = method;
    settings.locate_kinks = locate_kinks;
    return settings;
  };
  std::vector<MethodResults> methods = {
      {"pim", "PIM (paper)", settings_of(Method::pim, false), {}},
      {"pim-switching", "switching PIM d=2", settings_of(Method::pim_switching, false), {}},
      {"dopri5", "dopri5 (plain, like ode45)", settings_of(Method::dopri5, false), {}},
      {"dopri5-kinks", "dopri5 kink-located", settings_of(Method::dopri5, true), {}},
      {"rkf78-kinks", "rkf78 kink-located", settings_of(Method::rkf78, true), {}},
  };
  std::map<double, Reference> references;

  for (double alpha : o.alphas) {
    NondimensionalChain chain = paper_five_dof_case("4a");
    chain.alpha = {alpha};
    const GapStructure s = make_chain(chain);
    const double T = chain.period();
    std::vector<double> times;
    for (int k = 1; k <= o.periods; ++k) times.push_back(k * T);

    Reference ref;
    {
      MethodSettings exact_settings;
      exact_settings.method = Method::exact;
      const Factory exact = [&s, exact_settings] { return make_integrator(s, exact_settings); };
      const Run r = measure(exact, times, {}, 1, o.budget);
      if (!r.ok) throw Error(fmt::format("the exact solver failed at α = {}: {}", alpha, r.failure));
      ref.states = r.states;
      ref.events = r.stats.kink_events;
      const std::vector<double> window(times.begin(), times.begin() + o.accuracy_periods);
      ref.seconds = measure(exact, window, {}, o.repeats, o.budget).median_seconds;
      ref.period = regime(ref.states, o.regime_points);
    }
    references[alpha] = ref;
    fmt::print(stderr, "α = {:g}: exact {} switches, period {}, {:.3g} s; ", alpha, ref.events,
               ref.period, ref.seconds);

    for (MethodResults& m : methods) {
      auto& cells = m.by_alpha[alpha];
      // Steps per period for a fixed-grid method, tolerances for an adaptive one.
      std::vector<double> parameters(o.tolerances);
      if (m.fixed_step()) parameters.assign(o.steps.begin(), o.steps.end());
      for (double p : parameters) {
        MethodSettings settings = m.settings;
        if (m.fixed_step()) {
          settings.step = T / p;
        } else {
          settings.tolerance = p;
        }
        const Factory make = [&s, settings] { return make_integrator(s, settings); };
        // A method that locates its switches counts them; the others are judged by the contact
        // changes between the ends of their steps.
        const Counting counting =
            locates_switches(settings) ? Counting::located : Counting::step_ends;
        cells.emplace_back(p, run_one(s, make, times, ref, counting, o));
      }
      fmt::print(stderr, "{} ", m.key);
    }
    fmt::print(stderr, "\n");
  }

  // CSV: one file per method, and the cost to reach the target.
  for (const MethodResults& m : methods) {
    CsvWriter csv(fmt::format("{}/stability_{}.csv", o.out, m.key),
                  {"alpha", "parameter", "status", "error", "cpu_seconds", "events_seen",
                   "events_exact", "period_seen", "period_exact", "run_error"});
    for (const auto& [alpha, cells] : m.by_alpha) {
      const Reference& ref = references[alpha];
      for (const auto& [parameter, out] : cells) {
        // -1: not measured (the run failed). gnuplot's "pt variable" would take a "nan" in the
        // line for a character to draw.
        auto or_missing = [](double v) { return std::isfinite(v) ? v : -1.0; };
        csv.row({alpha, parameter, static_cast<double>(static_cast<int>(out.status)),
                 or_missing(out.error), or_missing(out.seconds), static_cast<double>(out.events),
                 static_cast<double>(ref.events), static_cast<double>(out.period),
                 static_cast<double>(ref.period), or_missing(out.run_error)});
      }
    }
  }
  auto cost_to_target = [&](const MethodResults& m, double alpha, double* parameter) {
    double best = kNaN;
    for (const auto& [p, out] : m.by_alpha.at(alpha)) {
      if (out.status != Status::ok || !(out.error <= o.target) || !std::isfinite(out.seconds)) continue;
      if (!(best <= out.seconds)) {
        best = out.seconds;
        *parameter = p;
      }
    }
    return best;
  };
  {
    std::vector<std::string> columns{"alpha", "exact"};
    for (const MethodResults& m : methods) columns.push_back(m.key);
    CsvWriter csv(fmt::format("{}/stability_cost.csv", o.out), columns);
    for (double alpha : o.alphas) {
      std::vector<double> row{alpha, references[alpha].seconds};
      for (const MethodResults& m : methods) {
        double p = 0.0;
        row.push_back(cost_to_target(m, alpha, &p));
      }
      csv.row(row);
    }
  }

  // The table: per α and method, what breaks where, and the cost of the target accuracy.
  fmt::print("\nStability and failure: the 5-DOF chain of figure 4a (ζ = 0.2, θ = 1, Q = ±1, from "
             "rest) with α = k2/k1 varied, against the exact event-driven solver. Blow-up, missed "
             "contacts (fewer than 95% of the exact switches seen) and regime (period of the last {} "
             "Poincaré points) over {} periods; the error and its cost over the first {}.\n"
             "Fixed-step methods over η = T/{}..T/{}; Runge-Kutta over tolerances {:g}..{:g}.\n",
             o.regime_points, o.periods, o.accuracy_periods, o.steps.front(), o.steps.back(),
             o.tolerances.front(), o.tolerances.back());
  fmt::print("| α | exact: period, switches, time | method | failures (parameter: what) | cost to "
             "reach {:g} |\n| --- | --- | --- | --- | --- |\n",
             o.target);
  for (double alpha : o.alphas) {
    const Reference& ref = references[alpha];
    for (const MethodResults& m : methods) {
      std::string failures;
      for (const auto& [p, out] : m.by_alpha.at(alpha)) {
        if (out.status == Status::ok) continue;
        failures += fmt::format("{}{}: {}", failures.empty() ? "" : "; ",
                                m.fixed_step() ? fmt::format("T/{:g}", p) : fmt::format("{:.0e}", p),
                                status_name(out.status));
      }
      double parameter = 0.0;
      const double cost = cost_to_target(m, alpha, &parameter);
      const std::string cost_text =
          std::isfinite(cost)
              ? fmt::format("{:.3g} s at {}", cost,
                            m.fixed_step() ? fmt::format("T/{:g}", parameter)
                                         : fmt::format("tol {:.0e}", parameter))
              : std::string("not reached");
      fmt::print("| {:g} | {}, {}, {:.3g} s | {} | {} | {} |\n", alpha,
                 ref.period == 0 ? std::string("aperiodic") : fmt::format("P{}", ref.period),
                 ref.events, ref.seconds, m.label, failures.empty() ? "none" : failures, cost_text);
    }
  }
  fmt::print("CSV files in {}\n", o.out);

  if (o.no_plot) return;
  const std::string out = fmt::format("{}/stability", o.plots);
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "data='{}'; out='{}.{}'; target={:g}; periods={}; accuracy_periods={}; plot_title='"
        "Stability and failure map: 5-DOF chain of figure 4a with α = k_2/k_1 varied; failures "
        "over {} periods, error over the first {}, against the exact solver'",
        o.out, out, format, o.target, o.periods, o.accuracy_periods, o.periods,
        o.accuracy_periods);
  };
  draw_figure_and_report(scripts_directory() + "/stability.gp", definitions, out,
                         "pwl bench stability", false);
}

}  // namespace

void add_stability_bench(CLI::App& bench) {
  auto options = std::make_shared<StabilityOptions>();
  CLI::App* c = bench.add_subcommand(
      "stability",
      "Stability and failure chart: contact stiffness ratio against step or tolerance\n"
      "Example: pwl bench stability --quick");
  c->add_option("--alpha", options->alphas, "Contact stiffness ratios k2/k1")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--steps", options->steps, "Fixed-step methods: steps per forcing period")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--tol", options->tolerances, "Runge-Kutta tolerances")
      ->delimiter(',')
      ->check(positive_number());
  c->add_option("--periods", options->periods, "Forcing periods from rest")
      ->check(positive_number());
  c->add_option("--regime-points", options->regime_points,
                "Last Poincaré points used to judge the regime (period)")
      ->check(positive_number());
  c->add_option("--target", options->target, "Error whose cost is reported")
      ->check(positive_number());
  c->add_option("--accuracy-periods", options->accuracy_periods,
                "Periods over which the error and its cost are measured")
      ->check(positive_number());
  c->add_option("--repeats", options->repeats, "Timed runs per cell (median reported)")
      ->check(positive_number());
  c->add_option("--out", options->out, "CSV folder (default plots/data/stability)");
  c->add_option("--plots", options->plots, "PNG and SVG folder (default plots/figures)");
  c->add_flag("--quick", options->quick, "A coarse grid and short runs (a smoke test)");
  c->add_flag("--no-plot", options->no_plot, "Write the CSV files only");
  c->callback([options] { stability(*options); });
}

}  // namespace pwl::app::accuracy_detail
