// Bad values everywhere, from one table: every numeric flag of every job refuses NaN, +Inf, -Inf
// and a value outside its sign or range with exit code 2 and a message that names the flag and
// the value, typed on the command line and written as a key of a scene file alike.
//
// The table is tests/cli/bad_values.csv: job(s), flag, bad value, a piece of the expected message.
// The program's command line is built here the way apps/pwl/main.cpp builds it (and checked against
// the program's own --help, so that a job registered there and not here fails), every job is
// enumerated, nested ones (bench chain, ...) too, and every option of a numeric type (CLI11's type
// name INT, UINT or FLOAT, lists included) must have rows for nan, inf and -inf, and every FROM:TO
// range (a text option named *range) a row with a non-finite end: a new numeric flag without them
// fails the coverage test, which names it. An option of a type this test does not know fails too,
// so that a new kind of value is classified rather than skipped. The sign and range rows are
// chosen per flag (a gap or a load has none).
//
// Relations between two flags (a smallest step at most the largest, a second parameter other than
// the first: apps/pwl/commands/flag_relations.hpp) are rows of the same table, whose flag field
// names both flags and whose value field gives both values, separated by a space
// ("--min-step --max-step" and "0.5 0.1"); every relation of the program's table must have one.
//
// Each row then runs the real program (PWL_EXECUTABLE) in a folder of its own with a time limit,
// several at once: a value that slips through is a run that exits 0, fails for another reason, or
// is killed at the limit, and the row fails with what the program said.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "commands/cli_checks.hpp"
#include "commands/commands.hpp"
#include "commands/flag_relations.hpp"
#include "scene/scene_command_line.hpp"

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------
// The program's command line, as main.cpp builds it.

std::unique_ptr<CLI::App> program() {
  auto app = std::make_unique<CLI::App>("pwl");
  app->require_subcommand(1);
  app->option_defaults()->always_capture_default();
  pwl::app::add_simulate_command(*app);
  pwl::app::add_analyze_command(*app);
  pwl::app::add_reproduce_command(*app);
  pwl::app::add_bench_command(*app);
  pwl::app::add_sweep_command(*app);
  pwl::app::add_map_command(*app);
  pwl::app::add_basin_command(*app);
  pwl::app::add_orbit_command(*app);
  pwl::app::add_continue_command(*app);
  pwl::app::add_run_command(*app);
  pwl::app::add_scene_options(*app);
  return app;
}

// Every job: a subcommand without subcommands of its own, by its words ("bench chain").
void collect_jobs(CLI::App& at, const std::string& prefix,
                  std::vector<std::pair<std::string, CLI::App*>>& jobs) {
  for (CLI::App* sub : at.get_subcommands({})) {
    const std::string name = prefix.empty() ? sub->get_name() : prefix + " " + sub->get_name();
    if (sub->get_subcommands({}).empty()) {
      jobs.emplace_back(name, sub);
    } else {
      collect_jobs(*sub, name, jobs);
    }
  }
}

// The option's long name ("--tol"), also for a hidden one (CLI11's get_name gives "" for those).
std::string flag_name(const CLI::Option& option) {
  if (!option.get_lnames().empty()) return "--" + option.get_lnames().front();
  if (!option.get_snames().empty()) return "-" + option.get_snames().front();
  return option.get_name(true, false);
}

enum class Kind { numeric, range, other };

// Whether an option takes numbers (INT, UINT, FLOAT, one or a list), a FROM:TO range (text named
// *range), or something else; throws for a type name this test does not know.
Kind kind_of(const CLI::Option& option, const std::string& job) {
  const std::string name = flag_name(option);
  if (option.get_expected_max() == 0) return Kind::other;  // a switch
  std::string type = option.get_type_name();
  type = type.substr(0, type.find(':'));  // "FLOAT:POSITIVE": the validators follow the type
  if (type == "INT" || type == "UINT" || type == "FLOAT" || type == "NUMBER") return Kind::numeric;
  if (type == "TEXT") {
    return name.size() >= 5 && name.compare(name.size() - 5, 5, "range") == 0 ? Kind::range
                                                                              : Kind::other;
  }
  throw std::runtime_error("pwl " + job + " " + name + ": type name \"" + option.get_type_name() +
                           "\" is unknown to tests/cli/bad_values_test.cpp; say there whether it "
                           "takes numbers");
}

