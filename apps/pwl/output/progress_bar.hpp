#pragma once
// A progress bar with the rate and the estimated time left, on stderr, redrawn at most ten times a
// second; silent when stderr is not a terminal or when asked to be.
#include <chrono>
#include <string>

namespace pwl::app {

class ProgressBar {
 public:
  ProgressBar(long total, std::string unit, bool enabled);
  ~ProgressBar();  // ends the line it drew on
  void advance(long count = 1);

 private:
  void draw(bool force);
  long total_;
  long done_ = 0;
  std::string unit_;
  bool enabled_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace pwl::app
