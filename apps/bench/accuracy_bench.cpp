// pwl bench accuracy: work-precision diagrams of every integrator against ground truth.
#include "bench/accuracy_bench.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "bench/bench_clock.hpp"
#include "commands/cli_checks.hpp"
#include "output/csv_writer.hpp"
#include "output/gnuplot.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/event_driven_solver.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/model/chain_builders.hpp"

namespace pwl::app {
namespace accuracy_detail {

Run measure(const Factory& make, const std::vector<double>& times,
            const std::vector<Vector>& truth, int repeats, double budget) {
  Run run;
  std::vector<double> seconds;
  double spent = 0.0;
  for (int r = 0; r < std::max(repeats, 1); ++r) {
    const double start = cpu_seconds();
    try {
      std::unique_ptr<Integrator> integrator = make();
      const Index n = integrator->dofs();
      integrator->set_state(0.0, Vector::Zero(n), Vector::Zero(n));
      for (std::size_t k = 0; k < times.size(); ++k) {
        integrator->advance_to(times[k]);
        if (r == 0) {
          Vector state(2 * n);
          state << integrator->position(), integrator->velocity();
          if (!state.allFinite()) throw DivergenceError("the state is not finite");
          if (k < truth.size()) {
            run.error = std::max(run.error, (state - truth[k]).cwiseAbs().maxCoeff());
          }
          run.states.push_back(std::move(state));
        }
      }
      if (r == 0) run.stats = integrator->stats();
    } catch (const InputError& e) {
      run.ok = false;
      run.failure_kind = "refused";
      run.failure = e.what();
      return run;
    } catch (const DivergenceError& e) {
      run.ok = false;
      run.failure_kind = "blow-up";
      run.failure = e.what();
      return run;
    } catch (const Error& e) {
      run.ok = false;
      run.failure_kind = "error";
      run.failure = e.what();
      return run;
    }
    const double elapsed = cpu_seconds() - start;
    seconds.push_back(elapsed);
    spent += elapsed;
    if (spent + elapsed > budget) break;  // the next run would overrun the budget
  }
  std::sort(seconds.begin(), seconds.end());
  run.repeats = static_cast<int>(seconds.size());
  run.median_seconds = seconds[seconds.size() / 2];
  run.min_seconds = seconds.front();
  return run;
}

double log_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
    if (!(x[i] > 0.0) || !(y[i] > 0.0) || !std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    const double a = std::log(x[i]), b = std::log(y[i]);
    sx += a, sy += b, sxx += a * a, sxy += a * b;
    ++count;
  }
  if (count < 2) return std::numeric_limits<double>::quiet_NaN();
  const double n = count;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

CheapestPoint cheapest_reaching(const std::vector<WorkCurve>& family, double error) {
  CheapestPoint best;
  for (std::size_t c = 0; c < family.size(); ++c) {
    for (std::size_t i = 0; i < family[c].size(); ++i) {
      const WorkPoint& p = family[c][i];
      if (!(p.error <= error) || !(p.seconds < best.seconds)) continue;
      best.curve = static_cast<int>(c);
      best.point = static_cast<int>(i);
      best.seconds = p.seconds;
    }
  }
  return best;
}

CostComparison compare_cost_to_reach(const std::vector<WorkCurve>& ours,
                                     const std::vector<WorkCurve>& theirs, double lo, double hi) {
  if (!(lo > 0.0) || !(lo <= hi) || !std::isfinite(hi)) {
    throw InputError(fmt::format("cost to reach: the errors lo = {} and hi = {} must satisfy "
                                 "0 < lo <= hi",
                                 lo, hi));
  }
  // The errors where either family's cost can change inside [lo, hi], with hi itself (the cost
  // on [e, next) is the cost at e, and below the lowest of them down to lo the cost at lo).
  std::vector<double> levels{hi, lo};
  for (const std::vector<WorkCurve>* family : {&ours, &theirs}) {
    for (const WorkCurve& curve : *family) {
      for (const WorkPoint& p : curve) {
        if (p.error >= lo && p.error <= hi) levels.push_back(p.error);
      }
    }
  }
  std::sort(levels.begin(), levels.end(), std::greater<>());
  CostComparison result;
  result.ours_cheaper_everywhere = true;
  for (double level : levels) {
    const CheapestPoint a = cheapest_reaching(ours, level);
    const CheapestPoint b = cheapest_reaching(theirs, level);
    const double ratio = !a.found()   ? 0.0
                         : !b.found() ? std::numeric_limits<double>::infinity()
                                      : b.seconds / a.seconds;
    if (!(ratio > 1.0)) result.ours_cheaper_everywhere = false;
    if (std::isnan(result.narrowest_ratio) || ratio < result.narrowest_ratio) {
      result.narrowest_ratio = ratio;
      result.narrowest_error = level;
    }
  }
  return result;
}

}  // namespace accuracy_detail

namespace {

using accuracy_detail::Factory;
using accuracy_detail::Run;

struct AccuracyOptions {
  std::vector<std::string> cases{"4a", "chain"};
  int periods = 200;  // figure 4a: forcing periods from rest (transient and attractor)
  int repeats = 5;
  double budget = 20.0;  // CPU seconds of repeated runs per point (at least one run)
  int chain_masses = 1000;
  double chain_time = 200.0;  // s (the paper's run)
  double chain_truth_tolerance = 1e-12;
  std::string out;    // CSV folder; default <plots>/data/accuracy
  std::string plots;  // PNG folder; default the plots directory
  bool quick = false;
  bool no_plot = false;
};

struct Point {
  double parameter = 0.0;  // steps per period (fixed step), tolerance, or 0
  double step = 0.0;       // η, or 0
  Run run;
};

struct Curve {
  std::string key;      // file stem and gnuplot key
  std::string label;    // for the table
  std::string parameter_name;
  bool fixed_step = false;
  bool runge_kutta = false;  // a Runge-Kutta curve (the rivals); otherwise one of pwl's methods
  std::vector<Point> points;
};

// The measured order: minus the slope of log(error) against log(accepted steps), over the points
// above the noise floor (and below 1e-1, where the asymptotic regime has not begun).
double measured_order(const Curve& c, double floor) {
  std::vector<double> steps, errors;
  for (const Point& p : c.points) {
    if (!p.run.ok || !(p.run.error > floor) || !(p.run.error < 1e-1)) continue;
    steps.push_back(static_cast<double>(p.run.stats.steps));
    errors.push_back(p.run.error);
  }
  return -accuracy_detail::log_slope(steps, errors);
}

void write_curve(const std::string& folder, const std::string& stem, const Curve& c) {
  CsvWriter csv(fmt::format("{}/{}_{}.csv", folder, stem, c.key),
                {"parameter", "cpu_seconds", "error", "steps", "rhs_evaluations", "events",
                 "step", "min_cpu_seconds", "repeats"});
  for (const Point& p : c.points) {
    if (!p.run.ok) continue;
    csv.row({p.parameter, p.run.median_seconds, p.run.error,
             static_cast<double>(p.run.stats.steps),
             static_cast<double>(p.run.stats.rhs_evaluations),
             static_cast<double>(p.run.stats.kink_events), p.step, p.run.min_seconds,
             static_cast<double>(p.run.repeats)});
  }
}

// The CPU-time slope: minus the slope of log(error) against log(CPU time) over the same points.
double work_slope(const Curve& c, double floor) {
  std::vector<double> seconds, errors;
  for (const Point& p : c.points) {
    if (!p.run.ok || !(p.run.error > floor) || !(p.run.error < 1e-1)) continue;
    seconds.push_back(p.run.median_seconds);
    errors.push_back(p.run.error);
  }
  return -accuracy_detail::log_slope(seconds, errors);
}

// A point's parameter as the tables print it.
std::string parameter_text(const Curve& c, const Point& p) {
  return c.parameter_name == "steps/period" ? fmt::format("η = T/{:g}", p.parameter)
         : c.parameter_name == "steps/s"    ? fmt::format("η = 1/{:g} s", p.parameter)
         : c.parameter_name == "tol"        ? fmt::format("tol {:.0e}", p.parameter)
                                            : std::string("-");
}

void print_table(const std::string& title, const std::vector<Curve>& curves, double floor) {
  fmt::print("\n{}\n", title);
  fmt::print("| method | parameter | CPU time (median) | error | steps | measured order | "
             "error ~ time^-s, s = |\n");
  fmt::print("| --- | --- | --- | --- | --- | --- | --- |\n");
  auto number = [](double v) {
    return std::isfinite(v) ? fmt::format("{:.2f}", v) : std::string("n/a");
  };
  for (const Curve& c : curves) {
    const double order = measured_order(c, floor);
    const double slope = work_slope(c, floor);
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      const Point& p = c.points[i];
      const std::string parameter = parameter_text(c, p);
      const std::string order_text = i == 0 ? number(order) : std::string();
      const std::string slope_text = i == 0 ? number(slope) : std::string();
      if (!p.run.ok) {
        fmt::print("| {} | {} | - | {}: {} | - | {} | {} |\n", c.label, parameter,
                   p.run.failure_kind, p.run.failure.substr(0, 80), order_text, slope_text);
        continue;
      }
      fmt::print("| {} | {} | {:.4g} s ({} runs) | {:.3e} | {} | {} | {} |\n", c.label, parameter,
                 p.run.median_seconds, p.run.repeats, p.run.error, p.run.stats.steps, order_text,
                 slope_text);
    }
  }
  fmt::print("measured order: minus the slope of log(error) against log(steps) over the points "
             "with {:g} < error < 0.1 (for the fixed-step methods the order in η; for the "
             "adaptive ones the steps include those that land on kinks, so it is not their "
             "nominal order). s: the same against CPU time.\n",
             floor);
}

// The cost-to-reach table (accuracy_detail::compare_cost_to_reach): at each decade of error from
// 1e-1 down to the floor, the cheapest pwl point and the cheapest Runge-Kutta point at or below
// it, and whether pwl is the cheaper at every error from 1e-3 down to the floor (not below 1e-10),
// checked at every measured point's error in between, not only at the decades.
void print_cost_to_reach(const std::vector<Curve>& curves, double floor) {
  // Each family's work curves (the points that ran, with a finite error) and, index for index,
  // the curve and point behind each work point.
  struct Family {
    std::vector<accuracy_detail::WorkCurve> work;
    std::vector<const Curve*> curves;
    std::vector<std::vector<const Point*>> points;
  };
  Family pwl, rk;
  for (const Curve& c : curves) {
    Family& f = c.runge_kutta ? rk : pwl;
    f.curves.push_back(&c);
    f.work.emplace_back();
    f.points.emplace_back();
    for (const Point& p : c.points) {
      if (!p.run.ok || !std::isfinite(p.run.error)) continue;
      f.work.back().push_back({p.run.median_seconds, p.run.error});
      f.points.back().push_back(&p);
    }
  }
  fmt::print("\nCost to reach an error: the cheapest point at or below it (CPU time, median)\n");
  fmt::print("| error <= | cheapest pwl point | CPU time | cheapest Runge-Kutta point | CPU time | "
             "Runge-Kutta / pwl |\n");
  fmt::print("| --- | --- | --- | --- | --- | --- |\n");
  for (int e = 1; std::pow(10.0, -e) >= floor * (1 - 1e-9); ++e) {
    const double level = std::pow(10.0, -e);
    const auto a = accuracy_detail::cheapest_reaching(pwl.work, level);
    const auto b = accuracy_detail::cheapest_reaching(rk.work, level);
    const auto name = [](const Family& f, const accuracy_detail::CheapestPoint& p) {
      if (!p.found()) return std::string("none");
      const auto curve = static_cast<std::size_t>(p.curve);
      const Point& q = *f.points[curve][static_cast<std::size_t>(p.point)];
      const Curve& c = *f.curves[curve];
      return fmt::format("{}, {} ({:.1e})", c.label, parameter_text(c, q), q.run.error);
    };
    const auto time = [](const accuracy_detail::CheapestPoint& p) {
      return p.found() ? fmt::format("{:.4g} s", p.seconds) : std::string("-");
    };
    fmt::print("| {:.0e} | {} | {} | {} | {} | {} |\n", level, name(pwl, a), time(a),
               name(rk, b), time(b),
               a.found() && b.found() ? fmt::format("{:.2f}", b.seconds / a.seconds)
                                      : std::string("-"));
  }
  const double hi = 1e-3;
  if (floor > hi) {
    fmt::print("pwl against the Runge-Kutta curves from 1e-03 down: not judged (the truth's floor "
               "{:.0e} is above 1e-03)\n",
               floor);
    return;
  }
  const double lo = std::max(floor, 1e-10);
  const auto verdict = accuracy_detail::compare_cost_to_reach(pwl.work, rk.work, lo, hi);
  const std::string margin =
      verdict.narrowest_ratio == 0.0 ? fmt::format("no pwl point is at or below {:.2e}",
                                                   verdict.narrowest_error)
      : std::isinf(verdict.narrowest_ratio)
          ? fmt::format("no Runge-Kutta point is at or below {:.2e}", verdict.narrowest_error)
          : fmt::format("Runge-Kutta / pwl = {:.2f} at {:.2e}", verdict.narrowest_ratio,
                        verdict.narrowest_error);
  fmt::print("pwl cheaper than every Runge-Kutta curve at every error from {:.0e} to {:.0e}: {} "
             "(narrowest: {})\n",
             hi, lo, verdict.ours_cheaper_everywhere ? "yes" : "no", margin);
}

std::vector<double> tolerances(bool quick, double tightest) {
  std::vector<double> t;
  for (int e = 3; e <= 12; ++e) {
    const double tol = std::pow(10.0, -e);
    if (tol < tightest * 0.99) break;
    if (quick && e % 3 != 0) continue;
    t.push_back(tol);
  }
  return t;
}

// A factory of the method table's integrator for `settings`.
Factory table_factory(const GapStructure& s, const MethodSettings& settings) {
  return [&s, settings] { return make_integrator(s, settings); };
}

// The settings of a fixed-grid method at step η.
MethodSettings at_step(Method method, double step) {
  MethodSettings settings;
  settings.method = method;
  settings.step = step;
  return settings;
}

// The four Runge-Kutta variants over tolerances: every adaptive row of the method table, plain
// and kink-located.
void runge_kutta_curves(const GapStructure& s, const std::vector<double>& tols,
                        const std::vector<double>& times, const std::vector<Vector>& truth,
                        const AccuracyOptions& o, std::vector<Curve>& curves) {
  for (const MethodTraits& row : method_table()) {
    if (!row.adaptive) continue;
    for (bool kinks : {false, true}) {
      if (kinks && !row.kink_location) continue;
      Curve c;
      c.key = fmt::format("{}{}", row.name, kinks ? "-kinks" : "");
      c.label = fmt::format("{}{}", row.name, kinks ? " kink-located" : "");
      c.parameter_name = "tol";
      c.runge_kutta = true;
      for (double tol : tols) {
        MethodSettings settings;
        settings.method = row.method;
        settings.tolerance = tol;
        settings.locate_kinks = kinks;
        const Factory make = table_factory(s, settings);
        c.points.push_back({tol, 0.0, accuracy_detail::measure(make, times, truth, o.repeats,
                                                                o.budget)});
        fmt::print(stderr, ".");
      }
      curves.push_back(std::move(c));
    }
  }
}

void plot(const AccuracyOptions& o, const std::string& stem, const std::vector<Curve>& curves,
          const std::string& title, const std::string& error_label) {
  if (o.no_plot) return;
  std::string keys;
  for (const Curve& c : curves) {
    if (std::any_of(c.points.begin(), c.points.end(), [](const Point& p) { return p.run.ok; })) {
      keys += (keys.empty() ? "" : " ") + c.key;
    }
  }
  const std::string out = fmt::format("{}/work_precision_{}", o.plots, stem);
  const auto definitions = [&](const std::string& format) {
    return fmt::format(
        "data='{}'; stem='{}'; curves='{}'; out='{}.{}'; plot_title={}; ylabel_text={}", o.out,
        stem, keys, out, format, gnuplot_quoted(title), gnuplot_quoted(error_label));
  };
  draw_figure_and_report(scripts_directory() + "/work_precision.gp", definitions, out,
                         "pwl bench accuracy", false);
}

void five_dof(const AccuracyOptions& o) {
  const NondimensionalChain chain = paper_five_dof_case("4a");
  const GapStructure s = make_chain(chain);
  const double T = chain.period();
  const int periods = o.quick ? std::min(o.periods, 10) : o.periods;
  std::vector<double> times;
  for (int k = 1; k <= periods; ++k) times.push_back(k * T);

  // The truth, and the exact solver's own point: its cost, and its agreement with the same
  // solver in the augmented-exponential representation (independent arithmetic).
  std::vector<Curve> curves;
  MethodSettings exact_settings;
  exact_settings.method = Method::exact;
  const Factory exact = table_factory(s, exact_settings);
  Run truth_run = accuracy_detail::measure(exact, times, {}, o.repeats, o.budget);
  if (!truth_run.ok) throw Error("the exact solver failed on figure 4a: " + truth_run.failure);
  const std::vector<Vector> truth = truth_run.states;
  {
    EventDrivenOptions eo;
    eo.representation = "exponential";
    const Factory other = [&s, eo] { return make_event_driven_solver(s, eo); };
    const Run check = accuracy_detail::measure(other, times, truth, 1, o.budget);
    truth_run.error = check.ok ? check.error : std::numeric_limits<double>::quiet_NaN();
    Curve c;
    c.key = std::string(method_traits(Method::exact).name);
    c.label = std::string(method_traits(Method::exact).label);
    c.parameter_name = "-";
    c.points.push_back({0.0, 0.0, truth_run});
    curves.push_back(std::move(c));
  }
  fmt::print(stderr, "figure 4a: exact solver {:.3g} s, {} events; measuring", truth_run.median_seconds,
             truth_run.stats.kink_events);

  const std::vector<int> pim_steps = o.quick ? std::vector<int>{25, 100, 400, 1600}
                                             : std::vector<int>{25, 50, 100, 200, 400, 800, 1600, 3200};
  {
    Curve c;
    c.key = "pim";
    c.label = "PIM (paper)";
    c.parameter_name = "steps/period";
    c.fixed_step = true;
    for (int n : pim_steps) {
      const MethodSettings settings = at_step(Method::pim, T / n);
      const Factory make = table_factory(s, settings);
      c.points.push_back({double(n), settings.step,
                          accuracy_detail::measure(make, times, truth, o.repeats, o.budget)});
      fmt::print(stderr, ".");
    }
    curves.push_back(std::move(c));
  }
  for (int degree : {2, 4}) {
    Curve c;
    c.key = degree == 2 ? "pim-switching" : fmt::format("pim-switching-d{}", degree);
    c.label = fmt::format("switching PIM d={} (order {})", degree, degree + 3);
    c.parameter_name = "steps/period";
    c.fixed_step = true;
    for (int n : pim_steps) {
      if (n > 1600) continue;  // at rounding level already
      MethodSettings settings = at_step(Method::pim_switching, T / n);
      settings.force_degree = degree;
      const Factory make = table_factory(s, settings);
      c.points.push_back({double(n), settings.step,
                          accuracy_detail::measure(make, times, truth, o.repeats, o.budget)});
      fmt::print(stderr, ".");
    }
    curves.push_back(std::move(c));
  }
  runge_kutta_curves(s, tolerances(o.quick, 1e-12), times, truth, o, curves);
  fmt::print(stderr, "\n");

  for (const Curve& c : curves) write_curve(o.out, "4a", c);
  print_table(fmt::format("Figure 4a (n = 5, α = 2, ζ = 0.2, θ = 1, from rest): largest error of "
                          "the {} Poincaré points against the exact event-driven solver",
                          periods),
              curves, 1e-11);
  print_cost_to_reach(curves, 1e-11);
  plot(o, "4a", curves,
       fmt::format("Figure 4a (5 DOF, α = 2, ζ = 0.2, θ = 1): {} periods from rest", periods),
       "largest error of the Poincaré states x, x′ (nondimensional)");
}

void large_chain(const AccuracyOptions& o) {
  const GapStructure s = make_chain(paper_large_chain(o.chain_masses));
  const double t_end = o.quick ? std::min(o.chain_time, 5.0) : o.chain_time;
  std::vector<double> times;
  for (int k = 1; k <= static_cast<int>(std::floor(t_end + 1e-9)); ++k) times.push_back(k);
  if (times.empty()) throw InputError(fmt::format("--chain-time = {} must be at least 1 s", t_end));

  MethodSettings truth_settings;
  truth_settings.method = Method::rkf78;
  truth_settings.tolerance = o.chain_truth_tolerance;
  truth_settings.locate_kinks = true;
  const Factory truth_factory = table_factory(s, truth_settings);
  const Run truth_run = accuracy_detail::measure(truth_factory, times, {}, 1, o.budget);
  if (!truth_run.ok) throw Error("the chain's truth (rkf78) failed: " + truth_run.failure);
  const std::vector<Vector> truth = truth_run.states;
  fmt::print(stderr, "chain n = {}: truth rkf78 kink-located tol {:g} took {:.3g} s; measuring",
             o.chain_masses, o.chain_truth_tolerance, truth_run.median_seconds);

  std::vector<Curve> curves;
  {
    Curve c;
    c.key = "pim";
    c.label = "PIM (paper, banded when it applies)";
    c.parameter_name = "steps/s";
    c.fixed_step = true;
    const std::vector<int> per_second = o.quick ? std::vector<int>{10, 50, 200}
                                                : std::vector<int>{5, 10, 25, 50, 100, 200, 400, 800};
    for (int n : per_second) {
      const MethodSettings settings = at_step(Method::pim, 1.0 / n);
      const Factory make = table_factory(s, settings);
      c.points.push_back({double(n), settings.step,
                          accuracy_detail::measure(make, times, truth, o.repeats, o.budget)});
      fmt::print(stderr, ".");
    }
    curves.push_back(std::move(c));
  }
  for (int degree : {2, 4}) {
    // The switching PIM with banded operators (banded_switching_pim.hpp), d = 2 (the default) and
    // 4 with the end slope, from η = 0.5 s (its cost is then that of locating the run's switches,
    // the same at any step) until it reaches the truth's tolerance (d = 4 sooner).
    Curve c;
    c.key = degree == 2 ? "pim-switching" : fmt::format("pim-switching-d{}", degree);
    c.label = fmt::format("switching PIM d={} (order {}), banded", degree, degree + 3);
    c.parameter_name = "steps/s";
    c.fixed_step = true;
    const std::vector<int> per_second =
        o.quick ? std::vector<int>{10, 50}
        : degree == 2 ? std::vector<int>{2, 4, 10, 25, 50, 100, 200}
                      : std::vector<int>{2, 4, 5, 10, 25, 50};
    for (int n : per_second) {
      MethodSettings settings = at_step(Method::pim_switching_banded, 1.0 / n);
      settings.force_degree = degree;
      const Factory make = table_factory(s, settings);
      c.points.push_back({double(n), settings.step,
                          accuracy_detail::measure(make, times, truth, o.repeats, o.budget)});
      fmt::print(stderr, ".");
    }
    curves.push_back(std::move(c));
  }
  runge_kutta_curves(s, tolerances(o.quick, 100 * o.chain_truth_tolerance), times, truth, o, curves);
  fmt::print(stderr, "\n");
  for (const Curve& c : curves) write_curve(o.out, "chain", c);
  print_table(fmt::format("Chain n = {} (paper §4.2), t in [0, {}] s: largest error of x, x′ at "
                          "every whole second against rkf78 kink-located at tolerance {:g} ({:.3g} s)",
                          o.chain_masses, t_end, o.chain_truth_tolerance, truth_run.median_seconds),
              curves, 100 * o.chain_truth_tolerance);
  print_cost_to_reach(curves, 100 * o.chain_truth_tolerance);
  plot(o, "chain", curves,
       fmt::format("Chain n = {} (m = 1 kg, k1 = k2 = 1 N/m, c = 0.2 N s/m): t in [0, {}] s",
                   o.chain_masses, t_end),
       fmt::format("largest error of x [m], x′ [m/s] vs rkf78 tol {:g}", o.chain_truth_tolerance));
}

void accuracy(AccuracyOptions o) {
  if (o.plots.empty()) o.plots = figures_directory(plots_directory());
  if (o.out.empty()) o.out = plots_directory() + "/data/accuracy";
  if (o.repeats < 1) throw InputError(fmt::format("--repeats = {} must be at least 1", o.repeats));
  if (o.periods < 1) throw InputError(fmt::format("--periods = {} must be at least 1", o.periods));
  if (o.chain_masses < 2) {
    throw InputError(fmt::format("--chain-masses = {} must be at least 2", o.chain_masses));
  }
  if (!(o.chain_truth_tolerance > 0.0) || !(o.chain_truth_tolerance < 1e-4)) {
    throw InputError(fmt::format("--chain-truth-tol = {} must be in (0, 1e-4)",
                                 o.chain_truth_tolerance));
  }
  std::filesystem::create_directories(o.out);
  std::filesystem::create_directories(o.plots);
  for (const std::string& c : o.cases) {
    if (c == "4a") {
      five_dof(o);
    } else if (c == "chain") {
      large_chain(o);
    } else {
      throw InputError(fmt::format("--case \"{}\": the cases are 4a and chain", c));
    }
  }
  fmt::print("CSV files in {}\n", o.out);
}

}  // namespace

