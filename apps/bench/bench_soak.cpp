#include "bench/bench_soak.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_clock.hpp"
#include "commands/cli_checks.hpp"
#include "commands/flag_relations.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/sweep_journal.hpp"

extern char** environ;

namespace pwl::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct SoakOptions {
  int points = 5000;  // per direction: 2 x points in all
  int transient = 900;
  int periods = 100;
  int threads = 2;
  int kills = 20;
  std::optional<std::uint64_t> seed;
  double min_delay = 0.05;  // s
  double max_delay = 0.0;   // s; 0: the uninterrupted run's time / kills
  std::string out = "soak";
  bool quiet = false;
};

std::vector<std::string> sweep_arguments(const SoakOptions& o, const fs::path& folder,
                                         bool resume) {
  std::vector<std::string> a = {"sweep",         "--figure",       "5",
                                "--parameter",   "theta",          "--range",
                                "0.5:3",         "--points",       std::to_string(o.points),
                                "--mode",        "continuation",   "--transient",
                                std::to_string(o.transient),       "--periods",
                                std::to_string(o.periods),         "--threads",
                                std::to_string(o.threads),         "--quiet",
                                "--no-plot",     "--out",          folder.string()};
  if (resume) a.emplace_back("--resume");
  return a;
}

// Starts `exe args` with stdout to /dev/null, stderr to `log`, and SIGINT and SIGTERM at their
// default (so that pwl installs its handlers even if this process was started with them ignored).
pid_t spawn(const std::string& exe, const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(exe.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  sigaddset(&defaults, SIGINT);
  sigaddset(&defaults, SIGTERM);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, exe.c_str(), &actions, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw Error(fmt::format("cannot start {}: {}", exe, std::strerror(rc)));
  return pid;
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw Error(fmt::format("waitpid({}): {}", pid, std::strerror(errno)));
  }
  return status;
}

// Sleeps `seconds` or until `pid` ends; its wait status when it ended.
std::optional<int> sleep_unless_done(pid_t pid, double seconds) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < until) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return std::nullopt;
}

std::string read_log(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// "exit 130", "killed by SIGKILL", ...
std::string describe_status(int status) {
  if (WIFEXITED(status)) return fmt::format("exit {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    const int s = WTERMSIG(status);
    return fmt::format("killed by {}", s == SIGKILL ? "SIGKILL"
                                       : s == SIGTERM ? "SIGTERM"
                                       : s == SIGINT  ? "SIGINT"
                                                      : fmt::format("signal {}", s));
  }
  return fmt::format("status {}", status);
}

// What the journals of a folder hold: each trusted record's checksum by id, damaged lines, torn
// bytes at the ends.
struct Journals {
  std::map<long, std::uint64_t> records;
  long damaged = 0;
  std::size_t torn = 0;
};

Journals scan(const fs::path& folder) {
  Journals j;
  if (!fs::exists(folder)) return j;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("journal-", 0) != 0 || entry.path().extension() != ".log") continue;
    const analysis::JournalFile file = analysis::read_journal_file(entry.path().string());
    for (const analysis::JournalRecord& r : file.records) j.records.emplace(r.id, r.checksum);
    j.damaged += static_cast<long>(file.damaged.size());
    j.torn += file.torn_bytes;
  }
  return j;
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

struct Attempt {
  int index = 0;
  std::string signal;  // "SIGKILL", "SIGTERM", "SIGINT"; empty for the last run, not killed
  double delay = 0.0;  // s after the start
  std::string outcome;
  double stop_ms = 0.0;  // from the signal to the end of the process
  long before = 0, after = 0;  // records in the journals
  std::size_t torn = 0;        // bytes of a torn last line left
  long damaged = 0;
  bool clean = false;  // the outcome expected for the signal and, for SIGINT/SIGTERM, whole lines
};

