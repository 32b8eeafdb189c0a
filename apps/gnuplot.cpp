#include "gnuplot.hpp"

#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>

namespace pwl::app {

bool run_gnuplot(const std::string& script, const std::string& definitions, std::string* why) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    *why = "gnuplot is not installed (apt-get install gnuplot-nox); the CSV files are written";
    return false;
  }
  const std::string command = fmt::format("gnuplot -e \"{}\" '{}'", definitions, script);
  if (std::system(command.c_str()) != 0) {
    *why = fmt::format("gnuplot failed on {}", script);
    return false;
  }
  return true;
}

std::string plots_directory() {
  if (const char* env = std::getenv("PWL_PLOTS_DIR")) return env;
  return PWL_PLOTS_DIR;
}

}  // namespace pwl::app
