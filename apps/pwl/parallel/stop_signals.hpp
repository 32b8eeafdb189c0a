#pragma once
// Stopping a long study at once on SIGINT (Ctrl-C) or SIGTERM (what kill, timeout and batch
// schedulers send) without losing what it finished.
//
// While a StopSignals lives, those signals only record that they came (an atomic store: the one
// thing a handler may safely do); the study's points look at received() between points and
// between forcing periods, stop within a period, keep every journal line whole (a write in
// progress finishes, since a handler never interrupts it half-way) and throw Stopped, which the
// program turns into its message and the exit code a shell gives a process killed by the signal
// (128 + its number: 130 for SIGINT, 143 for SIGTERM). A signal that was ignored when the program
// started (SIGINT of a command started with & by a non-interactive shell, or under nohup-like
// wrappers) stays ignored. The handlers are one-shot: a second Ctrl-C while the study winds down
// ends the process the ordinary way (a torn journal line at most, which --resume cuts off).
#include <stdexcept>
#include <string>

namespace pwl::app {

class StopSignals {
 public:
  // Installs the recording handlers for SIGINT and SIGTERM (those not ignored) and clears what an
  // earlier StopSignals recorded.
  StopSignals();
  // Puts back the handlers that were there before.
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  // The signal received while a StopSignals lived (SIGINT or SIGTERM), 0 when none. Safe from any
  // thread.
  static int received();
};

// "SIGINT", "SIGTERM", or "signal <n>".
std::string signal_name(int signal);

// A run that stopped on a signal, after keeping what it finished. what() says how far it got and
// how to go on; the program prints it and exits with exit_code().
class Stopped : public std::runtime_error {
 public:
  Stopped(int signal, const std::string& message)
      : std::runtime_error(message), signal_(signal) {}
  int signal() const { return signal_; }
  int exit_code() const { return 128 + signal_; }

 private:
  int signal_;
};

}  // namespace pwl::app