void add_accuracy_benches(CLI::App& bench) {
  auto options = std::make_shared<AccuracyOptions>();
  CLI::App* c = bench.add_subcommand(
      "accuracy",
      "Work-precision diagrams: error against CPU time for every method, with measured orders\n"
      "Example: pwl bench accuracy --case 4a --repeats 5");
  c->add_option("--case", options->cases, "Cases: 4a, chain (default both)")->delimiter(',');
  c->add_option("--periods", options->periods, "Figure 4a: forcing periods from rest")
      ->check(positive_number());
  c->add_option("--repeats", options->repeats, "Timed runs per point (median reported)")
      ->check(positive_number());
  c->add_option("--budget", options->budget, "CPU seconds of repeats per point (>= 1 run)")
      ->check(positive_number());
  c->add_option("--chain-masses", options->chain_masses, "Chain: number of masses")
      ->check(number_at_least(2));
  c->add_option("--chain-time", options->chain_time, "Chain: end time in seconds")
      ->check(number_at_least(1));
  c->add_option("--chain-truth-tol", options->chain_truth_tolerance,
                "Chain: tolerance of the kink-located rkf78 taken as the truth")
      ->check(number_between(0, 1e-4));
  c->add_option("--out", options->out, "CSV folder (default plots/data/accuracy)");
  c->add_option("--plots", options->plots, "PNG and SVG folder (default plots/figures)");
  c->add_flag("--quick", options->quick, "Fewer points and shorter runs (a smoke test)");
  c->add_flag("--no-plot", options->no_plot, "Write the CSV files only");
  c->callback([options] { accuracy(*options); });
  accuracy_detail::add_stability_bench(bench);
}

}  // namespace pwl::app