// Words of a job ("bench chain" -> bench, chain).
std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// ---------------------------------------------------------------------------------------------
// The table.

struct Row {
  std::string job;
  std::string flag;
  std::string value;
  std::string message;
  int line = 0;  // in bad_values.csv

  // One flag and its value, or the two of a relation (space-separated in both fields).
  std::vector<std::string> flags() const { return words(flag); }
  std::vector<std::string> values() const {
    return flags().size() == 1 ? std::vector<std::string>{value} : words(value);
  }
};

// One CSV line: fields separated by commas, a field in double quotes may hold commas and "" for a
// quote.
std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

// The rows, one per job: a row's job field may name several jobs separated by ';' (a flag that
// several jobs share through one registration, with the same check and message). Blank lines and
// lines starting with '#' are comments; the first other line is the header.
std::vector<Row> read_table(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::vector<Row> rows;
  std::string line;
  bool header = true;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> f = csv_fields(line);
    if (f.size() != 4) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected 4 fields, got " +
                               std::to_string(f.size()));
    }
    if (header) {
      if (f[0] != "job" || f[1] != "flag" || f[2] != "value" || f[3] != "message") {
        throw std::runtime_error(path + ": the header must be job,flag,value,message");
      }
      header = false;
      continue;
    }
    std::size_t from = 0;
    while (from <= f[0].size()) {
      const std::size_t end = std::min(f[0].find(';', from), f[0].size());
      rows.push_back({f[0].substr(from, end - from), f[1], f[2], f[3], number});
      from = end + 1;
    }
  }
  return rows;
}

const std::vector<Row>& table() {
  static const std::vector<Row> rows = read_table(PWL_BAD_VALUES_TABLE);
  return rows;
}

// The rows the tests below run. In the release build, every row. Under AddressSanitizer a run of
// the program costs about 0.6 s of CPU before it reads a flag (shadow memory, the leak check at
// exit) against 0.04 s, so the 600-odd runs of the whole table would take 6 minutes per test:
// there each (job, flag) runs one of its rows, cycling through the kinds the table gives it (NaN,
// ±Inf, the sign or range) from one flag to the next, so that every flag's refusal path and every
// kind of bad value runs under the sanitizers while the release build checks every message.
std::vector<Row> rows_to_run() {
#if defined(__SANITIZE_ADDRESS__)
  std::vector<Row> out;
  std::map<std::pair<std::string, std::string>, std::vector<const Row*>> groups;
  std::vector<std::pair<std::string, std::string>> order;
  for (const Row& row : table()) {
    auto& group = groups[{row.job, row.flag}];
    if (group.empty()) order.emplace_back(row.job, row.flag);
    group.push_back(&row);
  }
  for (std::size_t g = 0; g < order.size(); ++g) {
    const std::vector<const Row*>& group = groups[order[g]];
    out.push_back(*group[g % group.size()]);
  }
  return out;
#else
  return table();
#endif
}

// What each job needs besides the bad value to reach its checks, and what keeps a run that slips
// through out of the source tree and short: switches and folders only, never a number, so that a
// row's flag is not given twice (a row for a flag listed here replaces it). `D` is the row's own
// folder. A job missing here fails the tests that run rows.
const std::map<std::string, std::vector<std::string>>& base_arguments() {
  static const std::map<std::string, std::vector<std::string>> base{
      {"simulate", {"--quiet", "--out", "D"}},
      {"analyze", {"--out", "D"}},
      {"sweep", {"--quiet", "--no-plot", "--out", "D"}},
      {"map", {"--quiet", "--no-plot", "--out", "D"}},
      {"basin", {"--quiet", "--no-plot", "--out", "D"}},
      {"orbit", {"--quiet", "--out", "D"}},
      {"continue",
       {"--parameter", "theta", "--range", "0.9:1", "--no-plot", "--quiet", "--out", "D"}},
      {"bench chain", {"--quiet", "--out", "D"}},
      {"bench scaling", {"--quiet", "--out", "D"}},
      {"bench accuracy", {"--quick", "--no-plot", "--out", "D", "--plots", "D"}},
      {"bench stability", {"--quick", "--no-plot", "--out", "D", "--plots", "D"}},
      {"bench sweep", {"--quiet", "--out", "D"}},
      {"bench orbits", {"--quick", "--quiet", "--out", "D"}},
      {"bench soak", {"--quiet", "--out", "D"}},
      {"bench curves", {"--quick", "--out", "D"}},
  };
  return base;
}

