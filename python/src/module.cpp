// The Python module ecvpose._ecvpose (re-exported by the package ecvpose): libraries, frames and recognition.

#include <pybind11/pybind11.h>

#include "bindings.h"
#include "core/error.h"
#include "core/version.h"
#include "modeldb/sql.h"
#include "render/renderer.h"

PYBIND11_MODULE(_ecvpose, m) {
  namespace py = pybind11;
  m.doc() = "Known objects and their 6D pose in RGB-D images (ecvpose).";
  m.attr("__version__") = ecv::kVersion;
  // Bad input of any kind (a file, an argument, a library): the message names it and says what was expected.
  static const py::exception<ecv::InputError>& input_error =
      py::register_exception<ecv::InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const ecv::SqlError& sql) {
      PyErr_SetString(input_error.ptr(), sql.what());  // a library that is no database, locked, of another schema
    }
  });
  py::register_exception<ecv::RenderError>(m, "RenderError", PyExc_RuntimeError);
  ecv::python::BindLibrary(m);
  ecv::python::BindRecognizer(m);
  ecv::python::BindCamera(m);
}
