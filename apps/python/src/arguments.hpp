#pragma once
// Keyword arguments of a Python call as the CLI's own command line.
//
// Each job of the module registers its flags on a CLI11 app with the CLI's own functions
// (add_case_options, add_point_flags, add_orbit_flags, ...), so that the names, the defaults, the
// checks and their messages are the CLI's. The keyword arguments become an argument vector, a
// keyword `skip_periods=10` the flag `--skip-periods=10`, and the app parses it:
//   - None: the flag is not given (its default applies);
//   - True / False: a flag (--locate-kinks) given or not;
//   - int, str: as written; float: 17 significant digits, so the CLI reads the same double;
//   - a list, tuple or 1-D NumPy array: its items joined by commas (--loads=1,-1,1,-1,1);
//   - a range (a flag named *range, FROM:TO on the command line): a pair of numbers, (0.5, 3) for
//     --range=0.5:3, or the string as written.
//   - a parameter and its range, NAME=FROM:TO on the command line: a pair of the name and a pair of
//     numbers, ("alpha", (1, 15)) for --curves=alpha=1:15.
// A keyword that names no flag of the job raises TypeError naming it; a value the CLI refuses
// raises pwl.InputError with the CLI's message ("--n: must be a positive number, got 0").
#include <pybind11/pybind11.h>

#include <CLI/CLI.hpp>
#include <map>
#include <string>
#include <vector>

namespace pwl::python {

// Flags of the CLI job that the Python function does not take, with why (they shape the files a
// command writes; the function returns arrays instead). A keyword naming one raises TypeError
// with that reason.
using LeftOut = std::map<std::string, std::string>;

// Removes the flags `left_out` names (e.g. "--out") and --help from `app`.
void leave_out(CLI::App& app, const LeftOut& left_out);

// Parses `kwargs` (without the keywords the caller handles itself) with `app`. `function` names
// the Python function in messages ("simulate"). Throws pybind11::type_error for a keyword that is
// not a flag of `app`, or a value of the wrong kind for it; pwl::InputError for what CLI11 refuses.
void parse_keywords(CLI::App& app, const std::string& function, const pybind11::dict& kwargs,
                    const LeftOut& left_out = {});

// "--skip-periods" for "skip_periods".
std::string flag_of(const std::string& keyword);

// One keyword of a job, for its docstring: the keyword, what --help shows as its default ("" for
// none), its description, and whether it is a flag (True/False).
struct KeywordDoc {
  std::string keyword;
  std::string default_text;
  std::string description;
  bool flag = false;
};

// Every option of `app` (after leave_out) as keywords, in --help's order.
std::vector<KeywordDoc> keyword_docs(const CLI::App& app);

// The keyword docs of the job named `function` ("simulate", ...), registered by the job's
// binding (bind_run_jobs, bind_orbit_jobs) with `describe`, which builds the job's app as its
// function does; keywords_of throws InputError for a name none registered.
void register_keywords(const std::string& function, std::vector<KeywordDoc> (*describe)());
std::vector<KeywordDoc> keywords_of(const std::string& function);

}  // namespace pwl::python
