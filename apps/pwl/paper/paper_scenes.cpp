#include "paper/paper_scenes.hpp"

#include <fmt/format.h>

#include <cstdlib>

#include "output/shell_command.hpp"

namespace pwl::app {


std::string line_after(const std::string& text, const std::string& prefix) {
  const std::size_t at = text.find(prefix);
  if (at == std::string::npos) return "";
  const std::size_t from = at + prefix.size();
  return text.substr(from, text.find('\n', from) - from);
}

const std::vector<ReproducedScene>& reproduced_scenes() {
  static const std::vector<ReproducedScene> scenes{
      {"4a",
       "paper_fig4a.toml",
       {"output.title=Figure 4a: mass 5, the PIM against a kink-located reference"},
       {"run.periods=300", "run.skip_periods=200"},
       {{"comparison", "fig4a"}},
       true,
       ""},
      {"4b",
       "paper_fig4b.toml",
       {"output.title=Figure 4b: mass 5, the PIM against a kink-located reference"},
       {"run.periods=300", "run.skip_periods=200"},
       {{"comparison", "fig4b"}},
       true,
       ""},
      {"5",
       "paper_fig5.toml",
       {},
       {"run.periods=400", "analysis.transient=250"},
       {{"analysis", "analysis_fig5"}},
       true,
       ""},
      {"6",
       "paper_fig6.toml",
       {},
       {"run.periods=400", "analysis.transient=250"},
       {{"analysis", "analysis_fig6"}},
       true,
       ""},
      {"7-9",
       "paper_fig7-9_table1.toml",
       {},
       {"structure.masses=200", "method.reference_tol=1e-10", "run.runs=1"},
       {{"fig7", "fig7"}, {"fig8", "fig8"}, {"fig9", "fig9"}},
       true,
       ""},
      {"theta-sweep",
       "theta_sweep.toml",
       {},
       {"sweep.points=12", "run.transient=50", "run.periods=100"},
       {{"bifurcation", "bifurcation_theta"}},
       false,
       ""},
      {"theta-alpha-map",
       "theta_alpha_map.toml",
       {},
       {"map.x_points=5", "map.y_points=4", "run.transient=50", "run.periods=100"},
       {{"regime_map", "regime_map_theta_alpha"}, {"lambda1_map", "lambda1_map_theta_alpha"}},
       false,
       ""},
      {"continuation",
       "five_dof_continuation.toml",
       {},
       {"continuation.range=0.65:0.72", "continuation.over_sweep=8", "continuation.over_periods=40",
        "run.transient=50"},
       {{"frequency_response", "frequency_response_theta"},
        {"branch_over_diagram", "branches_over_diagram_theta"}},
       false,
       ""},
      {"basins",
       "hardening_basins.toml",
       {},
       {"basin.x_points=21", "basin.y_points=21", "run.transient=100", "run.periods=40"},
       {{"basin", "basins_hardening_oscillator"}},
       false,
       ""},
      {"theta-alpha-curves",
       "theta_alpha_curves.toml",
       {},
       {"continuation.range=0.98:1.02", "continuation.curves=alpha=4.5:5.5", "run.transient=50"},
       {{"bifurcation_curves", "bifurcation_curves_theta_alpha"}},
       false,
       ""},
      // The (θ, α) map again, its points all journaled already: only drawn, with the curves over it.
      {"theta-alpha-map-curves",
       "theta_alpha_map.toml",
       {"output.curves={data}/theta_alpha_curves", "run.resume=true"},
       {"map.x_points=5", "map.y_points=4", "run.transient=50", "run.periods=100"},
       {{"regime_map", "regime_map_curves_theta_alpha"}},
       false,
       "theta-alpha-map"},
  };
  return scenes;
}

std::string run_scene(const std::string& self, const ReproducedScene& scene, const std::string& out,
                      const std::string& data, bool quick) {
  std::string command =
      fmt::format("{} run {} --set output.out={}", shell_quoted(self),
                  shell_quoted(scenes_directory() + "/" + scene.scene), shell_quoted(out));
  const auto setting = [&](std::string s) {
    for (std::size_t at = s.find("{data}"); at != std::string::npos; at = s.find("{data}", at)) {
      s.replace(at, 6, data);
    }
    return " --set " + shell_quoted(s);
  };
  for (const std::string& s : scene.always) command += setting(s);
  if (quick) {
    for (const std::string& s : scene.quick) command += setting(s);
  }
  return captured_output(command);
}

}  // namespace pwl::app
