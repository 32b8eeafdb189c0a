// pwl: dynamics of piecewise-linear structures. apps/README.md says what each job does.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "commands/commands.hpp"
#include "parallel/stop_signals.hpp"
#include "pwl/errors.hpp"
#include "scene/scene_command_line.hpp"

int main(int argc, char** argv) {
  // A file size limit (ulimit -f) is met with SIGXFSZ, whose default action kills the process
  // with no word; ignored, the write fails with EFBIG instead and becomes an error message that
  // names the file, after the journal has been left with whole lines only.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{
      "pwl: vibration and bifurcation analysis of structures with gap-activated springs,\n"
      "by precise integration with one linear complementarity problem per step."};
  app.set_version_flag("--version", std::string("pwl ") + PWL_VERSION);
  app.require_subcommand(1);
  app.option_defaults()->always_capture_default();  // --help shows every default
  pwl::app::add_simulate_command(app);
  pwl::app::add_analyze_command(app);
  pwl::app::add_reproduce_command(app);
  pwl::app::add_bench_command(app);
  pwl::app::add_sweep_command(app);
  pwl::app::add_map_command(app);
  pwl::app::add_basin_command(app);
  pwl::app::add_orbit_command(app);
  pwl::app::add_continue_command(app);
  pwl::app::add_run_command(app);
  pwl::app::add_scene_options(app);
  // An empty list's default reads "[]" in --help: show nothing instead.
  const std::function<void(CLI::App&)> tidy = [&tidy](CLI::App& command) {
    for (CLI::Option* o : command.get_options()) {
      if (o->get_default_str() == "[]") o->default_str("");
    }
    for (CLI::App* sub : command.get_subcommands({})) tidy(*sub);
  };
  tidy(app);
  pwl::app::ExpandedCommandLine line;
  try {
    line = pwl::app::expand_scenes(std::vector<std::string>(argv + 1, argv + argc), app);
    std::vector<std::string> reversed(line.args.rbegin(), line.args.rend());  // CLI11's order
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0 && !line.settings.empty()) {
      fmt::print(stderr, "pwl: bad input: {}\n", pwl::app::locate_in_scene(e.what(), line));
      return 2;
    }
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const pwl::app::Stopped& e) {
    // A study stopped by SIGINT or SIGTERM, its journals whole: the exit code a shell reports for
    // a process killed by that signal.
    fmt::print(stderr, "pwl: {}\n", e.what());
    return e.exit_code();
  } catch (const pwl::InputError& e) {
    fmt::print(stderr, "pwl: bad input: {}\n", pwl::app::locate_in_scene(e.what(), line));
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "pwl: {}\n", e.what());
    return 1;
  }
  return 0;
}
