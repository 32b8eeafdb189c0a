#include "output/gnuplot.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "output/shell_command.hpp"
#include "output/shipped_files.hpp"

namespace pwl::app {

std::string gnuplot_quoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

bool run_gnuplot(const std::string& script, const std::string& definitions, std::string* why) {
  if (std::system("command -v gnuplot > /dev/null 2>&1") != 0) {
    *why = "gnuplot is not installed (apt-get install gnuplot-nox); the CSV files are written";
    return false;
  }
  // The definitions go through a file, not the shell, so that titles may hold any character.
  std::string prelude = (std::filesystem::temp_directory_path() / "pwl-gnuplot-XXXXXX").string();
  const int fd = mkstemp(prelude.data());
  if (fd < 0) {
    *why = "cannot create a temporary file for gnuplot";
    return false;
  }
  const std::string text =
      fmt::format("set loadpath {}\n{}\n", gnuplot_quoted(scripts_directory()), definitions);
  const bool written = write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  close(fd);
  const std::string command =
      fmt::format("gnuplot {} {}", shell_quoted(prelude), shell_quoted(script));
  const bool ok = written && std::system(command.c_str()) == 0;
  std::remove(prelude.c_str());
  if (!ok) *why = fmt::format("gnuplot failed on {}", script);
  return ok;
}

bool draw_figure(const std::string& script,
                 const std::function<std::string(const std::string& format)>& definitions,
                 std::string* why) {
  for (const std::string format : {"png", "svg"}) {
    if (!run_gnuplot(script, fmt::format("fmt='{}'; {}", format, definitions(format)), why))
      return false;
  }
  return true;
}


bool draw_figure_and_report(
    const std::string& script,
    const std::function<std::string(const std::string& format)>& definitions,
    const std::string& stem, const std::string& who, bool quiet) {
  std::string why;
  if (!draw_figure(script, definitions, &why)) {
    fmt::print(stderr, "{}: no figure: {}\n", who, why);
    return false;
  }
  if (!quiet) fmt::print("wrote {}.png and .svg\n", stem);
  return true;
}

}  // namespace pwl::app
