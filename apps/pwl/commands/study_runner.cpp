#include "commands/study_runner.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <system_error>

#include "commands/cli_checks.hpp"
#include "commands/case_options.hpp"
#include "commands/step_guard_report.hpp"
#include "parallel/distributed.hpp"
#include "parallel/stop_signals.hpp"
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

int parse_component(const std::string& flag, const std::string& name, int masses) {
  if (name.size() >= 2 && (name[0] == 'x' || name[0] == 'v')) {
    char* end = nullptr;
    const long i = std::strtol(name.c_str() + 1, &end, 10);
    if (*end == '\0' && i >= 1 && i <= masses) {
      return static_cast<int>(i - 1) + (name[0] == 'v' ? masses : 0);
    }
  }
  throw InputError(fmt::format("{} {}: name a state component x1..x{} or v1..v{}", flag, name,
                               masses, masses));
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
  ladder.apply(s);
  s.starts = starts;
  for (const std::string& name : record) s.components.push_back(parse_component("--record", name, masses));
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
  add_ladder_flags(c, f.ladder);
  c.add_option("--starts", f.starts,
               "Coexisting attractors: start each point from this many initial states (its own and\n"
               "reproducible random ones about its motion) and count the distinct attractors they\n"
               "reach (column attractors); the point's other columns stay its own start's")
      ->check(number_in(1, 1000));
}

void add_run_flags(CLI::App& c, RunFlags& f) {
  c.add_option("--out", f.out, "Output folder");
  c.add_flag("--resume", f.resume, "Continue a killed run in --out: skip the finished points");
  c.add_flag("--quiet", f.quiet, "No progress bar");
  c.add_flag("--no-plot", f.no_plot, "Write the CSV files only");
  c.add_option("--threads", f.threads, "OpenMP threads (default: all cores)")
      ->check(non_negative_number());
  add_force_flag(c, f.force);
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

// The format of the journals (sweep_journal.hpp), recorded in config.txt after the study's
// description. A folder whose config.txt lacks it holds journals whose checksums leave the ids
// out, which this version does not read.
constexpr std::string_view kJournalFormat = "journal_format = 5\n";

std::vector<fs::path> journal_files(const fs::path& folder) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::exists(folder, ec)) return files;
  fs::directory_iterator entries(folder, ec);
  if (ec) throw Error(fmt::format("cannot list {}: {}", folder.string(), ec.message()));
  for (const auto& entry : entries) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("journal-", 0) == 0 && entry.path().extension() == ".log") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Writes `text` to `path` whole or not at all: into a file beside it, renamed over it once every
// byte is written, so that a full disk leaves the old file as it was (a truncated config.txt would
// make the folder refuse --resume). pwl::Error names the path and the system's reason.
void write_whole_file(const fs::path& path, std::string_view text) {
  const std::string target = path.string();
  const std::string temporary = target + ".new";
  const auto fail = [&](const char* what, int error) {
    ::unlink(temporary.c_str());
    return Error(fmt::format("cannot {} {}: {}", what, target, std::strerror(error)));
  };
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int error = errno;
    throw Error(fmt::format("cannot write {}: {}", target, std::strerror(error)));
  }
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t w = ::write(fd, text.data() + written, text.size() - written);
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) {
      const int error = errno;
      ::close(fd);
      throw fail("write", error);
    }
    written += static_cast<std::size_t>(w);
  }
  if (::close(fd) != 0) throw fail("write", errno);
  if (::rename(temporary.c_str(), target.c_str()) != 0) throw fail("replace", errno);
}

