// pwl: dynamics of piecewise-linear structures. See README.md for the jobs it does.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "commands.hpp"
#include "pwl/errors.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "pwl: vibration and bifurcation analysis of structures with gap-activated springs,\n"
      "by precise integration with one linear complementarity problem per step."};
  app.set_version_flag("--version", std::string("pwl ") + PWL_VERSION);
  app.require_subcommand(1);
  pwl::app::add_simulate_command(app);
  pwl::app::add_analyze_command(app);
  pwl::app::add_reproduce_command(app);
  pwl::app::add_bench_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const pwl::InputError& e) {
    fmt::print(stderr, "pwl: bad input: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "pwl: {}\n", e.what());
    return 1;
  }
  return 0;
}
