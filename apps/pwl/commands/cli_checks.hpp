#pragma once
// Checks of flag values whose messages say what is wanted ("must be a positive number, got 0"),
// where CLI11's own range checks print the whole double range.
#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace pwl::app {

inline CLI::Validator number_check(bool zero_allowed) {
  return CLI::Validator(
      [zero_allowed](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || value < 0.0 ||
            (value == 0.0 && !zero_allowed)) {
          return (zero_allowed ? "must be zero or a positive number, got "
                               : "must be a positive number, got ") +
                 text;
        }
        return "";
      },
      zero_allowed ? "NONNEGATIVE" : "POSITIVE");
}

// > 0 and finite.
inline CLI::Validator positive_number() { return number_check(false); }
// >= 0 and finite.
inline CLI::Validator non_negative_number() { return number_check(true); }

}  // namespace pwl::app
