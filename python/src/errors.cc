#include "python/src/errors.h"

namespace casual3d::python {

std::string NamePath(const std::string& path, const std::string& message) {
  if (path.empty() || message.find(path) != std::string::npos) return message;
  return path + ": " + message;
}

void ThrowIfError(const Status& status, const std::string& path) {
  if (status.ok()) return;
  const std::string message = NamePath(path, status.message());
  switch (status.code()) {
    case StatusCode::kInvalidArgument:
      throw std::invalid_argument(message);
    case StatusCode::kIoError:
      throw IoException(message);
    default:
      throw FormatError(message);
  }
}

void RegisterErrors(pybind11::module_& m) {
  pybind11::register_exception<FormatError>(m, "FormatError", PyExc_ValueError);
  pybind11::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const IoException& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
}

}  // namespace casual3d::python
