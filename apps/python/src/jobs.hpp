#pragma once
// The module's functions, by room: the CLI's single-case and study jobs (run_jobs.cpp: simulate,
// analyze, sweep, map) and its periodic-orbit jobs (orbit_jobs.cpp: orbit, continue_).
#include <pybind11/pybind11.h>

#include "interrupt.hpp"

namespace pwl::python {

void bind_run_jobs(pybind11::module_& m);
void bind_orbit_jobs(pybind11::module_& m);

// Runs `work` with the GIL released, so that other Python threads run meanwhile. `work` must not
// touch a Python object. An Interrupted from it (Interrupt::poll) raises the pending Python
// exception (KeyboardInterrupt) once the GIL is back.
template <class Work>
void without_gil(Work&& work) {
  try {
    pybind11::gil_scoped_release release;
    work();
  } catch (const Interrupted&) {
    throw pybind11::error_already_set();
  }
}

}  // namespace pwl::python
