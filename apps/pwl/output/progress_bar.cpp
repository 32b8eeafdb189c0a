#include "output/progress_bar.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cstdio>

namespace pwl::app {

ProgressBar::ProgressBar(long total, std::string unit, bool enabled)
    : total_(total),
      unit_(std::move(unit)),
      enabled_(enabled && total > 0 && ::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_) {}

ProgressBar::~ProgressBar() {
  if (!enabled_) return;
  draw(true);
  std::fputc('\n', stderr);
}

void ProgressBar::advance(long count) {
  done_ += count;
  if (enabled_) draw(false);
}

void ProgressBar::draw(bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && drawn_ && now - last_ < std::chrono::milliseconds(100) && done_ < total_) return;
  last_ = now;
  drawn_ = true;
  const double seconds = std::chrono::duration<double>(now - start_).count();
  const double rate = seconds > 0.0 ? static_cast<double>(done_) / seconds : 0.0;
  const long left = rate > 0.0 ? static_cast<long>(static_cast<double>(total_ - done_) / rate) : 0;
  constexpr int width = 30;
  const int filled = static_cast<int>(width * done_ / total_);
  fmt::print(stderr, "\r[{:=<{}}{:<{}}] {}/{} {}  {:.1f} {}/s  ETA {}:{:02d}   ", "", filled, "",
             width - filled, done_, total_, unit_, rate, unit_, left / 60, left % 60);
  std::fflush(stderr);
}

}  // namespace pwl::app