// The base arguments of `job` in folder `dir`, without the flags `except` and their values.
std::vector<std::string> base_of(const std::string& job, const std::string& dir,
                                 const std::vector<std::string>& except) {
  std::vector<std::string> out;
  const std::vector<std::string>& base = base_arguments().at(job);
  for (std::size_t i = 0; i < base.size(); ++i) {
    const bool takes_value = i + 1 < base.size() && base[i + 1].rfind("--", 0) != 0;
    if (std::find(except.begin(), except.end(), base[i]) != except.end()) {
      if (takes_value) ++i;
      continue;
    }
    out.push_back(base[i] == "D" ? dir : base[i]);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Running the program.

struct Run {
  std::vector<std::string> args;      // after the program's name
  std::string dir;                    // its working folder; output.txt gets stdout and stderr
  std::string what;                   // for messages: the row
  std::vector<std::string> expected;  // pieces the output must hold
  int code = -1;                      // exit code, or -1 when killed
  bool timed_out = false;
  std::string output;
};

constexpr double kTimeLimit = 20.0;  // s per run; a refusal takes milliseconds
constexpr int kParallel = 4;

pid_t start(const Run& run) {
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid > 0) {
    ::setpgid(pid, pid);  // also here, so that the group exists before any kill
    return pid;
  }
  // The child: a process group of its own (a benchmark that slipped through may have started
  // programs of its own: the time limit ends them all), its own folder, one thread, every output
  // into output.txt, the plots folder of the jobs that default to it (bench accuracy and
  // stability) in the row's folder too.
  ::setpgid(0, 0);
  if (::chdir(run.dir.c_str()) != 0) ::_exit(127);
  ::setenv("PWL_PLOTS_DIR", run.dir.c_str(), 1);
  ::setenv("OMP_NUM_THREADS", "1", 1);
  const int fd = ::open("output.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) ::_exit(127);
  ::dup2(fd, 1);
  ::dup2(fd, 2);
  std::vector<std::string> all{PWL_EXECUTABLE};
  all.insert(all.end(), run.args.begin(), run.args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  ::execv(PWL_EXECUTABLE, argv.data());
  ::_exit(127);
}

// Runs every run, kParallel at a time, each killed at kTimeLimit.
void run_all(std::vector<Run>& runs) {
  struct Active {
    pid_t pid;
    std::size_t index;
    std::chrono::steady_clock::time_point since;
  };
  std::vector<Active> active;
  std::size_t next = 0;
  while (next < runs.size() || !active.empty()) {
    while (next < runs.size() && active.size() < static_cast<std::size_t>(kParallel)) {
      active.push_back({start(runs[next]), next, std::chrono::steady_clock::now()});
      ++next;
    }
    bool reaped = false;
    for (auto it = active.begin(); it != active.end();) {
      int status = 0;
      Run& run = runs[it->index];
      const pid_t done = ::waitpid(it->pid, &status, WNOHANG);
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - it->since).count();
      if (done == 0 && seconds > kTimeLimit) {
        ::kill(-it->pid, SIGKILL);  // the run's process group, which start() made
        ::waitpid(it->pid, &status, 0);
        run.timed_out = true;
      } else if (done == 0) {
        ++it;
        continue;
      } else {
        ::kill(-it->pid, SIGKILL);  // whatever the run left behind in its group
      }
      run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      std::ifstream in(run.dir + "/output.txt");
      std::stringstream text;
      text << in.rdbuf();
      run.output = text.str();
      it = active.erase(it);
      reaped = true;
    }
    if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

// A fresh folder under the test's working folder.
std::string fresh_folder(const std::string& name) {
  const fs::path dir = fs::current_path() / "bad_values_runs" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

// Checks every run: exit code 2 and every expected piece in what it printed.
void check_runs(const std::vector<Run>& runs) {
  int refused = 0;
  for (const Run& run : runs) {
    bool ok = run.code == 2 && !run.timed_out;
    for (const std::string& piece : run.expected)
      ok = ok && run.output.find(piece) != std::string::npos;
    if (ok) {
      ++refused;
      continue;
    }
    std::string command = "pwl";
    for (const std::string& a : run.args) command += " " + a;
    std::string expected;
    for (const std::string& piece : run.expected) expected += "\n    \"" + piece + "\"";
    FAIL_CHECK(run.what << "\n  " << command << "\n  "
                        << (run.timed_out
                                ? "still running after the time limit (the value slipped "
                                  "through)"
                                : "exit code " + std::to_string(run.code) + " (expected 2)")
                        << "\n  expected to see:" << expected << "\n  it said:\n"
                        << run.output);
  }
  INFO(refused << " of " << runs.size() << " runs refused as expected");
  CHECK(refused == static_cast<int>(runs.size()));
}

std::string row_name(const Row& row) {
  return "bad_values.csv:" + std::to_string(row.line) + ": pwl " + row.job + " " + row.flag + " " +
         row.value;
}

// The items of a value ("1,nan" -> 1, nan), and whether all of them are numbers.
std::vector<std::string> items(const std::string& value) {
  std::vector<std::string> out;
  std::size_t from = 0;
  while (from <= value.size()) {
    const std::size_t end = std::min(value.find(',', from), value.size());
    out.push_back(value.substr(from, end - from));
    from = end + 1;
  }
  return out;
}

bool is_number(const std::string& text) {
  if (text.empty()) return false;
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return *end == '\0';
}

// The value as TOML: numbers as numbers (nan, inf and -inf are TOML floats), a list of them as an
// array, anything else as a string.
std::string toml_value(const std::string& value) {
  const std::vector<std::string> parts = items(value);
  const bool numbers = std::all_of(parts.begin(), parts.end(), is_number);
  if (!numbers) return "\"" + value + "\"";
  if (parts.size() == 1) return parts[0];
  std::string array = "[";
  for (std::size_t i = 0; i < parts.size(); ++i) array += (i > 0 ? ", " : "") + parts[i];
  return array + "]";
}

}  // namespace

TEST_CASE("The program's jobs are the ones this test builds", "[bad-values]") {
  // main.cpp's command line against the one built here: the subcommands pwl --help and pwl bench
  // --help list.
  const auto listed = [](const std::string& args) {
    const std::string dir = fresh_folder("help_" + std::to_string(std::hash<std::string>()(args)));
    std::vector<Run> runs(1);
    runs[0].args = words(args);
    runs[0].dir = dir;
    run_all(runs);
    REQUIRE(runs[0].code == 0);
    std::set<std::string> names;
    std::istringstream in(runs[0].output);
    bool in_list = false;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("Subcommands:", 0) == 0) {
        in_list = true;
      } else if (in_list && line.size() > 2 && line[0] == ' ' && line[2] != ' ') {
        names.insert(words(line).front());
      } else if (in_list && line.find_first_not_of(' ') == std::string::npos) {
        in_list = false;
      }
    }
    return names;
  };
  const std::unique_ptr<CLI::App> app = program();
  std::set<std::string> top, bench;
  for (const CLI::App* sub : app->get_subcommands({})) top.insert(sub->get_name());
  for (const CLI::App* sub : app->get_subcommand("bench")->get_subcommands({}))
    bench.insert(sub->get_name());
  CHECK(listed("--help") == top);
  CHECK(listed("bench --help") == bench);
}

TEST_CASE("Every numeric flag of every job has its bad values in the table", "[bad-values]") {
  const std::unique_ptr<CLI::App> app = program();
  std::vector<std::pair<std::string, CLI::App*>> jobs;
  collect_jobs(*app, "", jobs);
  REQUIRE(jobs.size() >= 14);  // simulate ... continue, run, reproduce and six benchmarks

  // (job, flag) -> every item of every value its rows give ("2,nan" gives 2 and nan: a list
  // flag's rows put the bad item after a good one, to show that each item is checked).
  std::map<std::pair<std::string, std::string>, std::set<std::string>> values;
  for (const Row& row : table()) {
    for (const std::string& item : items(row.value)) values[{row.job, row.flag}].insert(item);
    values[{row.job, row.flag}].insert(row.value);
  }

  int numeric = 0, missing = 0;
  std::set<std::pair<std::string, std::string>> known;
  for (const auto& [job, command] : jobs) {
    for (const CLI::Option* option : command->get_options()) {
      const std::string flag = flag_name(*option);
      known.insert({job, flag});
      const Kind kind = kind_of(*option, job);
      if (kind == Kind::other) continue;
      ++numeric;
      const auto& given = values[{job, flag}];
      // Every numeric flag: the three non-finite values, alone or as an item of a list. A range:
      // a non-finite end.
      const std::vector<std::string> needed = kind == Kind::numeric
                                                  ? std::vector<std::string>{"nan", "inf", "-inf"}
                                                  : std::vector<std::string>{};
      for (const std::string& v : needed) {
        if (given.count(v) == 0) {
          ++missing;
          FAIL_CHECK("pwl " << job << " " << flag << " (" << option->get_type_name()
                            << ") has no row for the value " << v
                            << " in tests/cli/bad_values.csv: add one with the message it gives");
        }
      }
      if (kind == Kind::range && std::none_of(given.begin(), given.end(), [](const std::string& v) {
            return v.find("nan") != std::string::npos || v.find("inf") != std::string::npos;
          })) {
        ++missing;
        FAIL_CHECK("pwl " << job << " " << flag
                          << " (a FROM:TO range) has no row with a non-finite end in "
                             "tests/cli/bad_values.csv");
      }
    }
  }
  INFO(numeric << " numeric flags or ranges over " << jobs.size() << " jobs");
  CHECK(missing == 0);
  // No row for a job or flag that does not exist (a row left behind by a renamed flag).
  for (const Row& row : table()) {
    const std::vector<std::string> flags = row.flags();
    for (const std::string& flag : flags) {
      if (known.count({row.job, flag}) == 0) {
        FAIL_CHECK("bad_values.csv:" << row.line << ": pwl " << row.job << " has no flag "
                                     << flag);
      }
    }
    if (flags.size() > 2 || flags.size() != row.values().size()) {
      FAIL_CHECK("bad_values.csv:" << row.line << ": give one flag and its value, or the two "
                                      "flags of a relation and their two values");
    }
  }
  // Every relation between two flags has its row.
  for (const pwl::app::FlagRelation& relation : pwl::app::flag_relations()) {
    const std::string flags = relation.first + " " + relation.second;
    const bool has_row = std::any_of(table().begin(), table().end(), [&](const Row& row) {
      return row.job == relation.job && row.flag == flags;
    });
    if (!has_row) {
      FAIL_CHECK("pwl " << relation.job << ": the relation between " << relation.first << " and "
                        << relation.second << " (flag_relations.cpp) has no row \"" << flags
                        << "\" in tests/cli/bad_values.csv");
    }
  }
  // And every job with rows has its base arguments.
  for (const Row& row : table()) {
    if (base_arguments().count(row.job) == 0) {
      FAIL_CHECK("bad_values.csv:" << row.line << ": pwl " << row.job
                                   << " has no base arguments in bad_values_test.cpp");
    }
  }
}

TEST_CASE("Every bad value of the table is refused on the command line", "[bad-values]") {
  std::vector<Run> runs;
  int index = 0;
  for (const Row& row : rows_to_run()) {
    if (base_arguments().count(row.job) == 0) continue;  // reported by the coverage test
    Run run;
    run.dir = fresh_folder("flag_" + std::to_string(index++));
    run.args = words(row.job);
    const std::vector<std::string> flags = row.flags(), values = row.values();
    const std::vector<std::string> base = base_of(row.job, run.dir, flags);
    run.args.insert(run.args.end(), base.begin(), base.end());
    // --flag=value: a value starting with '-' is the flag's value, not another flag.
    for (std::size_t k = 0; k < flags.size(); ++k) run.args.push_back(flags[k] + "=" + values[k]);
    run.what = row_name(row);
    run.expected = {row.message};
    runs.push_back(std::move(run));
  }
  REQUIRE(!runs.empty());
  const auto began = std::chrono::steady_clock::now();
  run_all(runs);
  INFO(
      runs.size() << " runs in "
                  << std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count()
                  << " s");
  check_runs(runs);
}

TEST_CASE("Every bad value of the table is refused as a scene key, located in the scene",
          "[bad-values]") {
  // The row's flag as a key of [run] (the sections only group: any key means its flag), in a
  // scene of the row's job: `tol = nan`, `alpha = [1, -1]`, `range = "nan:3"`. A non-finite
  // number is refused by the scene reader itself, any other value by the job's check; either way
  // the message starts with the scene file, the line and the key.
  const std::unique_ptr<CLI::App> app = program();
  std::vector<std::pair<std::string, CLI::App*>> jobs;
  collect_jobs(*app, "", jobs);
  std::map<std::string, CLI::App*> by_name(jobs.begin(), jobs.end());
  std::vector<Run> runs;
  int index = 0;
  for (const Row& row : rows_to_run()) {
    if (base_arguments().count(row.job) == 0 || by_name.count(row.job) == 0) continue;
    const std::vector<std::string> flags = row.flags(), values = row.values();
    const bool hidden = std::any_of(flags.begin(), flags.end(), [&](const auto& f) {
      const CLI::Option* option = by_name[row.job]->get_option_no_throw(f);
      return option == nullptr || option->get_group().empty();
    });
    if (hidden) continue;  // a hidden flag has no scene key
    Run run;
    run.dir = fresh_folder("scene_" + std::to_string(index++));
    const auto key_of = [](const std::string& flag) {
      std::string key = flag.substr(2);
      std::replace(key.begin(), key.end(), '-', '_');
      return key;
    };
    const std::string key = key_of(flags.front());
    const std::string scene = run.dir + "/bad.toml";
    {
      std::ofstream file(scene);
      file << "job = \"" << row.job << "\"\n[run]\n";
      for (std::size_t k = 0; k < flags.size(); ++k) {
        file << key_of(flags[k]) << " = " << toml_value(values[k]) << "\n";
      }
    }
    run.args = {"run", scene};
    const std::vector<std::string> base = base_of(row.job, run.dir, flags);
    run.args.insert(run.args.end(), base.begin(), base.end());
    run.what = row_name(row) + " as the scene key run." + key;
    if (flags.size() > 1) {
      // A relation: refused once both keys are read, with the table's message and the scene's
      // file (the pair has no single line).
      run.expected = {scene, row.message};
      runs.push_back(std::move(run));
      continue;
    }
    const std::vector<std::string> parts = items(row.value);
    const auto non_finite = std::find_if(parts.begin(), parts.end(), [](const std::string& p) {
      return is_number(p) && !std::isfinite(std::strtod(p.c_str(), nullptr));
    });
    const bool numbers = std::all_of(parts.begin(), parts.end(), is_number);
    run.expected = {scene + ":3:", "run." + key + ":",
                    numbers && non_finite != parts.end()
                        ? "expected a finite number, got " + *non_finite
                        : row.message};
    runs.push_back(std::move(run));
  }
  REQUIRE(!runs.empty());
  run_all(runs);
  check_runs(runs);
}

TEST_CASE("The number checks refuse NaN, infinities and overflow and quote the value as typed",
          "[bad-values]") {
  using namespace pwl::app;
  const auto message = [](const CLI::Validator& v, std::string text) { return v(text); };
  CHECK(message(positive_number(), "1e-300") == "");
  CHECK(message(positive_number(), "0") == "must be a positive number, got 0");
  CHECK(message(positive_number(), "nan") == "must be a positive number, got nan");
  CHECK(message(positive_number(), "1e400") == "must be a positive number, got 1e400");
  CHECK(message(non_negative_number(), "0") == "");
  CHECK(message(non_negative_number(), "-0.5") == "must be zero or a positive number, got -0.5");
  CHECK(message(finite_number(), "-1e300") == "");
  CHECK(message(finite_number(), "-inf") == "must be a finite number, got -inf");
  CHECK(message(finite_number(), "one") == "must be a finite number, got one");
  CHECK(message(number_at_least(2), "2") == "");
  CHECK(message(number_at_least(2), "1") == "must be a number >= 2, got 1");
  CHECK(message(number_in(100, 1000000), "1000000") == "");
  CHECK(message(number_in(100, 1000000), "99") == "must be a number in [100, 1000000], got 99");
  CHECK(message(number_between(0, 1e-4), "0") == "must be a number in (0, 0.0001), got 0");
  CHECK(message(number_between(0, 1e-4), "1e-5") == "");
}
