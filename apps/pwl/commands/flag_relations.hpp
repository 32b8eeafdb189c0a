#pragma once
// Relations between two flags of a job, checked like a single flag's value (cli_checks.hpp): a
// smallest step at most the largest, a transient shorter than the run, a second parameter other
// than the first. One table holds every relation of every job; a job checks each of its relations
// where it reads its flags (check_relation, by the two flags' names), and tests/cli/bad_values.csv
// has a row for each relation of the table (bad_values_test.cpp fails for one without), run on
// the command line and as scene keys like every other bad value. A refusal is an InputError (exit
// code 2) that names both flags and both values:
//
//   --min-step = 0.5 must be at most --max-step = 0.1
//   --skip-periods = 1000 must be below --periods = 1000 (it would leave nothing to record)
//   --y = theta must differ from --x = theta (both axes would vary one parameter)
#include <string>
#include <vector>

namespace pwl::app {

enum class FlagRelationKind {
  at_most,  // first <= second
  below,    // first < second
  differs,  // first != second (as given: names of parameters or state components)
};

struct FlagRelation {
  std::string job;     // "continue", "simulate", "bench soak", ...
  std::string first;   // "--min-step"
  std::string second;  // "--max-step"
  FlagRelationKind kind = FlagRelationKind::at_most;
  // A value of 0 means "the default, chosen later" for these flags: the relation holds for a 0.
  bool zero_is_default = false;
  std::string why;     // why it must hold, for the message ("" for none)
};

// Every relation of every job.
const std::vector<FlagRelation>& flag_relations();

// Throws InputError when the values `a` of `first` and `b` of `second` break the relation of
// `job`'s table entry for those flags. Throws std::logic_error when the table has no such entry
// (a check not in the table would be a check the tests do not run).
void check_relation(const std::string& job, const std::string& first, double a,
                    const std::string& second, double b);
void check_relation(const std::string& job, const std::string& first, const std::string& a,
                    const std::string& second, const std::string& b);

}  // namespace pwl::app
