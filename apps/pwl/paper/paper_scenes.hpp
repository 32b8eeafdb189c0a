#pragma once
// The shipped scenes that `pwl reproduce` runs, each as a user would run it (`pwl run SCENE`), and
// where each puts the figures the guides show (plots/README.md lists them). A scene's own output goes under
// <plots>/data/<scene>; its figures are copied to <plots>/<name>.png and .svg.
#include <string>
#include <utility>
#include <vector>

#include "output/shipped_files.hpp"

namespace pwl::app {


struct ReproducedScene {
  std::string key;    // for --only: "4a", "4b", "5", "6", "7-9", "theta-sweep", "theta-alpha-map",
                      // "continuation", "basins"
  std::string scene;  // file name in the scenes folder
  // --set overrides of every run (the paper's figure title) and of a smoke run (--quick: shorter
  // runs, smaller grids).
  std::vector<std::string> always;
  std::vector<std::string> quick;
  // (file written by the scene, name of the figure under plots/), without the extension.
  std::vector<std::pair<std::string, std::string>> figures;
  // One of the paper's figures or its table (run first), or one of pwl's own studies.
  bool paper = false;
  // The key of an earlier scene whose output folder this run continues in (--resume, to draw it
  // again with more over it) instead of a fresh folder of its own; "" for none. In `always` and
  // `quick`, {data} stands for the folder every scene's output goes under.
  std::string continues;
};

// Every scene `pwl reproduce` runs, in order: the paper's figures and table first (`paper`), then
// the project's own charts that need no timing (the benchmarks' charts are made by their
// bench_*.toml scenes).
const std::vector<ReproducedScene>& reproduced_scenes();

// Runs `scene` through this very program (`self`: its path), its output under `out`, with the
// quick overrides when asked. Returns what it printed; throws Error when the run fails.
std::string run_scene(const std::string& self, const ReproducedScene& scene,
                      const std::string& out, const std::string& data, bool quick);

// The rest of the line after `prefix` in `text` ("" when absent).
std::string line_after(const std::string& text, const std::string& prefix);

}  // namespace pwl::app
