#pragma once
// Checks of numeric flag values whose messages say what is wanted ("must be a positive number,
// got 0"), where CLI11's own range checks print the whole double range.
//
// Every numeric flag of every job carries one of these (tests/cli/bad_values_test.cpp fails for a
// numeric flag without a row in tests/cli/bad_values.csv, and checks every row). A validator sees
// the text as typed (or as a scene wrote it), before CLI11 converts it, and for a list flag
// (--alpha 1,2,3) each item on its own; so NaN and ±Inf are refused here even where a NaN would
// otherwise mean "not given" (--theta, --zeta, --gap), and the message quotes the value as given.
// CLI11 words the refusal "<flag>: <message>", and the program exits with code 2.
//
// Where a job checks a sign or range after parsing with a message of its own that names the flag
// (--phase, --x0, --points of a sweep, ...), the flag takes finite_number() and keeps that check.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <limits>
#include <string>

namespace pwl::app {

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// The interval a numeric flag's value must lie in. The ends are included unless said otherwise;
// an infinite end leaves that side open. NaN and ±Inf are always refused: no flag takes them.
struct NumberRange {
  double low = -kUnbounded;
  double high = kUnbounded;
  bool low_open = false;   // value > low instead of >= low
  bool high_open = false;  // value < high instead of <= high
  std::string wanted;      // the message's "must be ..." part

  bool contains(double value) const {
    if (!std::isfinite(value)) return false;
    if (low_open ? !(value > low) : !(value >= low)) return false;
    if (high_open ? !(value < high) : !(value <= high)) return false;
    return true;
  }
};

// A validator for `range`: "must be <wanted>, got <text>", with `name` shown in --help
// (FLOAT:name).
inline CLI::Validator number_check(NumberRange range, const std::string& name) {
  return CLI::Validator(
      [range](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !range.contains(value)) {
          return fmt::format("must be {}, got {}", range.wanted, text);
        }
        return "";
      },
      name);
}

// Any finite number (the sign is free, or a job checks it after parsing).
inline CLI::Validator finite_number() {
  return number_check({-kUnbounded, kUnbounded, false, false, "a finite number"}, "FINITE");
}
// > 0 and finite.
inline CLI::Validator positive_number() {
  return number_check({0.0, kUnbounded, true, false, "a positive number"}, "POSITIVE");
}
// >= 0 and finite.
inline CLI::Validator non_negative_number() {
  return number_check({0.0, kUnbounded, false, false, "zero or a positive number"}, "NONNEGATIVE");
}
// >= low and finite.
inline CLI::Validator number_at_least(double low) {
  return number_check({low, kUnbounded, false, false, fmt::format("a number >= {}", low)},
                      fmt::format(">={}", low));
}
// In [low, high].
inline CLI::Validator number_in(double low, double high) {
  return number_check({low, high, false, false, fmt::format("a number in [{}, {}]", low, high)},
                      fmt::format("[{},{}]", low, high));
}
// In (low, high): both ends excluded.
inline CLI::Validator number_between(double low, double high) {
  return number_check({low, high, true, true, fmt::format("a number in ({}, {})", low, high)},
                      fmt::format("({},{})", low, high));
}

// `validator` for an option hidden from --help (group ""), whose name CLI11 leaves out of its
// refusal (": must be ..."): the message names `flag` itself.
inline CLI::Validator naming(const std::string& flag, const CLI::Validator& validator) {
  return CLI::Validator(
      [flag, validator](std::string& text) -> std::string {
        const std::string why = validator(text);
        return why.empty() ? why : flag + ": " + why;
      },
      validator.get_description());
}

// Adds `validator` to the option `flag` of `command`, registered elsewhere (a shared registration
// this job extends). Throws CLI::OptionNotFound when the command has no such option.
inline void check_flag(CLI::App& command, const std::string& flag,
                       const CLI::Validator& validator) {
  command.get_option(flag)->check(validator);
}

}  // namespace pwl::app
