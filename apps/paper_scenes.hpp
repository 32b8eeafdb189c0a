#pragma once
// The shipped scenes of the paper's figures 5 and 6 (apps/scenes/paper_fig5.toml,
// paper_fig6.toml), run as a user would run them (`pwl run SCENE`), for `pwl reproduce`: the
// regime pwl finds next to the one the paper states.
#include <string>
#include <vector>

namespace pwl::app {

// The folder of the shipped scenes: $PWL_SCENES_DIR, else apps/scenes of the source tree.
std::string scenes_directory();

struct SceneRegime {
  std::string figure;        // "5"
  std::string scene;         // the scene file
  std::string paper_regime;  // what the paper says
  std::string regime;        // what pwl finds
  std::string lambda1;       // the λ1 line of pwl analyze
  std::string zero_one;      // the K line
};

// Runs each paper scene of an analyze job through this very program (`self`: its path), its
// output under data_dir/<scene name>. quick: 400 periods, 250 of them transient. Copies the
// two-panel figure to plots_dir/analysis_fig<F>.png unless quick. Throws Error when a run fails.
std::vector<SceneRegime> run_paper_scenes(const std::string& self, const std::string& plots_dir,
                                          bool quick);

}  // namespace pwl::app