void run(const SoakOptions& o) {
  check_relation("bench soak", "--min-delay", o.min_delay, "--max-delay", o.max_delay);
  const std::string self = fs::read_symlink("/proc/self/exe").string();
  const fs::path out(o.out), whole = out / "whole", killed = out / "killed", logs = out / "logs";
  fs::remove_all(whole);
  fs::remove_all(killed);
  fs::create_directories(logs);
  const long total = 2L * o.points;
  const std::uint64_t seed = o.seed ? *o.seed : std::random_device{}();
  std::mt19937_64 random(seed);
  const auto say = [&](const std::string& text) {
    if (!o.quiet) fmt::print(stderr, "{}\n", text);
  };
  fmt::print("pwl bench soak: seed {} (--seed {} repeats the signals and delays)\n", seed, seed);

  say(fmt::format("uninterrupted run: {} points of {} + {} periods on {} threads ...", total,
                  o.transient, o.periods, o.threads));
  auto start = Clock::now();
  const int whole_status = wait_for(spawn(self, sweep_arguments(o, whole, false), logs / "whole.err"));
  const double whole_seconds = seconds_since(start);
  if (!WIFEXITED(whole_status) || WEXITSTATUS(whole_status) != 0) {
    throw Error(fmt::format("the uninterrupted run failed ({}): {}", describe_status(whole_status),
                            read_log(logs / "whole.err")));
  }
  // On average the kills leave about half of the sweep to the last run, so that every kill finds
  // the sweep still running.
  const double max_delay = o.max_delay > 0.0 ? o.max_delay : whole_seconds / o.kills;
  say(fmt::format("{:.1f} s; now {} kills after {:.2f} to {:.2f} s each ...", whole_seconds,
                  o.kills, o.min_delay, max_delay));

  const int signals[] = {SIGKILL, SIGTERM, SIGINT};
  const char* names[] = {"SIGKILL", "SIGTERM", "SIGINT"};
  std::uniform_int_distribution<int> which(0, 2);
  std::uniform_real_distribution<double> delay_of(o.min_delay, std::max(o.min_delay, max_delay));
  std::vector<Attempt> attempts;
  start = Clock::now();
  bool finished = false;
  for (int i = 1; i <= o.kills && !finished; ++i) {
    Attempt a;
    a.index = i;
    const int pick = which(random);
    a.delay = delay_of(random);
    a.before = static_cast<long>(scan(killed).records.size());
    const fs::path log = logs / fmt::format("attempt-{}.err", i);
    const pid_t pid = spawn(self, sweep_arguments(o, killed, i > 1), log);
    std::optional<int> status = sleep_unless_done(pid, a.delay);
    if (status) {
      a.signal = "(none)";
      finished = true;  // the sweep ended before its kill
    } else {
      a.signal = names[pick];
      const auto sent = Clock::now();
      ::kill(pid, signals[pick]);
      status = wait_for(pid);
      a.stop_ms = 1e3 * seconds_since(sent);
    }
    a.outcome = describe_status(*status);
    const Journals j = scan(killed);
    a.after = static_cast<long>(j.records.size());
    a.torn = j.torn;
    a.damaged = j.damaged;
    const int s = finished ? 0 : signals[pick];
    const bool code_ok =
        finished ? WIFEXITED(*status) && WEXITSTATUS(*status) == 0
        : s == SIGKILL
            ? WIFSIGNALED(*status) && WTERMSIG(*status) == SIGKILL
            // Handled: 128 + the signal. Killed by it: it came before the handlers were set or
            // after they were put back, while the result files were being written.
            : (WIFEXITED(*status) && WEXITSTATUS(*status) == 128 + s) ||
                  (WIFSIGNALED(*status) && WTERMSIG(*status) == s);
    a.clean = code_ok && a.damaged == 0 && (s == SIGKILL || a.torn == 0);
    say(fmt::format("  {:2}: {:7} after {:5.2f} s: {:16} {:6.1f} ms, {} -> {} points{}{}", i,
                    a.signal, a.delay, a.outcome, a.stop_ms, a.before, a.after,
                    a.torn ? fmt::format(", torn line of {} bytes", a.torn) : "",
                    a.clean ? "" : "  NOT CLEAN"));
    attempts.push_back(a);
  }
  // The last run, to the end.
  Attempt last;
  last.index = static_cast<int>(attempts.size()) + 1;
  last.before = static_cast<long>(scan(killed).records.size());
  const fs::path last_log = logs / "last.err";
  const auto last_start = Clock::now();
  const int last_status = wait_for(spawn(self, sweep_arguments(o, killed, true), last_log));
  last.delay = seconds_since(last_start);
  last.outcome = describe_status(last_status);
  const Journals final_journals = scan(killed);
  last.after = static_cast<long>(final_journals.records.size());
  last.torn = final_journals.torn;
  last.damaged = final_journals.damaged;
  last.clean = WIFEXITED(last_status) && WEXITSTATUS(last_status) == 0 && last.torn == 0 &&
               last.damaged == 0;
  const double killed_seconds = seconds_since(start);
  say(fmt::format("  last run: {} after {:.1f} s, {} -> {} points", last.outcome, last.delay,
                  last.before, last.after));

  // Every file but the journals byte for byte; the journals record for record.
  std::vector<std::string> compared, differing;
  for (const auto& entry : fs::directory_iterator(whole)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("journal-", 0) == 0) continue;
    compared.push_back(name);
    if (!fs::exists(killed / name) || file_bytes(entry.path()) != file_bytes(killed / name)) {
      differing.push_back(name);
    }
  }
  for (const auto& entry : fs::directory_iterator(killed)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("journal-", 0) != 0 && !fs::exists(whole / name)) differing.push_back(name);
  }
  std::sort(compared.begin(), compared.end());
  const Journals whole_journals = scan(whole);
  const bool same_records = whole_journals.records == final_journals.records;
  const bool identical = differing.empty() && same_records && !compared.empty();

  // Tables.
  long torn_lines = 0, clean_stops = 0, handled = 0;
  std::map<std::string, int> by_signal;
  double longest_stop = 0.0;
  for (const Attempt& a : attempts) {
    if (a.signal == "(none)") continue;
    ++by_signal[a.signal];
    if (a.torn > 0) ++torn_lines;
    if (a.signal != "SIGKILL") {
      ++handled;
      clean_stops += a.clean ? 1 : 0;
      longest_stop = std::max(longest_stop, a.stop_ms);
    }
  }
  const int kills = by_signal["SIGKILL"] + by_signal["SIGTERM"] + by_signal["SIGINT"];
  std::string table = fmt::format(
      "pwl bench soak: {} points (θ continuation of figure 5, up and down, {} + {} periods each, "
      "{} threads), seed {}\n\n",
      total, o.transient, o.periods, o.threads, seed);
  table += "| # | signal | after (s) | outcome | stop (ms) | points journaled before -> after | "
           "torn line cut next (bytes) | clean |\n|---|---|---|---|---|---|---|---|\n";
  for (const Attempt& a : attempts) {
    table += fmt::format("| {} | {} | {:.2f} | {} | {:.1f} | {} -> {} | {} | {} |\n", a.index,
                         a.signal, a.delay, a.outcome, a.stop_ms, a.before, a.after, a.torn,
                         a.clean ? "yes" : "NO");
  }
  table += fmt::format("| {} | (last run) | {:.2f} | {} | | {} -> {} | {} | {} |\n\n", last.index,
                       last.delay, last.outcome, last.before, last.after, last.torn,
                       last.clean ? "yes" : "NO");
  table += "| quantity | value |\n|---|---|\n";
  table += fmt::format("| kills | {} (SIGKILL {}, SIGTERM {}, SIGINT {}) |\n", kills,
                       by_signal["SIGKILL"], by_signal["SIGTERM"], by_signal["SIGINT"]);
  table += fmt::format("| clean stops by SIGTERM/SIGINT (exit 143/130, whole valid lines) | {} of "
                       "{} |\n",
                       clean_stops, handled);
  table += fmt::format("| longest stop after SIGTERM/SIGINT (ms) | {:.1f} |\n", longest_stop);
  table += fmt::format("| journal lines torn by SIGKILL (points computed again) | {} |\n",
                       torn_lines);
  table += fmt::format("| uninterrupted run (s) | {:.1f} |\n", whole_seconds);
  table += fmt::format("| killed and resumed runs, start to end (s) | {:.1f} |\n", killed_seconds);
  table += fmt::format("| files identical to the uninterrupted run's | {} ({}; journals: {} |\n",
                       identical ? "yes" : "NO",
                       differing.empty() ? fmt::format("{} byte for byte", fmt::join(compared, ", "))
                                         : fmt::format("differ: {}", fmt::join(differing, ", ")),
                       same_records ? fmt::format("the same {} records)", final_journals.records.size())
                                    : std::string("other records)"));
  if (finished) {
    table += fmt::format("\nThe sweep ended before kill {}: give a smaller --max-delay for {} "
                         "kills.\n",
                         attempts.size(), o.kills);
  }
  fmt::print("\n{}", table);

  const fs::path csv = out / "bench_soak.csv";
  std::FILE* f = std::fopen(csv.c_str(), "w");
  if (f == nullptr) throw Error(fmt::format("cannot write {}: {}", csv.string(), std::strerror(errno)));
  fmt::print(f, "attempt,signal,delay_s,outcome,stop_ms,journaled_before,journaled_after,"
                "torn_bytes,damaged_lines,clean\n");
  for (const Attempt& a : attempts) {
    fmt::print(f, "{},{},{:.4f},{},{:.2f},{},{},{},{},{}\n", a.index, a.signal, a.delay, a.outcome,
               a.stop_ms, a.before, a.after, a.torn, a.damaged, a.clean ? 1 : 0);
  }
  fmt::print(f, "{},,{:.4f},{},,{},{},{},{},{}\n", last.index, last.delay, last.outcome,
             last.before, last.after, last.torn, last.damaged, last.clean ? 1 : 0);
  if (std::fclose(f) != 0) throw Error(fmt::format("cannot write {}", csv.string()));
  if (std::FILE* md = std::fopen((out / "bench_soak.md").c_str(), "w")) {
    fmt::print(md, "{}", table);
    std::fclose(md);
  }
  fmt::print("\nwrote {0}/bench_soak.csv and {0}/bench_soak.md (the runs' stderr in {0}/logs)\n",
             o.out);
  if (!identical || clean_stops != handled || !last.clean) {
    throw Error("the soak failed: see the tables above");
  }
}

}  // namespace

