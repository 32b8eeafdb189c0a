#pragma once
// Scene files on the command line:
//
//   pwl run SCENE [--set key=value]... [flags]          runs the job the scene names
//   pwl JOB --scene SCENE [--set key=value]... [flags]   runs JOB with the scene's settings
//
// A job is a subcommand that does one study: simulate, analyze, sweep, map, and each benchmark
// ("bench chain", "bench accuracy", ...).
//
// The scene becomes the flags it stands for (scene.hpp), placed before the ones typed on the
// command line; a flag typed on the command line replaces the scene's. Each scene key is checked
// against the job's own options before anything runs: it must be one, and take that kind of value
// (a switch takes true/false, a number flag a number, a single-value flag one value), so that the
// message names the file, line and key rather than a flag the user never typed.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace pwl::app {

struct ExpandedCommandLine {
  std::vector<std::string> args;       // what the command-line parser gets (no program name)
  std::vector<SceneSetting> settings;  // the scene's settings that made it in, for messages
};

// `args` is argv without the program name. Without --scene and `run` it is returned unchanged.
// Throws InputError for a scene that cannot be read or parsed, a key the job does not have or a
// value of the wrong kind.
ExpandedCommandLine expand_scenes(const std::vector<std::string>& args, const CLI::App& app);

// `message` with, when it names a flag that a scene set, where in the scene it was set.
std::string locate_in_scene(const std::string& message, const ExpandedCommandLine& line);

// The jobs a scene may name: "simulate", "analyze", "sweep", "map", "bench chain", ...
std::vector<std::string> job_names(const CLI::App& app);

// Gives every job --scene and --set, for its --help (expand_scenes consumes them before parsing).
void add_scene_options(CLI::App& app);

// The `run` subcommand, for `pwl --help` and `pwl run --help`.
void add_run_command(CLI::App& app);

}  // namespace pwl::app
