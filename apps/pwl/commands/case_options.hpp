#pragma once
// The flags that describe one case of the nondimensional chain and how to integrate it, shared by
// the subcommands that run a single case (simulate, analyze).
#include <CLI/CLI.hpp>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pwl/model/chain_builders.hpp"
#include "pwl/integrators/integrator.hpp"
#include "pwl/integrators/method_table.hpp"
#include "pwl/study/point_model.hpp"

namespace pwl::app {

struct CaseOptions {
  std::string figure;  // a paper preset ("4a", "4b", "5", "6"); flags override it
  int masses = 5;
  std::vector<double> alpha;  // one value or one per mass
  // NaN: not given (the preset or the default applies).
  double zeta = std::numeric_limits<double>::quiet_NaN();
  double gap = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> gaps;  // per mass, overrides gap
  double theta = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> loads;  // Q per mass (or one value)
  int periods = 1000;
  int skip_periods = 0;  // periods left out of the written output
  int steps_per_period = 200;
  double dt = 0.0;             // overrides steps_per_period; must divide the period
  std::string method = "pim";  // a name of the method table (method_names())
  double tolerance = 1e-10;
  bool locate_kinks = false;
  std::string lcp_solver = "block-pivoting";
  // An explicit structure from a scene file's [structure] table (scene_structure.hpp) instead of
  // the chain; the chain's flags do not apply then.
  std::string structure_scene;

  // The chain these flags describe (the preset, then each given flag).
  NondimensionalChain chain() const;
  bool explicit_structure() const { return !structure_scene.empty(); }
  // The structure: the chain's, or the scene file's explicit one.
  GapStructure structure() const;
  // The point model these flags describe (study/point_model.hpp): the chain, or the explicit
  // structure of --structure-scene; what sweeps, maps and orbits vary. Throws InputError for flags
  // that do not make a valid model.
  analysis::PointModel model() const;
  // The forcing period: the chain's, or the common period of the explicit structure's loads.
  double period() const;
  // A short description for titles and messages.
  std::string description() const;
  // The step the PIM uses: period / steps_per_period, or dt when it divides the period.
  double step(double period) const;
  // The method table's settings these flags give (the step only for fixed-grid methods).
  MethodSettings method_settings(double period) const;
  // The integrator the flags name, with its state at rest at t = 0.
  std::unique_ptr<Integrator> integrator(const GapStructure& structure, double period) const;
};

void add_case_options(CLI::App& command, CaseOptions& options);

// --method's help: one line per row of the method table.
std::string method_help();

// The chain's own flags (--figure, --n, --alpha, --zeta, --gap, --theta, --loads), shared with
// the sweep and map jobs.
void add_chain_options(CLI::App& command, std::string& figure, int& masses,
                       std::vector<double>& alpha, double& zeta, double& gap, double& theta,
                       std::vector<double>& loads);

}  // namespace pwl::app
