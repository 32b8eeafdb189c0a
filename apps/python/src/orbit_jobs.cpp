// pwl.orbit and pwl.continue_: the jobs of `pwl orbit` and `pwl continue`, parsed by their own
// flags (orbit_command.hpp, continue_command.hpp) and run in memory.
#include <fmt/format.h>

#include <cmath>

#include "arguments.hpp"
#include "arrays.hpp"
#include "interrupt.hpp"
#include "jobs.hpp"
#include "structure.hpp"
#include "commands/continue_command.hpp"
#include "commands/orbit_command.hpp"
#include "pwl/orbits/orbit_profile.hpp"

namespace pwl::python {
namespace {

const LeftOut kOrbitLeftOut{
    {"--out", "pwl.orbit returns the orbit instead of writing orbit.csv and floquet.csv"},
    {"--quiet", "pwl.orbit prints nothing"},
    {"--no-path", "pwl.orbit writes no orbit_path.csv"},
};

const LeftOut kContinueLeftOut{
    {"--out",
     "pwl.continue_ returns the branch instead of writing branch.csv and bifurcations.csv"},
    {"--quiet", "pwl.continue_ prints no progress"},
    {"--no-plot", "pwl.continue_ draws nothing"},
    {"--record", "pwl.continue_ returns the amplitude and state of every mass"},
    {"--over-sweep", "run pwl.sweep(mode='continuation') for the brute-force diagram"},
    {"--over-periods", "run pwl.sweep(mode='continuation') for the brute-force diagram"},
    {"--threads", "it sets the threads of --over-sweep, which pwl.continue_ does not run"},
};

// The flags pwl.orbit takes: pwl orbit's, less those it leaves out.
void orbit_app(CLI::App& app, app::OrbitCommandFlags& flags) {
  app::add_orbit_command_flags(app, flags);
  leave_out(app, kOrbitLeftOut);
}
std::vector<KeywordDoc> orbit_keywords() {
  CLI::App app{"pwl.orbit"};
  app.option_defaults()->always_capture_default();
  app::OrbitCommandFlags flags;
  orbit_app(app, flags);
  return keyword_docs(app);
}

// The flags pwl.continue_ takes: pwl continue's, less those it leaves out.
void continuation_app(CLI::App& app, app::ContinueFlags& flags) {
  app::add_continue_flags(app, flags);
  leave_out(app, kContinueLeftOut);
}
std::vector<KeywordDoc> continuation_keywords() {
  CLI::App app{"pwl.continue_"};
  app.option_defaults()->always_capture_default();
  app::ContinueFlags flags;
  continuation_app(app, flags);
  return keyword_docs(app);
}

py::dict multipliers_dict(const orbits::FloquetMultipliers& mu) {
  py::dict d;
  d["multipliers"] = complex_array(mu.values);
  d["multipliers_complete"] = mu.complete;
  d["multipliers_converged"] = mu.converged;
  d["largest_modulus"] = mu.values.empty() ? std::nan("") : mu.largest_modulus();
  d["unstable_count"] = mu.unstable_count();
  return d;
}

py::dict orbit(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.orbit"};
  app::OrbitCommandFlags flags;
  orbit_app(app, flags);
  parse_keywords(app, "orbit", args, kOrbitLeftOut);
  app::read_method_given(app, flags.orbit);

  app::OrbitProblem problem = app::orbit_problem(flags);
  orbits::PeriodicOrbit orbit, minimal;
  orbits::OrbitProfile profile;
  without_gil([&] {
    orbits::StroboscopicMap& map = *problem.map;
    const Vector guess = app::starting_guess(flags.orbit, map);
    orbit = orbits::find_periodic_orbit(map, guess, problem.shooting);
    minimal = orbits::at_minimal_period(map, orbit, problem.shooting);
    profile = orbits::orbit_profile(map, orbit.state, flags.orbit.period);
  });
  py::dict d = multipliers_dict(orbit.multipliers);
  d["state"] = vector_array(orbit.state);
  d["period"] = orbit.period;
  d["minimal_period"] = minimal.period;
  d["minimal_largest_modulus"] =
      minimal.multipliers.values.empty() ? std::nan("") : minimal.multipliers.largest_modulus();
  d["forcing_period"] = orbit.forcing_period;
  d["residual"] = orbit.residual;
  d["iterations"] = orbit.iterations;
  d["evaluations"] = orbit.evaluations;
  d["solver"] = orbits::shooting_solver_name(orbit.solver);
  d["exact_tangent"] = orbit.exact_tangent;
  d["krylov_products"] = orbit.krylov_products;
  d["preconditioned"] = orbit.preconditioned;
  d["stable"] = orbit.stable();
  d["verdict"] = orbit.stable() ? "stable" : "unstable";
  d["monodromy"] = orbit.monodromy.size() > 0 ? py::object(matrix_array(orbit.monodromy))
                                              : py::object(py::none());
  d["amplitude"] = vector_array(profile.amplitude);
  d["max_position"] = vector_array(profile.max_position);
  d["min_position"] = vector_array(profile.min_position);
  d["max_gap"] = vector_array(profile.max_gap);
  d["min_gap"] = vector_array(profile.min_gap);
  d["method"] = app::orbit_method_label(problem.method);
  d["method_default"] = problem.method.chosen;
  d["description"] = name_given_structure(flags.orbit.run.description(), file.get());
  return d;
}

// Sees every accepted point of the continuation, for Ctrl-C.
class Checkpoints : public orbits::ContinuationObserver {
 public:
  void point(const orbits::BranchPoint&) override { interrupt_.poll(); }

