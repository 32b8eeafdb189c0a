// The extension pwl._pwl: pwl's jobs for Python. The package pwl (pwl/__init__.py) wraps its
// functions' dicts into result objects; see there and apps/python/README.md.
#include <pybind11/pybind11.h>

#include "arguments.hpp"
#include "jobs.hpp"
#include "pwl/errors.hpp"
#include "structure.hpp"

PYBIND11_MODULE(_pwl, m) {
  m.doc() = "pwl: dynamics of piecewise-linear structures (the extension; import pwl)";
  m.attr("__version__") = PWL_VERSION;
  // pybind11 tries the translator registered last first: InputError before its base Error.
  pybind11::register_exception<pwl::Error>(m, "RunError", PyExc_RuntimeError);
  pybind11::register_exception<pwl::InputError>(m, "InputError", PyExc_ValueError);
  pwl::python::bind_structure(m);
  pwl::python::bind_orbit_jobs(m);
  pwl::python::bind_run_jobs(m);
  // The keywords of a job, for the docstrings pwl/__init__.py writes: (keyword, default as --help
  // shows it, description, is a flag) in --help's order.
  m.def("keywords", [](const std::string& job) {
    pybind11::list rows;
    for (const auto& k : pwl::python::keywords_of(job)) {
      rows.append(pybind11::make_tuple(k.keyword, k.default_text, k.description, k.flag));
    }
    return rows;
  });
}
