#pragma once
// A one-line progress report on stderr for runs of unknown length (a continuation, its curves):
// on a terminal one line redrawn at most ten times a second, in a log a line every five seconds,
// and nothing when asked to be quiet. The text says what is being done and where; the line adds
// nothing of its own.
#include <chrono>
#include <string>

namespace pwl::app {

class ProgressLine {
 public:
  explicit ProgressLine(bool enabled);
  // Whether a line is due now (`force`: whatever the time since the last one, as at a new
  // stage); false when quiet.
  bool due(bool force = false) const;
  // Shows `text` (call when due) and starts the next interval.
  void show(const std::string& text);
  double seconds() const;  // since the start
  // Ends the terminal's redrawn line, so that what is printed next starts on a line of its own.
  void finish();

 private:
  bool enabled_, tty_, drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

// The line of a Newton iteration on a periodic orbit ("<what>: Newton iteration k, residual r, p
// GMRES products, s s"), the same for `pwl orbit` and `pwl continue`'s first orbit.
std::string newton_progress_text(const std::string& what, int iteration, double residual,
                                 long products, double seconds);

}  // namespace pwl::app