 private:
  Interrupt interrupt_;
};

// Ctrl-C looked at after every point of a bifurcation curve.
class CurveCheckpoints : public orbits::CurvesObserver {
 public:
  void point(const orbits::CurvePointRecord&) override { interrupt_.poll(); }

 private:
  Interrupt interrupt_;
};

// The counts a branch (ContinuationResult) and its curves (CurvesResult) both keep: integrations,
// Krylov and multiplier products, and how the leading multipliers fared and were found.
template <class Result>
py::dict work_counts(const Result& r) {
  py::dict work;
  work["monodromies"] = r.monodromies;
  work["integrations"] = r.integrations;
  work["krylov_products"] = r.krylov_products;
  work["multiplier_products"] = r.arnoldi_products;
  work["unconverged_multipliers"] = r.unconverged_multipliers;
  work["uncovered_bands"] = r.uncovered_bands;
  work["davidson_points"] = r.davidson_points;
  work["arnoldi_points"] = r.arnoldi_points;
  return work;
}

// The curves and codimension-two points as dicts of columns, as curves.csv and codim2.csv have
// them (the parameters by their names; multipliers complex; amplitude and state as rows).
void add_curves(py::dict& d, const orbits::CurvesResult& r, const orbits::CurvesOptions& o,
                Index n) {
  const std::string p = o.first.name(), q = o.second.name();
  py::dict curves;
  py::list type;
  std::vector<int> curve, period, spring;
  std::vector<double> pv, qv, kappa, amplitude, state;
  std::vector<std::complex<double>> multiplier;
  for (const orbits::CurvePointRecord& c : r.points) {
    curve.push_back(c.curve);
    type.append(orbits::curve_type_name(c.type));
    pv.push_back(c.p);
    qv.push_back(c.q);
    period.push_back(c.period);
    spring.push_back(c.spring + 1);
    multiplier.push_back(c.multiplier);
    kappa.push_back(c.kappa);
    amplitude.insert(amplitude.end(), c.amplitude.data(), c.amplitude.data() + n);
    state.insert(state.end(), c.state.data(), c.state.data() + 2 * n);
  }
  const auto rows = static_cast<py::ssize_t>(r.points.size());
  curves["curve"] = int_array(curve);
  curves["type"] = type;
  curves[p.c_str()] = vector_array(pv);
  curves[q.c_str()] = vector_array(qv);
  curves["period"] = int_array(period);
  curves["spring"] = int_array(spring);
  curves["multiplier"] = complex_array(multiplier);
  curves["kappa"] = vector_array(kappa);
  curves["amplitude"] = rows_array(amplitude, rows, n);
  curves["state"] = rows_array(state, rows, 2 * n);
  d["curves"] = curves;
  py::dict codim2;
  py::list ctype, detail, on;
  std::vector<double> cp, cq, cstate;
  for (const orbits::Codim2Point& c : r.codim2) {
    ctype.append(c.type);
    detail.append(c.detail);
    cp.push_back(c.p);
    cq.push_back(c.q);
    py::list ids;
    for (int id : c.curves) ids.append(id);
    on.append(ids);
    cstate.insert(cstate.end(), c.state.data(), c.state.data() + 2 * n);
  }
  codim2["type"] = ctype;
  codim2[p.c_str()] = vector_array(cp);
  codim2[q.c_str()] = vector_array(cq);
  codim2["curves"] = on;
  codim2["detail"] = detail;
  codim2["state"] = rows_array(cstate, static_cast<py::ssize_t>(r.codim2.size()), 2 * n);
  d["codim2"] = codim2;
  py::list ends, notes;
  for (const orbits::CurveSummary& c : r.curves) {
    ends.append(py::make_tuple(c.ends[0], c.ends[1]));
  }
  for (const std::string& note : r.notes) notes.append(note);
  d["curve_ends"] = ends;
  d["curve_notes"] = notes;
  d["curve_work"] = work_counts(r);
}

py::dict continuation(py::kwargs kwargs) {
  py::dict args(kwargs);
  const auto file = take_structure(args);
  CLI::App app{"pwl.continue_"};
  app::ContinueFlags flags;
  continuation_app(app, flags);
  parse_keywords(app, "continue_", args, kContinueLeftOut);
  app::read_method_given(app, flags.orbit);

  const app::ContinuationProblem problem = app::continuation_problem(flags);
  orbits::ContinuationResult result;
  without_gil([&] {
    Vector guess;
    {
      orbits::StroboscopicMap map(problem.first_case, problem.method.settings,
                                  problem.method.steps_per_period);
      guess = app::starting_guess(flags.orbit, map);
    }
    Checkpoints checkpoints;
    result = orbits::continue_periodic_orbit(problem.base, guess, problem.options, &checkpoints);
  });
  orbits::CurvesResult curves;
  if (problem.curves) {
    const std::vector<orbits::Bifurcation> starts = app::curve_starts(problem, result.bifurcations);
    without_gil([&] {
      CurveCheckpoints checkpoints;
      curves = orbits::follow_bifurcation_curves(problem.base, starts, *problem.curves,
                                                 &checkpoints);
    });
  }
  const auto count = static_cast<py::ssize_t>(result.points.size());
  const Index n = problem.base.dofs();
  std::vector<int> branch, period, stable, unstable, iterations;
  std::vector<double> parameter, arclength, largest, residual, amplitude, state;
  std::size_t width = 0;
  for (const orbits::BranchPoint& p : result.points) {
    width = std::max(width, p.orbit.multipliers.values.size());
  }
  py::array_t<std::complex<double>> multipliers({count, static_cast<py::ssize_t>(width)});
  auto mu = multipliers.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < count; ++i) {
    const orbits::BranchPoint& p = result.points[static_cast<std::size_t>(i)];
    branch.push_back(p.branch);
    parameter.push_back(p.parameter);
    arclength.push_back(p.arclength);
    period.push_back(p.orbit.period);
    stable.push_back(p.orbit.stable() ? 1 : 0);
    largest.push_back(p.orbit.multipliers.largest_modulus());
    unstable.push_back(p.orbit.multipliers.unstable_count());
    residual.push_back(p.orbit.residual);
    iterations.push_back(p.orbit.iterations);
    amplitude.insert(amplitude.end(), p.profile.amplitude.data(),
                     p.profile.amplitude.data() + n);
    state.insert(state.end(), p.orbit.state.data(), p.orbit.state.data() + 2 * n);
    const auto& values = p.orbit.multipliers.values;
    for (std::size_t j = 0; j < width; ++j) {
      mu(i, static_cast<py::ssize_t>(j)) =
          j < values.size() ? values[j] : std::complex<double>(std::nan(""), std::nan(""));
    }
  }
  py::dict d;
  d["branch"] = int_array(branch);
  d["parameter"] = vector_array(parameter);
  d["arclength"] = vector_array(arclength);
  d["period"] = int_array(period);
  d["stable"] = int_array(stable);
  d["max_abs_multiplier"] = vector_array(largest);
  d["unstable_multipliers"] = int_array(unstable);
  d["residual"] = vector_array(residual);
  d["iterations"] = int_array(iterations);
  d["amplitude"] = rows_array(amplitude, count, n);
  d["state"] = rows_array(state, count, 2 * n);
  d["multipliers"] = multipliers;

