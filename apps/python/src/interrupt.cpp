#include "interrupt.hpp"

#include <pybind11/pybind11.h>

namespace pwl::python {

Interrupt::Interrupt()
    : thread_(std::this_thread::get_id()), last_(std::chrono::steady_clock::now()) {}

void Interrupt::poll() {
  if (std::this_thread::get_id() != thread_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  bool raised = false;
  {
    pybind11::gil_scoped_acquire gil;
    raised = PyErr_CheckSignals() != 0;  // the exception stays pending for the binding
  }
  if (raised) throw Interrupted();
}

}  // namespace pwl::python
