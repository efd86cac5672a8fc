// The Python module airtwin._core, re-exported by the package airtwin (python/airtwin/).

#include <pybind11/pybind11.h>

#include "python/bindings.h"

PYBIND11_MODULE(_core, m) {
  m.doc() =
      "airtwin: the air-jet manipulation twin from Python. SI units (m, s, m/s) except angles "
      "people type, which are in degrees and named _deg. docs/python.md.";
  airtwin::python::bind_errors(m);
  airtwin::python::bind_field(m);
  airtwin::python::bind_prediction(m);
  airtwin::python::bind_identification(m);
  airtwin::python::bind_twin(m);
  airtwin::python::bind_planner(m);
  airtwin::python::bind_run(m);
  airtwin::python::bind_probe(m);
  airtwin::python::bind_region(m);
  // The shipped scenario files (airtwin.env's task names).
  m.attr("SCENES_DIR") = AIRTWIN_SCENES_DIR;
}
