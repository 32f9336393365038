#pragma once

// How the module turns a casual3d::Status into a Python exception. Every
// binding runs the C++ call (with the GIL released where it is long), then
// calls ThrowIfError with the GIL held again; pybind11 translates the thrown
// C++ exception:
//   kInvalidArgument  -> ValueError           (an option or array out of range)
//   kIoError          -> OSError              (the operating system refused)
//   anything else     -> casual3d.FormatError (a ValueError: malformed,
//                        unsupported or missing data, limits, internal errors)

#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>

#include "format/status.h"

namespace casual3d::python {

// Thrown for statuses other than kInvalidArgument and kIoError.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown for kIoError.
class IoException : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// `message` prefixed with "`path`: " unless it already names `path`.
std::string NamePath(const std::string& path, const std::string& message);

// Throws the exception of `status` (see above) if it is not OK. `path`, when
// not empty, is named at the start of the message (NamePath).
void ThrowIfError(const Status& status, const std::string& path = "");

// Defines casual3d.FormatError (a subclass of ValueError) in `m` and the
// translators of the exceptions above.
void RegisterErrors(pybind11::module_& m);

}  // namespace casual3d::python
