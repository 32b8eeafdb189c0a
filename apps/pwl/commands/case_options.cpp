#include "commands/case_options.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <algorithm>
#include <filesystem>
#include <limits>

#include "commands/cli_checks.hpp"
#include "commands/step_guard_report.hpp"
#include "pwl/integrators/accuracy_step.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"
#include "scene/scene_structure.hpp"

namespace pwl::app {

void add_chain_options(CLI::App& c, std::string& figure, int& masses, std::vector<double>& alpha,
                       double& zeta, double& gap, double& theta, std::vector<double>& loads) {
  c.add_option("--figure", figure, "Start from one of the paper's 5-DOF cases: 4a, 4b, 5, 6")
      ->check(CLI::IsMember({"4a", "4b", "5", "6"}));
  c.add_option("--n", masses, "Number of masses")->check(positive_number());
  // Unset chain parameters come from --figure's case, else from the chain's defaults. A NaN
  // stands for "not given" in zeta, gap and theta, so their validators refuse a typed NaN (and
  // ±Inf) before it can pass for the default. θ's sign is the chain's own check (make_chain:
  // "theta = -1 must be positive and finite"), which every job runs before any work, through
  // CaseOptions::structure or CaseOptions::model.
  const NondimensionalChain d;
  const auto preset = [](double value) { return fmt::format("{} or --figure's", value); };
  c.add_option("--alpha", alpha, "Contact stiffness ratio k2/k1 (one value or one per mass)")
      ->delimiter(',')
      ->check(non_negative_number())
      ->default_str(preset(d.alpha[0]));
  c.add_option("--zeta", zeta, "Damping ratio c/sqrt(k1 m)")
      ->check(non_negative_number())
      ->default_str(preset(d.zeta));
  c.add_option("--gap", gap, "Nondimensional gap of every mass's spring (negative: preloaded)")
      ->check(finite_number())
      ->default_str(preset(d.gap[0]));
  c.add_option("--theta", theta, "Forcing frequency ratio ω/ω0")
      ->check(finite_number())
      ->default_str(preset(d.theta));
  c.add_option("--loads", loads, "Load amplitudes Q per mass, comma separated")
      ->delimiter(',')
      ->check(finite_number())
      ->default_str(fmt::format("{} or --figure's", fmt::join(d.amplitude, ",")));
}

std::string method_help() {
  std::string help = "Integrator:";
  for (const MethodTraits& row : method_table()) {
    help += fmt::format("\n  {}: {}", row.name, row.summary);
  }
  return help;
}

Vector InitialStateFlags::state(Index dofs) const {
  Vector y = Vector::Zero(2 * dofs);
  const auto fill = [&](const char* flag, const std::vector<double>& values, Index offset) {
    if (values.empty()) return;
    // Each value first, then their count: a NaN is wrong whatever the number of masses.
    for (double value : values) {
      if (!std::isfinite(value)) {
        throw InputError(fmt::format("{} {}: {} is not a finite number", flag,
                                     fmt::join(values, ","), value));
      }
    }
    const std::size_t n = static_cast<std::size_t>(dofs);
    if (values.size() != 1 && values.size() != n) {
      throw InputError(fmt::format("{} {}: {} values for {} masses; give one per mass or one value "
                                   "for every mass",
                                   flag, fmt::join(values, ","), values.size(), dofs));
    }
    for (Index i = 0; i < dofs; ++i) {
      y[offset + i] = values.size() == 1 ? values[0] : values[static_cast<std::size_t>(i)];
    }
  };
  fill("--x0", x0, 0);
  fill("--v0", v0, dofs);
  return y;
}

std::string InitialStateFlags::text() const {
  if (at_rest()) return "rest";
  std::string text;
  if (!x0.empty()) text += fmt::format("x0 = ({})", fmt::join(x0, ","));
  if (!v0.empty()) text += fmt::format("{}v0 = ({})", text.empty() ? "" : ", ", fmt::join(v0, ","));
  return text;
}

void add_initial_state_flags(CLI::App& c, InitialStateFlags& f) {
  c.add_option("--x0", f.x0,
               "Initial displacements at t = 0, comma separated: one per mass, or one value for\n"
               "every mass (default: 0)")
      ->delimiter(',');
  c.add_option("--v0", f.v0,
               "Initial velocities at t = 0, as --x0 (default: 0; both left out: from rest)")
      ->delimiter(',');
}

analysis::PoincareSection SectionFlags::poincare_section(Index dofs) const {
  analysis::PoincareSection s;
  try {
    s = analysis::parse_poincare_section(section, dofs);
  } catch (const InputError& e) {
    throw InputError(fmt::format("--section {}: {}", section, e.what()));
  }
  if (!(phase >= 0.0 && phase < 1.0)) {
    throw InputError(fmt::format(
        "--phase {}: the phase is a fraction of the forcing period, 0 <= P < 1", phase));
  }
  s.phase = phase;
  return s;
}

void add_section_flags(CLI::App& c, SectionFlags& f, const std::string& what) {
  c.add_option("--section", f.section,
               "Poincaré section: strobe (the states at t = (k + P) T, P = --phase), or a\n"
               "hyperplane x<i>=<level>,<up|down|both> or v<i>=... (every crossing of that\n"
               "component through the level in that direction, e.g. v3=0,down: the largest\n"
               "excursions of mass 3). The regime, λ1 and K are properties of the motion and\n"
               "stay classified on the stroboscopic map at --phase; the section changes which\n"
               "points are recorded. " +
                   what);
  c.add_option("--phase", f.phase,
               "Phase P of the stroboscopic points, a fraction of the forcing period T,\n"
               "0 <= P < 1: the points at t = (k + P) T");
}

void add_case_options(CLI::App& c, CaseOptions& o) {
  add_chain_options(c, o.figure, o.masses, o.alpha, o.zeta, o.gap, o.theta, o.loads);
  c.add_option("--gaps", o.gaps, "Gaps per mass, comma separated (overrides --gap)")
      ->delimiter(',')
      ->check(finite_number())
      ->default_str("");
  c.add_option("--periods", o.periods, "Forcing periods to integrate")->check(positive_number());
  c.add_option("--skip-periods", o.skip_periods, "Leading periods left out of the output")
      ->check(non_negative_number());
  CLI::Option* spp =
      c.add_option("--steps-per-period", o.steps_per_period, "PIM steps per forcing period")
          ->check(positive_number());
  CLI::Option* dt =
      c.add_option("--dt", o.dt, "PIM step (must divide the forcing period; 0: --steps-per-period)")
          ->check(non_negative_number());
  c.add_option("--rtol", o.rtol,
               "PIM family: the largest step T/N whose estimated error, relative to the\n"
               "motion, meets this over the first 4 periods (step doubling; instead of\n"
               "--steps-per-period and --dt; at least 1e-12)")
      ->check(positive_number())
      ->check(number_in(kSmallestRelativeTolerance, 0.5))
      ->excludes(spp)
      ->excludes(dt);
  c.add_option("--method", o.method, method_help())->check(CLI::IsMember(method_names()));
  c.add_option("--force-degree", o.force_degree,
               "Switching PIM: derivatives d of the spring forces used (order d + 3), 0 .. 8;\n"
               "default 2, or with --rtol chosen with the step from 2, 4 and 6")
      ->check(number_in(0, 8))
      ->default_str("2");
  c.add_option("--tol", o.tolerance, "Relative and absolute tolerance of dopri5/rkf78")
      ->check(positive_number());
  c.add_flag("--locate-kinks", o.locate_kinks,
             "dopri5/rkf78: end a step exactly at every spring opening or closing");
  c.add_option("--structure-scene", o.structure_scene,
               "Integrate the explicit structure (M, C, K, gap springs, loads) of this scene\n"
               "file's [structure] table instead of the chain")
      ->check(CLI::ExistingFile);
  c.add_option("--lcp", o.lcp_solver, "PIM's LCP solver: block-pivoting or lemke")
      ->check(CLI::IsMember({"block-pivoting", "lemke"}));
  add_initial_state_flags(c, o.start);
  add_force_flag(c, o.force);
}

GapStructure CaseOptions::structure() const {
  if (!explicit_structure()) return make_chain(chain());
  const bool chain_flags = !figure.empty() || !alpha.empty() || !std::isnan(zeta) ||
                           !std::isnan(gap) || !gaps.empty() || !std::isnan(theta) ||
                           !loads.empty() || masses != 5;
  if (chain_flags) {
    throw InputError(fmt::format(
        "--structure-scene {}: the chain's flags (--figure, --n, --alpha, --zeta, --gap, --gaps, "
        "--theta, --loads) do not apply to an explicit structure",
        structure_scene));
  }
  return read_scene_structure(structure_scene);
}

double CaseOptions::period() const {
  return explicit_structure() ? structure().common_period() : chain().period();
}

std::string CaseOptions::description() const {
  if (explicit_structure()) return fmt::format("the structure of {}", structure_scene);
  const NondimensionalChain c = chain();
  return fmt::format("α = {}, ζ = {}, Δ̃ = {}, θ = {}", fmt::join(c.alpha, ","), c.zeta,
                     fmt::join(c.gap, ","), c.theta);
}

NondimensionalChain CaseOptions::chain() const {
  NondimensionalChain c;
  if (!figure.empty()) c = paper_five_dof_case(figure);
  c.masses = masses;
  if (!alpha.empty()) c.alpha = alpha;
  if (!std::isnan(zeta)) c.zeta = zeta;
  if (!gaps.empty()) {
    c.gap = gaps;
  } else if (!std::isnan(gap)) {
    c.gap = {gap};
  }
  if (!std::isnan(theta)) c.theta = theta;
  if (!loads.empty()) {
    c.amplitude = loads;
  } else if (masses != 5) {
    // The paper's alternating Q = (1, -1, 1, ...) for any number of masses.
    c.amplitude.clear();
    for (int i = 0; i < masses; ++i) c.amplitude.push_back(i % 2 == 0 ? 1.0 : -1.0);
  }
  return c;
}

int CaseOptions::grid_steps(double period) const {
  if (!(rtol > 0.0)) return steps_per_period;
  if (rtol_steps > 0 && rtol_method == method) return static_cast<int>(rtol_steps);
  const Method m = parse_method(method);
  if (!method_traits(m).fixed_grid) {
    throw InputError(fmt::format("--rtol = {}: the accuracy request of the PIM family; {} takes "
                                 "--tol",
                                 rtol, method));
  }
  const GapStructure s = structure();
  const Index n = s.dofs();
  const Vector y = start.state(n);
  MethodSettings settings;
  settings.method = m;
  settings.lcp = parse_lcp_algorithm(lcp_solver);
  AccuracyRequest request;
  request.relative_tolerance = rtol;
  request.period = period;
  request.probe = std::min(periods, 4) * period;
  request.max_steps_per_period = std::numeric_limits<int>::max() / 2;
  if (takes_force_degree(method_traits(m))) {
    if (force_degree >= 0) {
      settings.force_degree = force_degree;
    } else {
      request.force_degrees.assign(kChoosableForceDegrees.begin(), kChoosableForceDegrees.end());
    }
  }
  std::string why;
  if (!request.is_valid(&why)) throw InputError("--rtol: " + why);
  const AccuracyStep chosen = step_for_accuracy(s, settings, 0.0, y.head(n), y.tail(n), request);
  rtol_steps = chosen.steps_per_period;
  rtol_degree = chosen.force_degree;
  rtol_method = method;
  fmt::print(stderr,
             "pwl: note: --rtol {:g}: η = T/{} = {:.6g}{} (estimated error {:.2g} over the first "
             "{} periods; {} step{} tried{})\n",
             rtol, chosen.steps_per_period, chosen.step,
             chosen.force_degree >= 0 ? fmt::format(", force degree {}", chosen.force_degree) : "",
             chosen.estimated_error, std::min(periods, 4), chosen.candidates,
             chosen.candidates > 1 ? "s" : "",
             chosen.degree_checks > 0
                 ? fmt::format(", then {} lower degree{} at that step", chosen.degree_checks,
                               chosen.degree_checks > 1 ? "s" : "")
                 : "");
  return static_cast<int>(rtol_steps);
}

int CaseOptions::switching_degree(double period) const {
  const MethodTraits& traits = method_traits(parse_method(method));
  if (!takes_force_degree(traits)) {
    if (force_degree >= 0) {
      throw InputError(fmt::format("--force-degree = {}: {} takes no force degree (the switching "
                                   "PIM does)",
                                   force_degree, traits.name));
    }
    return MethodSettings{}.force_degree;
  }
  if (force_degree >= 0) return force_degree;
  if (rtol > 0.0) {
    grid_steps(period);
    return rtol_degree;
  }
  return MethodSettings{}.force_degree;
}

double CaseOptions::step(double period) const {
  if (rtol > 0.0) return period / grid_steps(period);
  if (dt == 0.0) return period / steps_per_period;
  if (!(dt > 0.0)) throw InputError(fmt::format("--dt = {} must be positive", dt));
  const double ratio = period / dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio) {
    throw InputError(fmt::format(
        "--dt = {} does not divide the forcing period {} ({} steps); use --steps-per-period", dt,
        period, ratio));
  }
  return period / std::round(ratio);
}

