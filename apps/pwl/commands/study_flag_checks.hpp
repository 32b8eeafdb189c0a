#pragma once
// The value checks of the flags that `pwl sweep` and `pwl map` share through add_point_flags
// (study_runner.hpp), added where each job registers them (cli_checks.hpp says why every numeric
// flag has one). --tol and --threads carry theirs from the registration itself.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

#include "commands/cli_checks.hpp"
#include "pwl/errors.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

inline void check_point_flags(CLI::App& command) {
  check_flag(command, "--transient", non_negative_number());
  check_flag(command, "--periods", positive_number());
  check_flag(command, "--steps-per-period", positive_number());
}

// The ends of a FROM:TO flag (`text`, split by parse_range into `from` and `to`) that a study
// varies `parameter` of `model` over: both finite, and each a value the model takes (θ > 0, a load
// frequency > 0, ...). Throws InputError naming the flag and its text, as pwl continue words it.
inline void check_range_ends(const analysis::PointModel& model,
                             const analysis::SweepParameter& parameter, const std::string& flag,
                             const std::string& text, double from, double to) {
  if (!std::isfinite(from) || !std::isfinite(to)) {
    throw InputError(fmt::format("{} = \"{}\": FROM and TO must be finite numbers", flag, text));
  }
  std::string why;
  for (const double end : {from, to}) {
    if (!model.accepts(parameter, end, &why)) {
      throw InputError(
          fmt::format("{} = \"{}\": at {} = {}: {}", flag, text, parameter.name(), end, why));
    }
  }
}

}  // namespace pwl::app
