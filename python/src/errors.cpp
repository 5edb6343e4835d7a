// keyanim.Error: the C++ offline::Error as a Python exception, with its place as attributes.
// File-system failures become OSError (FileNotFoundError, PermissionError, ...) as Python's own
// file functions raise them.
#include "common.h"
#include "keyanim/offline/error.h"

namespace keyanim::python {
namespace {

PyObject* error_type = nullptr;

const char* const kErrorDoc =
    "Raised when keyanim cannot make what was asked: a malformed BVH or .kanim file, settings\n"
    "that make no sense, a limit reached. A ValueError, with attributes:\n"
    "  kind     'malformed', 'unsupported', 'limit', 'invalid_argument' or 'io'\n"
    "  file     the file concerned (str), or None\n"
    "  line, column   1-based place in BVH text (0 when the error is not about a place in text)\n"
    "  section, offset   the .kanim section ('header', 'KEYS', ...) and absolute byte offset,\n"
    "           or None and 0 when the error is not about a place in a .kanim\n"
    "  status   the .kanim loader's status ('checksum_mismatch', ...), or None\n"
    "  message  what is wrong, without the place\n"
    "str(error) is 'file:line:column: message' (BVH) or 'file: section S, offset N (0xN): status:\n"
    "message' (.kanim), as the keyanim tool prints them.";

py::object optional_text(const std::string& s) { return s.empty() ? py::object(py::none()) : py::object(text(s)); }

void raise(const offline::Error& e) {
  if (e.kind() == offline::ErrorKind::io && e.system_error() != 0) {
    // OSError(errno, strerror, filename) picks the subclass (FileNotFoundError, ...) itself.
    const py::object os_error = py::reinterpret_borrow<py::object>(PyExc_OSError)(
        e.system_error(), text(e.message()), optional_text(e.file()));
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(os_error.ptr())), os_error.ptr());
    return;
  }
  const py::object exc = py::reinterpret_borrow<py::object>(error_type)(text(e.what()));
  exc.attr("kind") = offline::error_kind_string(e.kind());
  exc.attr("file") = optional_text(e.file());
  exc.attr("line") = e.line();
  exc.attr("column") = e.column();
  exc.attr("section") = optional_text(e.section());
  exc.attr("offset") = e.byte_offset();
  exc.attr("status") = e.section().empty() ? py::object(py::none()) : py::object(py::str(status_string(e.status())));
  exc.attr("message") = text(e.message());
  PyErr_SetObject(error_type, exc.ptr());
}

}  // namespace

void register_errors(py::module_& m) {
  error_type = PyErr_NewExceptionWithDoc("keyanim.Error", kErrorDoc, PyExc_ValueError, nullptr);
  if (error_type == nullptr) throw py::error_already_set();
  m.add_object("Error", py::handle(error_type));
  // Defaults, for an Error raised from Python code (keyanim.dataset) with a message alone.
  const py::handle type(error_type);
  type.attr("kind") = "invalid_argument";
  for (const char* name : {"file", "section", "status", "message"}) type.attr(name) = py::none();
  for (const char* name : {"line", "column", "offset"}) type.attr(name) = 0;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const offline::Error& e) {
      raise(e);
    }
  });
}

}  // namespace keyanim::python
