#include "output/shipped_files.hpp"

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <system_error>

namespace pwl::app {
namespace fs = std::filesystem;

namespace {

// <prefix>/share/pwl when this executable is an installed one (<prefix>/bin/pwl with the data
// folder beside it), nothing otherwise.
std::optional<fs::path> installed_data_directory() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (error) return std::nullopt;
  const fs::path bin = self.parent_path();
  if (bin.filename() != fs::path(PWL_INSTALL_BIN_DIR).filename()) return std::nullopt;
  const fs::path data = bin.parent_path() / PWL_INSTALL_DATA_DIR;
  if (!fs::is_directory(data, error)) return std::nullopt;
  return data;
}

}  // namespace

std::string scripts_directory() {
  if (const char* env = std::getenv("PWL_PLOTS_DIR")) return std::string(env) + "/scripts";
  if (const auto data = installed_data_directory()) return (*data / "scripts").string();
  return std::string(PWL_SOURCE_PLOTS_DIR) + "/scripts";
}

std::string scenes_directory() {
  if (const char* env = std::getenv("PWL_SCENES_DIR")) return env;
  if (const auto data = installed_data_directory()) return (*data / "scenes").string();
  return PWL_SOURCE_SCENES_DIR;
}

std::string plots_directory() {
  if (const char* env = std::getenv("PWL_PLOTS_DIR")) return env;
  if (installed_data_directory()) return "plots";
  return PWL_SOURCE_PLOTS_DIR;
}

std::string figures_directory(const std::string& plots) { return plots + "/figures"; }

}  // namespace pwl::app
