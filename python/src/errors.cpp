// python/src/errors.cpp — orbis.Error and orbis.MissingFileError (contract in errors.hpp).
#include "errors.hpp"

#include <cerrno>
#include <cstring>

#include "bindings.hpp"
#include "orbis/util/error.hpp"

namespace orbis::python {
namespace {

// Created once when the module loads and deliberately never released: the translator below may
// run until the interpreter shuts down, after module globals are gone.
PyObject* errorType = nullptr;
PyObject* missingFileType = nullptr;

void raiseError(const Error& e) {
  py::object instance = py::reinterpret_borrow<py::object>(errorType)(e.what());
  instance.attr("source") = e.source();
  instance.attr("where") = e.where();
  PyErr_SetObject(errorType, instance.ptr());
}

}  // namespace

void requireFile(const std::filesystem::path& file) {
  std::error_code ignored;
  if (std::filesystem::exists(file, ignored)) return;
  py::object instance =
      py::reinterpret_borrow<py::object>(missingFileType)(ENOENT, std::strerror(ENOENT), file.string());
  instance.attr("source") = file.string();
  instance.attr("where") = "";
  PyErr_SetObject(missingFileType, instance.ptr());
  throw py::error_already_set();
}

void bindErrors(py::module_& m) {
  errorType = PyErr_NewExceptionWithDoc(
      "orbis.Error",
      "An orbis failure caused by outside input (a file, a settings key, an argument).\n\n"
      "str(e) names the source, the location and what was expected; e.source is the file or\n"
      "origin, e.where the line or settings key (may be empty).",
      PyExc_RuntimeError, nullptr);
  if (!errorType) throw py::error_already_set();
  const py::tuple bases = py::make_tuple(py::handle(PyExc_FileNotFoundError), py::handle(errorType));
  py::dict namespace_;
  namespace_["__module__"] = "orbis";
  namespace_["__doc__"] = "A file given to orbis does not exist (both FileNotFoundError and orbis.Error).";
  missingFileType = py::module_::import("builtins").attr("type")("MissingFileError", bases, namespace_).release().ptr();
  m.attr("Error") = py::handle(errorType);
  m.attr("MissingFileError") = py::handle(missingFileType);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      raiseError(e);
    }
  });
}

}  // namespace orbis::python
