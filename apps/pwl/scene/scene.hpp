#pragma once
// Scene files: one TOML file describes a whole study, so that it can be kept, shared, edited and
// rerun. A scene names its job and groups its settings by what they are about:
//
//     job = "analyze"              # simulate | analyze | sweep | map | bench chain | ...
//     [structure]                  # the paper's nondimensional chain ...
//     figure = "4b"                #   a preset, then any of masses, alpha, zeta, gap, gaps,
//     theta = 1.0                  #   theta, loads
//     [method]
//     name = "pim"                 # any --method; steps_per_period, dt, tol, locate_kinks, lcp
//     [run]
//     periods = 1000
//     x0 = [0.1, 0, 0, 0, 0]       # the initial state (--x0, --v0; one value is every mass's)
//     [analysis]
//     transient = 500
//     section = "v3=0,down"        # --section: strobe (with phase = P) or a hyperplane
//     [output]
//     out = "out/fig4b"
//
// Every key is a flag of the job's subcommand, written without the leading dashes and with '_'
// for '-' (`steps_per_period` is `--steps-per-period`); `structure.masses` is `--n` and
// `method.name` is `--method`. A list is a comma-separated flag value and `true` turns a switch
// on. The section only groups: the same key means the same flag in any section. What a scene
// does not state takes the subcommand's documented default, so a scene states only what its study
// needs.
//
// Instead of the chain's parameters, [structure] may give a structure explicitly (masses are
// numbered from 1):
//
//     [structure]
//     mass = [[1.0, 0.0], [0.0, 1.0]]          # M, C, K as rows
//     damping = [[0.1, 0.0], [0.0, 0.1]]
//     stiffness = [[2.0, -1.0], [-1.0, 1.0]]
//     spring = [{ mass = 2, stiffness = 4.0, gap = 0.2 },            # to the ground
//               { mass = 1, other_mass = 2, direction = -1, stiffness = 1.0, gap = 0.1 }]
//     load = [{ mass = 2, amplitude = 1.0, omega = 1.2, phase = 0.0 }]
//
// which the subcommand reads through `--structure-scene <file>` (scene_structure.hpp).
//
// This file only turns text into flags: it needs neither the solvers nor the command-line
// library, so that it can be fuzzed on its own. Whether each flag exists and takes that kind of
// value is checked against the subcommand itself (scene_command_line.hpp).
#include <string>
#include <string_view>
#include <vector>

namespace pwl::app {

// One setting of a scene, as the flag of a subcommand.
struct SceneSetting {
  enum class Kind { boolean, integer, real, text, list };
  std::string key;                  // dotted, as written: "method.tol"
  std::string flag;                 // "--tol"
  std::vector<std::string> values;  // the flag's arguments (none for a switch that is on)
  Kind kind = Kind::text;
  bool switched_on = true;  // a boolean: whether the switch is given at all
  std::string where;        // "file:line:column" of the value, or "--set key=value"
  long position = 0;        // line and column in the file (for its order)
};

struct Scene {
  std::string name;                    // the file it came from
  std::string job;                     // the subcommand it is for ("" when it does not say)
  std::vector<SceneSetting> settings;  // in file order, overrides last
  bool explicit_structure = false;     // [structure] gives M, C, K, springs and loads
};

// Parses a scene. `name` is the file name used in messages. `overrides` are "key=value" with a
// dotted key and a TOML value ("method.tol=1e-8", "structure.figure=4b"; a bare word is taken as
// text); they replace or add to what the file says. Throws InputError naming the file, line,
// key and what was expected, for a syntax error, an unknown section, a nested table, a mixed or
// nested list, or an override that is not key=value.
Scene parse_scene(std::string_view text, const std::string& name,
                  const std::vector<std::string>& overrides = {});

// Reads and parses the file at `path` (InputError when it cannot be read).
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// The settings as subcommand arguments: "--tol", "1e-08", "--locate-kinks", ...
std::vector<std::string> scene_arguments(const Scene& scene);

// The text as the TOML library may safely see it. toml++ 3.3 (Debian 12) meets some malformed
// input with undefined behaviour instead of an error: non-ASCII characters where it tests for
// blanks (an unreachable branch), and a key or value missing where it assumes one ("[ = 1",
// "x = [}", "{ = 1 }", ...), as fuzzing found. So this screens first and refuses, with
// file:line:column: a control character other than tab and line ends; a non-ASCII character
// outside a comment (the non-ASCII bytes of comments are blanked, keeping every position); a
// section header without a name; a missing key or value. All of these are invalid TOML anyway.
std::string screen_scene_text(std::string_view text, const std::string& name);

// The sections a scene may have.
const std::vector<std::string>& scene_sections();

}  // namespace pwl::app