void add_soak_bench(CLI::App& bench) {
  auto o = std::make_shared<SoakOptions>();
  auto seed = std::make_shared<std::uint64_t>(0);
  CLI::App* c = bench.add_subcommand(
      "soak",
      "A continuation sweep of 10^4 points killed at random moments (SIGKILL, SIGTERM, SIGINT)\n"
      "and resumed, again and again, must end with the uninterrupted run's files byte for byte\n"
      "Example: pwl bench soak --kills 20 --out out/soak");
  c->add_option("--points", o->points, "Parameter values; the sweep runs up and down: 2x points")
      ->check(positive_number());
  c->add_option("--transient", o->transient, "Transient periods per point")
      ->check(non_negative_number());
  c->add_option("--periods", o->periods, "Recorded periods per point")->check(positive_number());
  c->add_option("--threads", o->threads, "OpenMP threads of each run")->check(positive_number());
  c->add_option("--kills", o->kills, "Runs killed before the last one")->check(positive_number());
  c->add_option("--seed", *seed, "Seed of the signals and delays (default: a random one)")
      ->check(non_negative_number());
  c->add_option("--min-delay", o->min_delay, "Shortest time from a run's start to its kill (s)")
      ->check(positive_number());
  c->add_option("--max-delay", o->max_delay,
                "Longest time from a run's start to its kill (s; default: the uninterrupted "
                "run's time / kills)")
      ->check(positive_number());
  c->add_option("--out", o->out, "Folder for the runs, bench_soak.csv and bench_soak.md");
  c->add_flag("--quiet", o->quiet, "Print only the tables");
  c->callback([o, seed, c] {
    if (c->count("--seed") > 0) o->seed = *seed;
    run(*o);
  });
}

}  // namespace pwl::app
