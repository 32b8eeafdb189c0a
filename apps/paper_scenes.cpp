#include "paper_scenes.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "pwl/errors.hpp"

namespace pwl::app {
namespace {

// Runs `command`, returns what it printed (stdout and stderr); throws on a non-zero exit.
std::string capture(const std::string& command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) throw Error(fmt::format("cannot run: {}", command));
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()) != nullptr) {
    out += buffer.data();
  }
  const int status = pclose(pipe.release());
  if (status != 0) throw Error(fmt::format("{} failed:\n{}", command, out));
  return out;
}

// The rest of the line after `prefix` in `text` ("" when absent).
std::string line_after(const std::string& text, const std::string& prefix) {
  const std::size_t at = text.find(prefix);
  if (at == std::string::npos) return "";
  const std::size_t from = at + prefix.size();
  return text.substr(from, text.find('\n', from) - from);
}

std::string shell_quoted(const std::string& s) { return fmt::format("'{}'", s); }

}  // namespace

std::string scenes_directory() {
  if (const char* env = std::getenv("PWL_SCENES_DIR")) return env;
  return PWL_SCENES_DIR;
}

std::vector<SceneRegime> run_paper_scenes(const std::string& self, const std::string& plots_dir,
                                          bool quick) {
  // SPEC.md §5: the paper's captions.
  const std::vector<std::pair<std::string, std::string>> cases{{"5", "chaotic"},
                                                               {"6", "quasi-periodic"}};
  std::vector<SceneRegime> results;
  for (const auto& [figure, paper] : cases) {
    SceneRegime r;
    r.figure = figure;
    r.paper_regime = paper;
    r.scene = fmt::format("{}/paper_fig{}.toml", scenes_directory(), figure);
    const std::string out = fmt::format("{}/data/scene_fig{}", plots_dir, figure);
    std::string command = fmt::format("{} run {} --set output.out={}", shell_quoted(self),
                                      shell_quoted(r.scene), shell_quoted(out));
    if (quick) command += " --set run.periods=400 --set analysis.transient=250";
    fmt::print("figure {}: pwl run {}\n", figure, r.scene);
    std::fflush(stdout);
    const std::string printed = capture(command);
    r.regime = line_after(printed, "regime: ");
    r.lambda1 = line_after(printed, "lambda1: ");
    r.zero_one = line_after(printed, "0-1 test: ");
    if (r.regime.empty()) throw Error(fmt::format("{} printed no regime:\n{}", command, printed));
    fmt::print("  the paper says {}, pwl finds {} (λ1 {}; {})\n", paper, r.regime, r.lambda1,
               r.zero_one);
    if (!quick) {
      std::filesystem::copy_file(out + "/analysis.png",
                                 fmt::format("{}/analysis_fig{}.png", plots_dir, figure),
                                 std::filesystem::copy_options::overwrite_existing);
    }
    results.push_back(r);
  }
  return results;
}

}  // namespace pwl::app
