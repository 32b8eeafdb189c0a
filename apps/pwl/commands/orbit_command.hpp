#pragma once
// pwl orbit as functions, for the command and for an embedding (the Python module): its flags,
// and the problem they describe, checked and ready for Newton. The command then prints the
// method's note, takes the starting guess, runs find_periodic_orbit and writes orbit.csv,
// floquet.csv and orbit_path.csv; the Python module does the same in memory.
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "commands/orbit_options.hpp"
#include "pwl/orbits/periodic_orbit.hpp"
#include "pwl/orbits/stroboscopic_map.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

struct OrbitCommandFlags {
  OrbitFlags orbit;
  int shots = 1;
  std::string solver = "automatic";
  int floquet_count = 6;
  bool no_path = false;
};

// Every flag of pwl orbit: add_orbit_flags (with --dt), --shots, --solver, --floquet-count and
// --no-path. After parsing, call read_method_given(command, flags.orbit).
void add_orbit_command_flags(CLI::App& command, OrbitCommandFlags& flags);

// What Newton needs: the case, the method, the shooting options and the stroboscopic map.
struct OrbitProblem {
  analysis::PointModel model;
  analysis::PointCase point;
  OrbitMethod method;
  orbits::ShootingOptions shooting;
  std::unique_ptr<orbits::StroboscopicMap> map;
};

// Checks the flags (InputError naming the flag and its value) and builds the map of the case.
// The guess is starting_guess(flags.orbit, *problem.map).
OrbitProblem orbit_problem(const OrbitCommandFlags& flags);

}  // namespace pwl::app
