#include "output/progress_line.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace pwl::app {

ProgressLine::ProgressLine(bool enabled)
    : enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

bool ProgressLine::due(bool force) const {
  if (!enabled_) return false;
  if (force || !drawn_) return true;
  return std::chrono::steady_clock::now() - last_ >= std::chrono::milliseconds(tty_ ? 100 : 5000);
}

void ProgressLine::show(const std::string& text) {
  if (!enabled_) return;
  last_ = std::chrono::steady_clock::now();
  if (tty_) {
    fmt::print(stderr, "\r{:<78}", text);
  } else {
    fmt::print(stderr, "{}\n", text);
  }
  drawn_ = true;
  std::fflush(stderr);
}

double ProgressLine::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressLine::finish() {
  if (enabled_ && tty_ && drawn_) std::fputc('\n', stderr);
  drawn_ = false;
}

std::string newton_progress_text(const std::string& what, int iteration, double residual,
                                 long products, double seconds) {
  return fmt::format("{}: Newton iteration {}, residual {:.2e}, {} GMRES products, {:.1f} s", what,
                     iteration, residual, products, seconds);
}

}  // namespace pwl::app