  py::dict table;
  py::list type, detail;
  std::vector<double> b_parameter, b_abs, b_test;
  std::vector<int> b_branch, b_period, b_spring, b_located, b_largest, b_to, b_joined;
  std::vector<std::complex<double>> b_multiplier;
  std::vector<double> b_state;
  for (const orbits::Bifurcation& b : result.bifurcations) {
    const bool grazing = b.type == orbits::BifurcationType::grazing;
    type.append(orbits::bifurcation_name(b.type));
    detail.append(app::bifurcation_detail(b));
    b_parameter.push_back(b.parameter);
    b_branch.push_back(b.branch);
    b_period.push_back(b.period);
    b_spring.push_back(grazing ? b.spring + 1 : 0);
    const std::complex<double> nan(std::nan(""), std::nan(""));
    b_multiplier.push_back(grazing ? nan : b.multiplier);
    b_abs.push_back(grazing ? std::nan("") : std::abs(b.multiplier));
    b_test.push_back(b.test_value);
    b_located.push_back(b.located ? 1 : 0);
    b_largest.push_back(b.at_largest_gap ? 1 : 0);
    b_to.push_back(b.to_branch);
    b_joined.push_back(b.joined_by);
    for (Index i = 0; i < 2 * n; ++i) {
      b_state.push_back(i < b.state.size() ? b.state(i) : std::nan(""));
    }
  }
  const auto found = static_cast<py::ssize_t>(result.bifurcations.size());
  table["type"] = type;
  table["parameter"] = vector_array(b_parameter);
  table["branch"] = int_array(b_branch);
  table["period"] = int_array(b_period);
  table["spring"] = int_array(b_spring);
  table["multiplier"] = complex_array(b_multiplier);
  table["abs_multiplier"] = vector_array(b_abs);
  table["detail"] = detail;
  table["located"] = int_array(b_located);
  table["at_largest_gap"] = int_array(b_largest);
  table["to_branch"] = int_array(b_to);
  table["joined_by"] = int_array(b_joined);
  table["test_value"] = vector_array(b_test);
  table["state"] = rows_array(b_state, found, 2 * n);
  d["bifurcations"] = table;
  py::list notes;
  for (const std::string& note : result.notes) notes.append(note);
  d["notes"] = notes;
  // The work and what the band round the circle saw (ContinuationResult's counts).
  py::dict work = work_counts(result);
  work["matrix_free"] = result.matrix_free;
  work["band_cuts"] = result.band_cuts;
  work["band"] = result.band;
  work["narrowest_band"] = result.narrowest_band;
  work["step_cuts"] = result.step_cuts;
  d["work"] = work;
  if (problem.curves) {
    add_curves(d, curves, *problem.curves, n);
  } else {
    d["curves"] = py::none();
    d["codim2"] = py::none();
    d["curve_ends"] = py::list();
    d["curve_notes"] = py::list();
    d["curve_work"] = py::none();
  }
  d["parameter_name"] = problem.parameter.name();
  d["method"] = app::orbit_method_label(problem.method);
  d["method_default"] = problem.method.chosen;
  d["description"] = name_given_structure(flags.orbit.run.description(), file.get());
  return d;
}

}  // namespace

void bind_orbit_jobs(py::module_& m) {
  m.def("orbit", &orbit, "The period-k orbit by shooting: see pwl.orbit.");
  m.def("continue_", &continuation, "Continuation of a periodic orbit: see pwl.continue_.");
  register_keywords("orbit", &orbit_keywords);
  register_keywords("continue_", &continuation_keywords);
}

}  // namespace pwl::python
