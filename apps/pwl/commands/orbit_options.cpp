#include "commands/orbit_options.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "commands/cli_checks.hpp"
#include "commands/step_guard_report.hpp"
#include "pwl/errors.hpp"
#include "pwl/integrators/method_table.hpp"

namespace pwl::app {

namespace {

constexpr Index kExactDofs = 20;      // the default exact solver's largest structure ...
constexpr Index kExactSprings = 62;   // ... and its most gap springs (the method table's limit)

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t from = 0;
  while (true) {
    const std::size_t comma = line.find(',', from);
    std::string field = line.substr(from, comma == std::string::npos ? std::string::npos
                                                                     : comma - from);
    while (!field.empty() && (field.back() == ' ' || field.back() == '\r')) field.pop_back();
    while (!field.empty() && field.front() == ' ') field.erase(0, 1);
    fields.push_back(field);
    if (comma == std::string::npos) return fields;
    from = comma + 1;
  }
}

}  // namespace

void add_orbit_flags(CLI::App& c, OrbitFlags& f, bool with_dt) {
  add_case_options(c, f.run);
  // An orbit is not a run of so many periods: the flags of one are left out.
  c.remove_option(c.get_option("--periods"));
  c.remove_option(c.get_option("--skip-periods"));
  if (!with_dt) c.remove_option(c.get_option("--dt"));
  c.get_option("--method")
      ->default_str(fmt::format("exact for <= {} masses and <= {} gap springs, else pim-switching",
                                kExactDofs, kExactSprings));
  c.get_option("--steps-per-period")
      ->description("Steps per forcing period of a fixed-grid method (pim, pim-switching)");
  c.add_option("--period", f.period, "Forcing periods per orbit: k of a period-k orbit")
      ->check(positive_number());
  c.add_option("--newton-tol", f.newton_tolerance,
               "Newton's tolerance: |φ_kT(y) − y|_∞ <= tol · max(1, |y|_∞)")
      ->check(positive_number());
  c.add_option("--max-iterations", f.max_iterations, "Newton iterations at most")
      ->check(positive_number());
  c.add_option("--transient", f.transient,
               "Guess: the state this many forcing periods after rest")
      ->check(non_negative_number());
  c.add_option("--guess-file", f.guess_file,
               "Guess: the state in this CSV file instead (header x1..xn,v1..vn, e.g. an\n"
               "orbit.csv; the last row is read, a leading column such as t is skipped)")
      ->check(CLI::ExistingFile);
  c.add_option("--multiplier-margin", f.multiplier_margin,
               "Krylov: Arnoldi reports every Floquet multiplier of modulus above 1 − this\n"
               "(its count doubles until the smallest is below); 0: those outside the circle.\n"
               "continue: 1e-5 by default, so that --band's band is watched at least this wide\n"
               "where they converged within half their basis (--curves: 0 unless another is given)")
      ->check(number_check({0.0, 1.0, false, true, "a number in [0, 1)"}, "[0,1)"));
  c.add_option("--multiplier-method", f.multiplier_method,
               "Krylov: automatic (Davidson preconditioned by the open structure where its damping\n"
               "is classical: a long chain's crowd of long waves in a few products each; Arnoldi\n"
               "elsewhere) or arnoldi (always thick-restarted Arnoldi), for comparison")
      ->check(CLI::IsMember({"automatic", "arnoldi"}));
  c.add_option("--gmres-recycle", f.gmres_recycle,
               "Krylov: vectors GMRES carries from one solve to the next of the same operator\n"
               "(GCRO-DR: the harmonic Ritz vectors of its smallest eigenvalues), below GMRES's 60;\n"
               "0: none")
      ->check(number_check({0.0, 60.0, false, true, "a whole number in [0, 60)"}, "[0,60)"));
  c.add_flag("--gmres-reform", f.gmres_reform,
             "Krylov: carry those vectors to a new operator too (the next Newton iterate, the\n"
             "next point) by forming their image again, --gmres-recycle products each time\n"
             "(GCRO-DR across a sequence of systems); off by default: on pwl's short,\n"
             "preconditioned solves it costs more products than it saves");
  c.add_flag("--no-precondition", f.no_precondition,
             "Krylov: GMRES without the open structure's preconditioner (as it runs where the\n"
             "damping is not classical), for comparison");
  c.add_option("--out", f.out, "Output folder");
  c.add_flag("--quiet", f.quiet, "No progress on standard error");
}

void read_method_given(const CLI::App& c, OrbitFlags& f) { f.method_given = c.count("--method") > 0; }

OrbitMethod orbit_method(const OrbitFlags& f, const GapStructure& structure, double period) {
  OrbitMethod m;
  CaseOptions run = f.run;
  m.chosen = !f.method_given;
  if (m.chosen) {
    // An accuracy request (--rtol) or a force degree asks for the switching PIM; otherwise the
    // exact solver where it applies.
    run.method = run.rtol == 0.0 && run.force_degree < 0 && structure.dofs() <= kExactDofs &&
                         structure.spring_count() <= kExactSprings
                     ? "exact"
                     : "pim-switching";
  }
  m.settings = run.method_settings(period);  // checks --dt against the period
  guard_step(structure, m.settings, period, f.run.force);
  m.steps_per_period = method_traits(m.settings.method).fixed_grid
                           ? static_cast<int>(std::lround(period / m.settings.step))
                           : run.steps_per_period;
  return m;
}