analysis::PointModel CaseOptions::model() const {
  if (!explicit_structure()) {
    // The chain's own checks (θ > 0, ζ >= 0, α >= 0, one value or one per mass) on the flags as
    // given, also when a study varies one of them: a sweep of θ from --theta -1 is refused like
    // a simulation at θ = -1.
    const NondimensionalChain c = chain();
    make_chain(c);
    return analysis::PointModel(c);
  }
  return analysis::PointModel(analysis::ExplicitStructure{
      structure(), description(), std::filesystem::path(structure_scene).filename().string()});
}

MethodSettings CaseOptions::method_settings(double period) const {
  MethodSettings m;
  m.method = parse_method(method);
  // The degree first: a --force-degree the method does not take is refused before --rtol searches.
  m.force_degree = switching_degree(period);
  if (method_traits(m.method).fixed_grid || rtol > 0.0) m.step = step(period);  // --rtol: checks the method
  m.tolerance = tolerance;
  m.locate_kinks = locate_kinks;
  m.max_step = period / 8;
  m.lcp = parse_lcp_algorithm(lcp_solver);
  report_exact_progress(m);
  return m;
}

std::unique_ptr<Integrator> CaseOptions::integrator(const GapStructure& structure,
                                                    double period) const {
  const MethodSettings settings = method_settings(period);
  guard_step(structure, settings, period, force);
  std::unique_ptr<Integrator> integrator = make_integrator(structure, settings);
  if (!start.at_rest()) {
    const Index n = structure.dofs();
    const Vector y = start.state(n);
    integrator->set_state(0.0, y.head(n), y.tail(n));
  }
  return integrator;
}

}  // namespace pwl::app