// Refuses a folder in which no file can be created (read-only, not ours), naming the system's
// reason, before any point is computed: a resumed run appends to journals that exist, which a
// read-only folder allows, and would fail only when it writes the result files. (Result files that
// exist and may be written would do without creating any; such a folder is refused all the same.)
void check_folder_takes_files(const fs::path& folder) {
  const std::string probe = (folder / fmt::format(".pwl-probe-{}", ::getpid())).string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int error = errno;
    throw Error(fmt::format("cannot create files in the output folder {}: {}", folder.string(),
                            std::strerror(error)));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

// A journal that could not be written: told apart from a point's own errors on the way out of
// run_grid, to say what is kept.
class JournalWriteError : public Error {
 public:
  using Error::Error;
};

void run_distributed(const Study& study, const RunFlags& flags, const Distributed& world) {
  // SIGINT and SIGTERM stop the points from here to the end of the grid (stop_signals.hpp); the
  // result files are written with the usual handlers back, as any other program writes files.
  std::optional<StopSignals> signals(std::in_place);
  // Before anything is written: a refused step costs nothing (every rank refuses alike).
  guard_study_steps(study.tasks, study.case_of, study.settings, flags.force, world.rank() == 0);
  const fs::path folder(flags.out);
  const fs::path config = folder / "config.txt";
  const std::string configuration = study.description + std::string(kJournalFormat);
  bool resuming = false;
  // Every rank checks the recorded configuration, so that all of them refuse a mismatch alike.
  std::error_code ec;
  if (flags.resume && fs::exists(config, ec)) {
    const std::string recorded = read_file(config);
    if (recorded == study.description) {
      throw InputError(fmt::format(
          "--resume into {}: its journals are of an older format, whose checksums leave the point "
          "ids out (config.txt has no \"{}\"); start over without --resume",
          flags.out, kJournalFormat.substr(0, kJournalFormat.size() - 1)));
    }
    // A journal of another format: its lines hold another set of indicators (format 5 added the
    // ladder's: minimal period, multiplier, record period, decided by, confirmation, observed
    // periods, halves, rotation p/q).
    const std::size_t format_at = recorded.rfind("journal_format = ");
    const std::string_view expected = kJournalFormat.substr(0, kJournalFormat.size() - 1);
    if (format_at != std::string::npos) {
      std::string format = recorded.substr(format_at);
      format = format.substr(0, format.find('\n'));
      if (format != expected) {
        throw InputError(fmt::format(
            "--resume into {}: its journals are of an older format (config.txt has \"{}\", this "
            "version writes \"{}\", with more indicators per point); start over without --resume",
            flags.out, format, expected));
      }
    }
    if (recorded != configuration) {
      throw InputError(fmt::format("--resume into {}: its configuration differs: {}", flags.out,
                                   first_difference(recorded, configuration)));
    }
    resuming = true;
  }
  world.barrier();
  if (world.rank() == 0) {
    fs::create_directories(folder, ec);
    if (ec) {
      throw Error(fmt::format("cannot create the output folder {}: {}", flags.out, ec.message()));
    }
    if (!fs::is_directory(folder, ec)) {
      throw Error(fmt::format("the output folder {} exists and is not a folder", flags.out));
    }
    check_folder_takes_files(folder);
    if (!resuming) {
      for (const fs::path& f : journal_files(folder)) {
        if (!fs::remove(f, ec) && ec) {
          throw Error(fmt::format("cannot remove the old journal {}: {}", f.string(), ec.message()));
        }
      }
      write_whole_file(config, configuration);
    }
  }
  world.barrier();
  auto journal = std::make_unique<analysis::SweepJournal>(
      (folder / fmt::format("journal-{}.log", world.rank())).string(), true);
  if (journal->cut_bytes() > 0) {
    fmt::print(stderr,
               "pwl: note: cut a torn last line of {} bytes off {}: a run was killed while writing "
               "it; its point is computed again\n",
               journal->cut_bytes(), journal->path());
  }
  world.barrier();
  std::set<long> ids;
  for (const analysis::GridTask& task : study.tasks) ids.insert(task.ids.begin(), task.ids.end());
  std::vector<std::string> paths;
  for (const fs::path& f : journal_files(folder)) paths.push_back(f.string());
  const auto stop_asked = [] { return StopSignals::received() != 0; };
  analysis::StudyJournals journals = analysis::read_study_journals(
      paths, [&](long id) { return ids.count(id) > 0; }, stop_asked);
  if (journals.stopped) {
    // Told to stop while the journals were read: nothing was computed or written yet.
    const int signal = StopSignals::received();
    const std::string message = fmt::format(
        "stopped by {} while reading the journals in {}, before computing anything; run the same "
        "command with --resume to go on",
        signal_name(signal), flags.out);
    if (world.size() > 1) {
      fmt::print(stderr, "pwl (rank {}): {}\n", world.rank(), message);
      world.abort(128 + signal);
    }
    throw Stopped(signal, message);
  }
  std::map<long, analysis::PointResult> done = std::move(journals.records);
  // Every rank reads every journal; one of them speaks.
  if (world.rank() == 0) {
    for (const std::string& w : journals.warnings) fmt::print(stderr, "pwl: warning: {}\n", w);
    for (const std::string& n : journals.notes) fmt::print(stderr, "pwl: note: {}\n", n);
    if (resuming) {
      fmt::print(stderr, "resuming in {}: {} of {} points are journaled, {} to compute\n",
                 flags.out, done.size(), ids.size(), ids.size() - done.size());
    }
  }

  std::vector<analysis::GridTask> mine;
  long todo = 0;
  for (std::size_t t = 0; t < study.tasks.size(); ++t) {
    if (static_cast<int>(t % static_cast<std::size_t>(world.size())) != world.rank()) continue;
    mine.push_back(study.tasks[t]);
    for (long id : study.tasks[t].ids) todo += done.count(id) == 0 ? 1 : 0;
  }
  std::string computed;
  long journaled_here = 0;
  analysis::GridEnd end = analysis::GridEnd::finished;
  const long total = static_cast<long>(ids.size());
  const auto journaled = [&] { return static_cast<long>(done.size()) + journaled_here; };
  try {
    ProgressBar bar(todo, "points", !flags.quiet && world.rank() == 0);
    analysis::GridRun run;
    run.threads = flags.threads;
    run.stop = stop_asked;
    end = analysis::run_grid(
        mine, study.case_of, study.initial_state, study.settings, done,
        [&](long id, const analysis::PointResult& r) {
          try {
            journal->append(id, r);
          } catch (const Error& e) {
            throw JournalWriteError(e.what());
          }
          ++journaled_here;
          if (world.size() > 1) computed += analysis::encode_record(id, r);
          bar.advance();
        },
        run);
  } catch (const JournalWriteError& e) {
    throw Error(fmt::format(
        "{}; the {} of {} points journaled before are kept in {}: once it can be written, run "
        "the same command with --resume to finish",
        e.what(), journaled(), total, flags.out));
  }
  const int signal = StopSignals::received();
  signals.reset();
  journal.reset();
  if (end == analysis::GridEnd::stopped || signal != 0) {
    const long left = total - journaled();
    const std::string message = fmt::format(
        "stopped by {}: {} of {} points are done and journaled in {}; run the same command with "
        "--resume to {}",
        signal_name(signal), journaled(), total, flags.out,
        left > 0 ? fmt::format("compute the other {}", left) : std::string("write the result files"));
    if (world.size() > 1) {
      // The other processes would wait for this one at the gathering below: end them all. What
      // they journaled in this run is theirs to count, so this one tells its own.
      fmt::print(stderr,
                 "pwl (rank {}): stopped by {}: this process journaled {} points in {} in this run "
                 "(of {} that were left); run the same command with --resume to finish\n",
                 world.rank(), signal_name(signal), journaled_here, flags.out,
                 total - static_cast<long>(done.size()));
      world.abort(128 + signal);
    }
    throw Stopped(signal, message);
  }
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
  // The result files may not fit where the journals did: say that nothing is lost.
  const std::string kept = fmt::format(
      "every point is journaled in {}: once it can be written, run the same command with "
      "--resume to write the result files",
      flags.out);
  try {
    study.finish(records);
  } catch (const InputError&) {
    throw;
  } catch (const Error& e) {
    throw Error(fmt::format("{}; {}", e.what(), kept));
  } catch (const std::system_error& e) {
    // A write refused on the way (fmt::print on a full disk), whose message names no file.
    throw Error(fmt::format("cannot write the result files in {}: {}; {}", flags.out,
                            e.code().message(), kept));
  }
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

std::map<long, analysis::PointResult> compute_study(const Study& study, int threads, bool force) {
  guard_study_steps(study.tasks, study.case_of, study.settings, force);
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
  const auto count = [](auto k, const char* one, const char* many) {
    return fmt::format("{} {}", k, k == 1 ? one : many);
  };
  if (model.explicit_structure()) {
    const GapStructure& g = model.structure().structure;
    // Underscores of the file name escaped: gnuplot's enhanced text reads '_' as a subscript.
    std::string label;
    for (char ch : model.structure().label) label += ch == '_' ? std::string("\\_") : std::string(1, ch);
    base = fmt::format("base case: {}, {}, {}, {}", label, count(g.dofs(), "mass", "masses"),
                       count(g.springs.size(), "gap spring", "gap springs"),
                       count(g.loads.size(), "load", "loads"));
  } else {
    const NondimensionalChain& chain = model.chain();
    base = fmt::format("base case: {}, α = {}, ζ = {}, Δ̃ = {}, θ = {}, Q = ({})",
                       count(chain.masses, "mass", "masses"), fmt::join(chain.alpha, ","), chain.zeta,
                       fmt::join(chain.gap, ","), chain.theta, fmt::join(chain.amplitude, ","));
  }
  std::string title = fmt::format("{}; {} + {} periods per point, {}", base,
                                  point.transient_periods, point.recorded_periods, integration);
  if (!point.section.is_default()) {
    title += fmt::format("; section {}", point.section.label(model.dofs()));
  }
  // The evidence ladder, briefly (analysis/README.md, "How a verdict is reached", says what each
  // step does): named as a whole when it is the default, else step by step.
  analysis::PointSettings ladder = point;
  ladder.use_ladder();
  if (ladder.describe() == point.describe()) {
    title += "; evidence ladder";
  } else if (!point.ladder_on()) {
    title += "; plain record (--quick)";
  } else {
    if (point.evidence_periods > 0) title += fmt::format("; evidence +{}", point.evidence_periods);
    if (point.refine_max_period > 0) {
      title += fmt::format(", refinement <= {}", point.refine_max_period);
    }
    if (point.check_periods) title += ", periods by Newton";
    if (point.confirm != analysis::Confirmation::none) {
      title += fmt::format(", checked ({})", analysis::confirmation_name(point.confirm));
    }
  }
  title.erase(std::remove(title.begin(), title.end(), '\''), title.end());
  return title;
}

}  // namespace pwl::app