Vector read_state_file(const std::string& flag, const std::string& path, Index dofs) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{} {}: cannot read the file", flag, path));
  std::string line;
  if (!std::getline(in, line)) throw InputError(fmt::format("{} {}: the file is empty", flag, path));
  const std::vector<std::string> header = split(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t i = 0; i < header.size(); ++i) column.emplace(header[i], i);
  std::vector<std::size_t> wanted;
  for (const char kind : {'x', 'v'}) {
    for (Index i = 1; i <= dofs; ++i) {
      const std::string name = fmt::format("{}{}", kind, i);
      const auto found = column.find(name);
      if (found == column.end()) {
        throw InputError(fmt::format(
            "{} {}: the header has no column {}; a state of this structure needs x1..x{},v1..v{}",
            flag, path, name, dofs, dofs));
      }
      wanted.push_back(found->second);
    }
  }
  // No state components beyond the structure's (a state of another structure).
  int components = 0;
  for (const std::string& name : header) {
    if (name.size() >= 2 && (name[0] == 'x' || name[0] == 'v') &&
        name.find_first_not_of("0123456789", 1) == std::string::npos) {
      ++components;
    }
  }
  if (components != 2 * dofs) {
    throw InputError(fmt::format(
        "{} {}: the header names {} state components, a state of this structure has {} "
        "(x1..x{},v1..v{})",
        flag, path, components, 2 * dofs, dofs, dofs));
  }
  std::string last;
  int row = 1, last_row = 0;
  while (std::getline(in, line)) {
    ++row;
    if (line.find_first_not_of(" \r\t") == std::string::npos) continue;
    last = line;
    last_row = row;
  }
  if (last.empty()) throw InputError(fmt::format("{} {}: no row below the header", flag, path));
  const std::vector<std::string> fields = split(last);
  Vector y(2 * dofs);
  for (std::size_t k = 0; k < wanted.size(); ++k) {
    const std::size_t at = wanted[k];
    char* end = nullptr;
    const double value = at < fields.size() ? std::strtod(fields[at].c_str(), &end) : NAN;
    if (at >= fields.size() || fields[at].empty() || *end != '\0' || !std::isfinite(value)) {
      throw InputError(fmt::format("{} {}: line {}: column {} is not a finite number", flag, path,
                                   last_row, header[at]));
    }
    y(static_cast<Index>(k)) = value;
  }
  return y;
}

void note_when_no_tangent_map(const orbits::StroboscopicMap& map) {
  if (map.exact_tangent()) return;
  fmt::print("note: {} has no exact tangent map: every monodromy comes from forward differences "
             "of the flow (one integration per column), and the multipliers are accurate to about "
             "eight digits\n",
             method_label(map.settings()));
}

Vector starting_guess(const OrbitFlags& f, orbits::StroboscopicMap& map) {
  if (!f.guess_file.empty()) {
    if (!f.run.start.at_rest()) {
      throw InputError(fmt::format("--guess-file {}: --x0/--v0 ({}) start the transient that "
                                   "gives the guess instead; give one or the other",
                                   f.guess_file, f.run.start.text()));
    }
    return read_state_file("--guess-file", f.guess_file, map.dofs());
  }
  const Vector start = f.run.start.state(map.dofs());
  return f.transient > 0 ? map.advance(start, f.transient) : start;
}

void check_orbit_flags(const OrbitFlags& f) {
  // CLI11 checks the typed values; a scene's --set goes through it too. These are the ones the
  // library would refuse without naming the flag.
  if (f.period < 1) throw InputError(fmt::format("--period = {} must be >= 1", f.period));
  if (!(f.newton_tolerance > 0) || !std::isfinite(f.newton_tolerance)) {
    throw InputError(fmt::format("--newton-tol = {} must be positive", f.newton_tolerance));
  }
  if (f.max_iterations < 1) {
    throw InputError(fmt::format("--max-iterations = {} must be >= 1", f.max_iterations));
  }
  if (f.transient < 0) throw InputError(fmt::format("--transient = {} must be >= 0", f.transient));
  if (!(f.multiplier_margin >= 0 && f.multiplier_margin < 1)) {
    throw InputError(
        fmt::format("--multiplier-margin = {} must be in [0, 1)", f.multiplier_margin));
  }
  const orbits::ShootingOptions defaults;
  if (f.gmres_recycle < 0 || f.gmres_recycle >= defaults.gmres_dimension) {
    throw InputError(fmt::format("--gmres-recycle = {} must be in [0, {})", f.gmres_recycle,
                                 defaults.gmres_dimension));
  }
}

orbits::ShootingOptions shooting_options(const OrbitFlags& f) {
  orbits::ShootingOptions s;
  s.period = f.period;
  s.tolerance = f.newton_tolerance;
  s.max_iterations = f.max_iterations;
  s.arnoldi.margin = f.multiplier_margin;
  s.arnoldi.method = f.multiplier_method == "arnoldi" ? orbits::ArnoldiOptions::Method::arnoldi
                                                      : orbits::ArnoldiOptions::Method::automatic;
  s.gmres_recycled = f.gmres_recycle;
  s.gmres_reform = f.gmres_reform;
  s.precondition = !f.no_precondition;
  return s;
}

std::string eigen_solver_name(orbits::FloquetMultipliers::Method method) {
  switch (method) {
    case orbits::FloquetMultipliers::Method::dense: return "the dense monodromy";
    case orbits::FloquetMultipliers::Method::arnoldi: return "Arnoldi";
    case orbits::FloquetMultipliers::Method::davidson: return "Davidson";
  }
  return "?";
}

std::string multiplier_text(const std::complex<double>& mu) {
  return fmt::format("{:.6g}{:+.6g}i", mu.real(), mu.imag());
}

std::string orbit_method_label(const OrbitMethod& m) {
  const std::string label = method_label(m.settings);
  if (!method_traits(m.settings.method).fixed_grid) return label;
  return fmt::format("{}, η = T/{}", label, m.steps_per_period);
}

}  // namespace pwl::app
