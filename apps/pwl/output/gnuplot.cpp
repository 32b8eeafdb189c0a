#include "output/gnuplot.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <gnuplot-iostream.h>
#include <optional>
#include <string_view>

#include "output/shipped_files.hpp"

namespace pwl::app {
namespace {

// The gnuplot program on PATH, found without a shell.
std::optional<std::filesystem::path> gnuplot_on_path() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return std::nullopt;
  std::string_view rest(path);
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::string_view folder = rest.substr(0, colon);
    rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
    const std::filesystem::path candidate =
        std::filesystem::path(folder.empty() ? std::string_view(".") : folder) / "gnuplot";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return std::nullopt;
}

// SIGPIPE ignored while gnuplot is fed: a gnuplot that stops early (a crash, a broken script)
// closes the pipe, and the writes must then fail with EPIPE rather than end pwl.
class IgnoredSigpipe {
 public:
  IgnoredSigpipe() {
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGPIPE, &ignore, &previous_);
  }
  ~IgnoredSigpipe() { sigaction(SIGPIPE, &previous_, nullptr); }
  IgnoredSigpipe(const IgnoredSigpipe&) = delete;
  IgnoredSigpipe& operator=(const IgnoredSigpipe&) = delete;

 private:
  struct sigaction previous_ {};
};

}  // namespace

std::string gnuplot_quoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\'') {
      quoted += "''";
    } else if (byte < 0x20 || byte == 0x7f) {
      quoted += ' ';
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// The session goes through gnuplot-iostream's stream: the load path, the definitions and a `load`
// of the shipped script, so that the scripts stay plain files a user can edit and run by hand
// (`gnuplot -e "..." plots/scripts/x.gp` gives the same figure). gnuplot-iostream closes its pipe
// without reporting how gnuplot ended, so the stream writes to a duplicate of the pipe's
// descriptor and the pipe itself is closed here, with gnuplot's exit status: a script error (gnuplot
// stops at the first error when it reads a pipe) becomes a failure, not a silent missing figure.
bool run_gnuplot(const std::string& script, const std::string& definitions, std::string* why) {
  const std::optional<std::filesystem::path> program = gnuplot_on_path();
  if (!program) {
    *why = "gnuplot is not installed (apt-get install gnuplot-nox); the CSV files are written";
    return false;
  }
  const IgnoredSigpipe sigpipe;
  std::fflush(nullptr);  // what pwl printed comes before what gnuplot prints
  FILE* pipe = popen(program->c_str(), "w");
  if (pipe == nullptr) {
    *why = fmt::format("cannot start {}", program->string());
    return false;
  }
  const int copy = dup(fileno(pipe));
  FILE* stream_file = copy >= 0 ? fdopen(copy, "w") : nullptr;
  bool written = false;
  if (stream_file != nullptr) {
    Gnuplot session(stream_file);  // closes stream_file when it ends
    session << "set loadpath " << gnuplot_quoted(scripts_directory()) << '\n'
            << definitions << '\n'
            << "load " << gnuplot_quoted(script) << '\n';
    session.flush();
    written = session.good();
  } else if (copy >= 0) {
    close(copy);
  }
  const int status = pclose(pipe);
  const bool ok = written && status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
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
