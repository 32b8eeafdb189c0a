#include "commands/study_runner.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "commands/cli_checks.hpp"
#include "commands/case_options.hpp"
#include "parallel/distributed.hpp"
#include "output/progress_bar.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/parameter_sweep.hpp"
#include "pwl/study/sweep_journal.hpp"
#include "pwl/errors.hpp"

namespace pwl::app {

namespace fs = std::filesystem;

analysis::PointModel ModelFlags::model() const {
  // The same model flags as simulate and analyze, built and checked the same way.
  CaseOptions c;
  c.figure = figure;
  c.masses = masses;
  c.alpha = alpha;
  c.zeta = zeta;
  c.gap = gap;
  c.theta = theta;
  c.loads = loads;
  c.structure_scene = structure_scene;
  return c.model();
}

void add_model_flags(CLI::App& c, ModelFlags& f) {
  add_chain_options(c, f.figure, f.masses, f.alpha, f.zeta, f.gap, f.theta, f.loads);
  c.add_option("--structure-scene", f.structure_scene,
               "Vary the explicit structure (M, C, K, gap springs, loads) of this scene file's\n"
               "[structure] table instead of the chain; its parameters are spring<j>.stiffness,\n"
               "spring<j>.gap, load<j>.amplitude, load<j>.frequency and damping (a scale of C)")
      ->check(CLI::ExistingFile);
}

analysis::SweepParameter parse_model_parameter(const analysis::PointModel& model,
                                               const std::string& flag, const std::string& name) {
  try {
    return model.parameter(name);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{} {}: {}", flag, name, e.what()));
  }
}

analysis::PointSettings PointFlags::settings(int masses) const {
  analysis::PointSettings s;
  s.transient_periods = transient;
  s.recorded_periods = periods;
  s.steps_per_period = steps_per_period;
  s.lyapunov = !no_lyapunov;
  s.method.method = parse_method(method);
  s.lyapunov_estimate = lyapunov.empty() ? analysis::default_lyapunov_estimate(s.method.method)
                                         : analysis::parse_lyapunov_estimate(lyapunov);
  s.method.tolerance = tolerance;
  s.method.locate_kinks = locate_kinks;
  s.method.lcp = parse_lcp_algorithm(lcp_solver);
  for (const std::string& name : record) {
    int component = -1;
    if (name.size() >= 2 && (name[0] == 'x' || name[0] == 'v')) {
      char* end = nullptr;
      const long i = std::strtol(name.c_str() + 1, &end, 10);
      if (*end == '\0' && i >= 1 && i <= masses) {
        component = static_cast<int>(i - 1) + (name[0] == 'v' ? masses : 0);
      }
    }
    if (component < 0) {
      throw InputError(fmt::format("--record {}: name a state component x1..x{} or v1..v{}", name,
                                   masses, masses));
    }
    s.components.push_back(component);
  }
  if (record.empty()) s.components = {masses - 1, 2 * masses - 1};
  std::string why;
  if (!s.is_valid(masses, &why)) throw InputError(why);
  return s;
}

void add_point_flags(CLI::App& c, PointFlags& f, bool with_record) {
  c.add_option("--transient", f.transient, "Forcing periods integrated and discarded per point");
  c.add_option("--periods", f.periods, "Forcing periods recorded and classified per point");
  c.add_option("--steps-per-period", f.steps_per_period, "PIM steps per forcing period");
  if (with_record) {
    c.add_option("--record", f.record,
                 "State components kept at each Poincaré point, comma separated (default: x and v "
                 "of the last mass)")
        ->delimiter(',');
  }
  c.add_flag("--no-lyapunov", f.no_lyapunov, "Skip λ1 (then only the period search and K decide)");
  c.add_option("--lyapunov", f.lyapunov,
               "How λ1 is estimated: tangent-vector, tangent-frame (both need a method with an\n"
               "exact tangent map; without one λ1 is left out) or two-trajectories (any method).\n"
               "Default: tangent-vector with a tangent map, else two-trajectories (as analyze)")
      ->check(CLI::IsMember({"tangent-vector", "tangent-frame", "two-trajectories"}));
  c.add_option("--method", f.method, method_help())->check(CLI::IsMember(method_names()));
  c.add_option("--tol", f.tolerance, "Relative and absolute tolerance of dopri5/rkf78")
      ->check(positive_number());
  c.add_flag("--locate-kinks", f.locate_kinks,
             "dopri5/rkf78: end a step exactly at every spring opening or closing");
  c.add_option("--lcp", f.lcp_solver, "PIM's LCP solver: block-pivoting or lemke")
      ->check(CLI::IsMember({"block-pivoting", "lemke"}));
}

void add_run_flags(CLI::App& c, RunFlags& f) {
  c.add_option("--out", f.out, "Output folder");
  c.add_flag("--resume", f.resume, "Continue a killed run in --out: skip the finished points");
  c.add_flag("--quiet", f.quiet, "No progress bar");
  c.add_flag("--no-plot", f.no_plot, "Write the CSV files only");
  c.add_option("--threads", f.threads, "OpenMP threads (default: all cores)")
      ->check(non_negative_number());
}

void parse_range(const std::string& flag, const std::string& text, double* from, double* to) {
  const std::size_t colon = text.find(':');
  bool ok = colon != std::string::npos;
  if (ok) {
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    char* end_a = nullptr;
    char* end_b = nullptr;
    *from = std::strtod(a.c_str(), &end_a);
    *to = std::strtod(b.c_str(), &end_b);
    ok = !a.empty() && !b.empty() && *end_a == '\0' && *end_b == '\0';
  }
  if (!ok) throw InputError(fmt::format("{} = \"{}\": give the range as FROM:TO", flag, text));
}

namespace {

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The first line where the recorded configuration and this run's differ.
std::string first_difference(const std::string& recorded, const std::string& now) {
  std::istringstream a(recorded), b(now);
  std::string la, lb;
  while (true) {
    const bool ha = static_cast<bool>(std::getline(a, la));
    const bool hb = static_cast<bool>(std::getline(b, lb));
    if (!ha && !hb) return "";
    if (!ha) la = "(nothing)";
    if (!hb) lb = "(nothing)";
    if (la != lb) return fmt::format("the folder records \"{}\", this run has \"{}\"", la, lb);
  }
}

std::vector<fs::path> journal_files(const fs::path& folder) {
  std::vector<fs::path> files;
  if (!fs::exists(folder)) return files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("journal-", 0) == 0 && entry.path().extension() == ".log") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

void run_distributed(const Study& study, const RunFlags& flags, const Distributed& world) {
  const fs::path folder(flags.out);
  const fs::path config = folder / "config.txt";
  // Every rank checks the recorded configuration, so that all of them refuse a mismatch alike.
  if (flags.resume && fs::exists(config)) {
    const std::string recorded = read_file(config);
    if (recorded != study.description) {
      throw InputError(fmt::format("--resume into {}: its configuration differs: {}", flags.out,
                                   first_difference(recorded, study.description)));
    }
  }
  world.barrier();
  if (world.rank() == 0) {
    fs::create_directories(folder);
    if (!flags.resume || !fs::exists(config)) {
      for (const fs::path& f : journal_files(folder)) fs::remove(f);
    }
    std::ofstream(config, std::ios::binary | std::ios::trunc) << study.description;
  }
  world.barrier();
  auto journal = std::make_unique<analysis::SweepJournal>(
      (folder / fmt::format("journal-{}.log", world.rank())).string(), true);
  world.barrier();
  std::map<long, analysis::PointResult> done;
  for (const fs::path& f : journal_files(folder)) done.merge(analysis::read_journal(f.string()));

  std::vector<analysis::GridTask> mine;
  long todo = 0;
  for (std::size_t t = 0; t < study.tasks.size(); ++t) {
    if (static_cast<int>(t % static_cast<std::size_t>(world.size())) != world.rank()) continue;
    mine.push_back(study.tasks[t]);
    for (long id : study.tasks[t].ids) todo += done.count(id) == 0 ? 1 : 0;
  }
  std::string computed;
  {
    ProgressBar bar(todo, "points", !flags.quiet && world.rank() == 0);
    analysis::run_grid(mine, study.case_of, study.initial_state, study.settings, done,
                       [&](long id, const analysis::PointResult& r) {
                         journal->append(id, r);
                         if (world.size() > 1) computed += analysis::encode_record(id, r);
                         bar.advance();
                       },
                       {flags.threads});
  }
  journal.reset();
  const std::vector<std::string> gathered = world.gather(computed);
  if (world.rank() != 0) return;
  // Rank 0's journal holds its own points; the others' come from the gathered records, so that
  // the folder need not be shared for a run that is not resumed.
  done.clear();
  for (const fs::path& f : journal_files(folder)) done.merge(analysis::read_journal(f.string()));
  for (const std::string& lines : gathered) {
    std::istringstream in(lines);
    std::string line;
    while (std::getline(in, line)) {
      if (auto r = analysis::decode_record(line)) done.emplace(r->first, std::move(r->second));
    }
  }
  std::map<long, analysis::PointResult> records;
  for (const analysis::GridTask& task : study.tasks) {
    for (long id : task.ids) {
      auto found = done.find(id);
      if (found == done.end()) {
        throw Error(fmt::format("point {} is missing from the journals in {}", id, flags.out));
      }
      records.emplace(id, found->second);
    }
  }
  study.finish(records);
}

}  // namespace

void run_study(const Study& study, const RunFlags& flags) {
  Distributed world;
  if (world.size() == 1) {
    run_distributed(study, flags, world);
    return;
  }
  // With several processes an error on one must end all of them, or the others wait forever.
  try {
    run_distributed(study, flags, world);
  } catch (const InputError& e) {
    fmt::print(stderr, "pwl (rank {}): bad input: {}\n", world.rank(), e.what());
    world.abort(2);
  } catch (const std::exception& e) {
    fmt::print(stderr, "pwl (rank {}): {}\n", world.rank(), e.what());
    world.abort(1);
  }
}

std::map<long, analysis::PointResult> compute_study(const Study& study, int threads) {
  std::map<long, analysis::PointResult> records;
  analysis::run_grid(study.tasks, study.case_of, study.initial_state, study.settings, {},
                     [&](long id, const analysis::PointResult& r) { records.emplace(id, r); },
                     {threads});
  return records;
}

std::string parameter_label(const analysis::SweepParameter& parameter) {
  using Kind = analysis::SweepParameter::Kind;
  const int j = parameter.index() + 1;
  switch (parameter.kind()) {
    case Kind::theta:
      return "θ = ω/ω_0";
    case Kind::alpha:
      return "α = k_2/k_1";
    case Kind::zeta:
      return "ζ (damping ratio)";
    case Kind::gap:
      return "Δ̃ (nondimensional gap)";
    case Kind::amplitude:
      return "load scale (times Q)";
    case Kind::spring_stiffness:
      return fmt::format("stiffness k of gap spring {}", j);
    case Kind::spring_gap:
      return fmt::format("gap Δ of gap spring {}", j);
    case Kind::load_amplitude:
      return fmt::format("amplitude of load {}", j);
    case Kind::load_frequency:
      return fmt::format("circular frequency ω of load {}", j);
    case Kind::damping:
      return "damping scale (times C)";
  }
  return analysis::parameter_name(parameter);
}

std::string study_title(const analysis::PointModel& model, const analysis::PointSettings& point) {
  const MethodTraits& method = method_traits(point.method.method);
  // The PIM is the default and goes unnamed; any other method is named by its label.
  const std::string named =
      point.method.method == Method::pim ? std::string() : method_label(point.method) + ", ";
  const std::string integration =
      method.fixed_grid ? fmt::format("{}η = T/{}", named, point.steps_per_period)
                        : method_label(point.method);
  std::string base;
  if (model.explicit_structure()) {
    const GapStructure& g = model.structure().structure;
    // Underscores of the file name escaped: gnuplot's enhanced text reads '_' as a subscript.
    std::string label;
    for (char ch : model.structure().label) label += ch == '_' ? std::string("\\_") : std::string(1, ch);
    const auto count = [](auto k, const char* one, const char* many) {
      return fmt::format("{} {}", k, k == 1 ? one : many);
    };
    base = fmt::format("base case: {}, {}, {}, {}", label, count(g.dofs(), "mass", "masses"),
                       count(g.springs.size(), "gap spring", "gap springs"),
                       count(g.loads.size(), "load", "loads"));
  } else {
    const NondimensionalChain& chain = model.chain();
    base = fmt::format("base case: {} masses, α = {}, ζ = {}, Δ̃ = {}, θ = {}, Q = ({})",
                       chain.masses, fmt::join(chain.alpha, ","), chain.zeta,
                       fmt::join(chain.gap, ","), chain.theta, fmt::join(chain.amplitude, ","));
  }
  std::string title = fmt::format("{}; {} + {} periods per point, {}", base,
                                  point.transient_periods, point.recorded_periods, integration);
  if (!point.section.is_default()) {
    title += fmt::format("; section {}", point.section.label(model.dofs()));
  }
  title.erase(std::remove(title.begin(), title.end(), '\''), title.end());
  return title;
}

}  // namespace pwl::app
