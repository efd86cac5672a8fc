// The library's input errors as Python's ValueError, message unchanged: what the CLI prints
// after "airtwin: error: " (app/main.cc).

#include <pybind11/pybind11.h>

#include "common/errors.h"
#include "python/bindings.h"

namespace airtwin::python {

void bind_errors(pybind11::module_& m) {
  (void)m;
  // InputError is the base of FieldError and UsageError: one translator covers the three.
  pybind11::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace airtwin::python
