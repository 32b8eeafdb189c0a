#pragma once
// Ctrl-C during a long run that has released the GIL.
//
// Python handles SIGINT by setting a flag that only its main thread acts on, between bytecodes, so
// a C++ loop running without the GIL would finish before KeyboardInterrupt is raised. A run that
// has a natural checkpoint (a forcing period of simulate, a point of a sweep or map, a point of a
// continuation) calls Interrupt::poll() there: at most every 0.2 s it takes the GIL and lets
// Python run its signal handlers (PyErr_CheckSignals); when one raised, poll throws Interrupted,
// which unwinds the run. The binding catches it with the GIL held and re-raises the pending Python
// exception (KeyboardInterrupt). Only the thread that made the Interrupt polls (Python runs signal
// handlers only in its main thread anyway); OpenMP workers of a sweep pass by. Newton of pwl.orbit
// has no checkpoint: Ctrl-C there takes effect when the call returns.
#include <chrono>
#include <stdexcept>
#include <thread>

namespace pwl::python {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

class Interrupt {
 public:
  Interrupt();
  // To be called without the GIL. Throws Interrupted when a Python signal handler raised.
  void poll();

 private:
  std::thread::id thread_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace pwl::python
